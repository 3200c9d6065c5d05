//! Points spread over a spherical light for Heckbert & Herf's accumulation (the `reference`
//! technique): uniform in area over the part of the sphere that some receiver in view can see.

use glam::Vec3;

/// A cap of the light sphere: every point whose direction from the centre lies within the
/// half-angle of `axis`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cap {
    pub axis: Vec3,
    pub cos_half_angle: f32,
}

/// The smallest cap around the receivers' mean direction that holds every point of the sphere
/// (`center`, `radius`) seen from any of `points`: from a point at distance d the visible part
/// is the cap of half-angle acos(r / d) facing it. A point on or inside the sphere sees it all.
pub fn visible_cap(center: Vec3, radius: f32, points: &[Vec3]) -> Cap {
    let whole = Cap { axis: Vec3::NEG_Y, cos_half_angle: -1.0 };
    let mean = points.iter().map(|p| (*p - center).normalize_or_zero()).sum::<Vec3>();
    let Some(axis) = mean.try_normalize() else { return whole };
    let mut half = 0.0f32;
    for p in points {
        let d = (*p - center).length();
        if d <= radius {
            return whole;
        }
        let off_axis = axis.dot((*p - center) / d).clamp(-1.0, 1.0).acos();
        half = half.max(off_axis + (radius / d).clamp(0.0, 1.0).acos());
    }
    Cap { axis, cos_half_angle: half.min(std::f32::consts::PI).cos() }
}

/// `n` points uniform in area over `cap` of the sphere: a spherical Fibonacci lattice, which
/// is stratified in height and low-discrepancy in angle, and the same every frame.
pub fn cap_points(center: Vec3, radius: f32, cap: Cap, n: usize) -> Vec<Vec3> {
    let golden_angle = std::f32::consts::PI * (3.0 - 5.0f32.sqrt());
    let (u, v) = cap.axis.any_orthonormal_pair();
    (0..n)
        .map(|i| {
            let z = 1.0 - (1.0 - cap.cos_half_angle) * (i as f32 + 0.5) / n as f32;
            let ring = (1.0 - z * z).max(0.0).sqrt();
            let phi = golden_angle * i as f32;
            center + radius * (ring * (phi.cos() * u + phi.sin() * v) + z * cap.axis)
        })
        .collect()
}

/// The points accumulation renders a hard shadow from: `n` of [`cap_points`] over the
/// [`visible_cap`] of `receivers`, or the centre alone for a point light.
pub fn light_points(center: Vec3, radius: f32, receivers: &[Vec3], n: usize) -> Vec<Vec3> {
    if radius > 0.0 { cap_points(center, radius, visible_cap(center, radius, receivers), n) } else { vec![center] }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn vec3() -> impl Strategy<Value = Vec3> {
        (-10.0f32..10.0, -10.0f32..10.0, -10.0f32..10.0).prop_map(|(x, y, z)| Vec3::new(x, y, z))
    }

    proptest! {
        #[test]
        fn the_cap_holds_every_visible_point(
            receivers in proptest::collection::vec(vec3(), 1..6),
            radius in 0.01f32..2.0,
            probes in proptest::collection::vec(vec3(), 20),
        ) {
            let center = Vec3::new(0.0, 12.0, 0.0);
            let cap = visible_cap(center, radius, &receivers);
            for p in &receivers {
                for probe in &probes {
                    // A point of the sphere that `p` sees: in front of p's tangent cone.
                    let q = center + radius * probe.normalize_or(Vec3::X);
                    if (q - center).dot(*p - center) > radius * radius {
                        let cos = cap.axis.dot((q - center) / radius);
                        prop_assert!(cos >= cap.cos_half_angle - 1e-4, "visible point outside the cap");
                    }
                }
            }
        }

        #[test]
        fn cap_points_lie_on_the_sphere_inside_the_cap(cos_half in -1.0f32..0.99, n in 1usize..300) {
            let (center, radius) = (Vec3::new(1.0, 2.0, 3.0), 0.5);
            let cap = Cap { axis: Vec3::new(0.3, -1.0, 0.2).normalize(), cos_half_angle: cos_half };
            let points = cap_points(center, radius, cap, n);
            prop_assert_eq!(points.len(), n);
            let mut height = 0.0;
            for q in &points {
                prop_assert!(((*q - center).length() - radius).abs() < 1e-4);
                let z = cap.axis.dot((*q - center) / radius);
                prop_assert!(z >= cos_half - 1e-4);
                height += z / n as f32;
            }
            // Uniform in area means uniform in height along the axis: the mean height is the middle.
            prop_assert!((height - (1.0 + cos_half) / 2.0).abs() < 1e-3);
        }
    }

    #[test]
    fn points_inside_the_light_see_all_of_it() {
        let cap = visible_cap(Vec3::ZERO, 1.0, &[Vec3::new(0.0, 0.5, 0.0), Vec3::new(0.0, -9.0, 0.0)]);
        assert_eq!(cap.cos_half_angle, -1.0);
    }
}
