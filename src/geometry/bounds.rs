use glam::{Mat4, Vec2, Vec3};

/// An axis-aligned box; `min > max` on some axis means empty.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub min: Vec3,
    pub max: Vec3,
}

impl Aabb {
    pub const EMPTY: Aabb = Aabb { min: Vec3::INFINITY, max: Vec3::NEG_INFINITY };

    pub fn from_points(points: impl IntoIterator<Item = Vec3>) -> Self {
        points.into_iter().fold(Self::EMPTY, |b, p| Aabb { min: b.min.min(p), max: b.max.max(p) })
    }

    pub fn is_empty(&self) -> bool {
        self.min.cmpgt(self.max).any()
    }

    pub fn union(&self, other: &Aabb) -> Aabb {
        Aabb { min: self.min.min(other.min), max: self.max.max(other.max) }
    }

    pub fn center(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }

    pub fn corners(&self) -> [Vec3; 8] {
        std::array::from_fn(|i| {
            Vec3::new(
                if i & 1 == 0 { self.min.x } else { self.max.x },
                if i & 2 == 0 { self.min.y } else { self.max.y },
                if i & 4 == 0 { self.min.z } else { self.max.z },
            )
        })
    }

    /// The box of this box's corners after `m` (conservative for rotations).
    pub fn transformed(&self, m: &Mat4) -> Aabb {
        Aabb::from_points(self.corners().map(|c| m.transform_point3(c)))
    }
}

/// Whether any two of `boxes` (2D, min and max corners), each grown by `pad` on every side,
/// overlap: what decides whether several casters' shadows need to be kept apart.
pub fn any_two_meet(boxes: &[(Vec2, Vec2)], pad: f32) -> bool {
    let meet =
        |a: &(Vec2, Vec2), b: &(Vec2, Vec2)| (a.0 - pad).cmple(b.1 + pad).all() && (b.0 - pad).cmple(a.1 + pad).all();
    boxes.iter().enumerate().any(|(i, a)| boxes[i + 1..].iter().any(|b| meet(a, b)))
}
