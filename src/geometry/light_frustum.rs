//! The spot frustum a shadow map is rendered through, fitted every frame.
//!
//! A point can only be shadowed if the segment to the light crosses a caster, so the frustum
//! needs to cover the casters' angular extent from the light, and of that only the part where a
//! receiver is in view: the window is the intersection of the two. Everything outside it is lit.

use glam::{DMat4, DVec3, DVec4, Mat4, Vec3};

/// Widest half-angle a single frustum covers (tan 80°); casters beyond it (a light among its
/// casters) are clipped, which a cube map would fix.
const MAX_TAN: f64 = 5.671;

/// A perspective frustum from the light: view space has +Z away from the light, and the window
/// is given in tangent units (x/z, y/z).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightFrustum {
    /// World → light view; linear depth is view-space z.
    pub view: Mat4,
    /// World → clip, depth 0 at `near` and 1 at `far`.
    pub view_proj: Mat4,
    /// x0, y0, x1, y1 of the window in tangent units.
    pub window: [f32; 4],
    pub near: f32,
    pub far: f32,
}

/// Fits the frustum from `light` looking towards `aim` around the `casters`' points, cut to the
/// `receivers`' points in view. `None` when no receiver in view can be shadowed.
pub fn fit_spot_frustum(light: Vec3, aim: Vec3, casters: &[Vec3], receivers: &[Vec3]) -> Option<LightFrustum> {
    if casters.is_empty() || receivers.is_empty() {
        return None;
    }
    let l = light.as_dvec3();
    let z_axis = (aim.as_dvec3() - l).try_normalize().unwrap_or(DVec3::NEG_Y);
    let hint = if z_axis.y.abs() < 0.99 { DVec3::Y } else { DVec3::X };
    let x_axis = hint.cross(z_axis).normalize();
    let y_axis = z_axis.cross(x_axis);
    let view = DMat4::from_cols(
        DVec4::new(x_axis.x, y_axis.x, z_axis.x, 0.0),
        DVec4::new(x_axis.y, y_axis.y, z_axis.y, 0.0),
        DVec4::new(x_axis.z, y_axis.z, z_axis.z, 0.0),
        DVec4::new(-x_axis.dot(l), -y_axis.dot(l), -z_axis.dot(l), 1.0),
    );
    let to_view = |p: &Vec3| view.transform_point3(p.as_dvec3());

    let caster_view: Vec<DVec3> = casters.iter().map(to_view).collect();
    let far = caster_view.iter().map(|p| p.z).fold(f64::NEG_INFINITY, f64::max);
    if far <= 0.0 {
        return None; // every caster is behind the light's aim
    }
    let near = caster_view.iter().map(|p| p.z).fold(f64::INFINITY, f64::min).max(far * 1e-4);
    let caster_window = tangent_window(&caster_view);
    let receiver_view: Vec<DVec3> = receivers.iter().map(to_view).collect();
    // A receiver point beside or behind the light makes its window unbounded: use the casters'.
    let receiver_window = tangent_window(&receiver_view);
    let mut w = [
        caster_window[0].max(receiver_window[0]),
        caster_window[1].max(receiver_window[1]),
        caster_window[2].min(receiver_window[2]),
        caster_window[3].min(receiver_window[3]),
    ];
    if w[0] >= w[2] || w[1] >= w[3] {
        return None;
    }
    // Pad by 1% (the 2×2 filter reads one texel beyond) and keep a point-like caster non-degenerate.
    let pad_x = ((w[2] - w[0]) * 0.01).max(1e-6);
    let pad_y = ((w[3] - w[1]) * 0.01).max(1e-6);
    w = [w[0] - pad_x, w[1] - pad_y, w[2] + pad_x, w[3] + pad_y];
    // The depth range reaches the receivers too: `far` is then the farthest receiver, which
    // bounds how far a smoothie can matter; depth is linear in the colour target anyway.
    let far = receiver_view.iter().map(|p| p.z).fold(far, f64::max) * 1.001;
    Some(frustum(view, w, near, far))
}

fn frustum(view: DMat4, w: [f64; 4], near: f64, far: f64) -> LightFrustum {
    let (sx, sy) = (w[2] - w[0], w[3] - w[1]);
    let depth_scale = far / (far - near);
    let proj = DMat4::from_cols(
        DVec4::new(2.0 / sx, 0.0, 0.0, 0.0),
        DVec4::new(0.0, 2.0 / sy, 0.0, 0.0),
        DVec4::new(-(w[0] + w[2]) / sx, -(w[1] + w[3]) / sy, depth_scale, 1.0),
        DVec4::new(0.0, 0.0, -near * depth_scale, 0.0),
    );
    LightFrustum {
        view: view.as_mat4(),
        view_proj: (proj * view).as_mat4(),
        window: w.map(|v| v as f32),
        near: near as f32,
        far: far as f32,
    }
}

impl LightFrustum {
    /// The same frustum with its window grown by `pad` tangent units on every side (geometry
    /// drawn around the casters, such as smoothies), still within ±tan 80°.
    pub fn grown(&self, pad: f32) -> LightFrustum {
        let [x0, y0, x1, y1] = self.window.map(f64::from);
        let pad = f64::from(pad);
        let w = [(x0 - pad).max(-MAX_TAN), (y0 - pad).max(-MAX_TAN), (x1 + pad).min(MAX_TAN), (y1 + pad).min(MAX_TAN)];
        frustum(self.view.as_dmat4(), w, f64::from(self.near), f64::from(self.far))
    }
}

/// Bounds of x/z and y/z over points in front of the light; unbounded (±MAX_TAN) if one is not.
fn tangent_window(points: &[DVec3]) -> [f64; 4] {
    let mut w = [MAX_TAN, MAX_TAN, -MAX_TAN, -MAX_TAN];
    for p in points {
        if p.z <= 0.0 {
            return [-MAX_TAN, -MAX_TAN, MAX_TAN, MAX_TAN];
        }
        let (tx, ty) = ((p.x / p.z).clamp(-MAX_TAN, MAX_TAN), (p.y / p.z).clamp(-MAX_TAN, MAX_TAN));
        w = [w[0].min(tx), w[1].min(ty), w[2].max(tx), w[3].max(ty)];
    }
    w
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Aabb;
    use proptest::prelude::*;

    fn ground() -> Vec<Vec3> {
        Aabb { min: Vec3::new(-10.0, 0.0, -10.0), max: Vec3::new(10.0, 0.0, 10.0) }.corners().to_vec()
    }

    #[test]
    fn no_casters_needs_no_frustum() {
        assert!(fit_spot_frustum(Vec3::Y * 5.0, Vec3::ZERO, &[], &ground()).is_none());
    }

    #[test]
    fn receivers_away_from_the_casters_need_no_frustum() {
        let caster = Aabb { min: Vec3::new(-0.5, 1.0, -0.5), max: Vec3::new(0.5, 2.0, 0.5) }.corners();
        let far_receiver = Aabb { min: Vec3::new(50.0, 0.0, 50.0), max: Vec3::new(51.0, 0.0, 51.0) }.corners();
        assert!(fit_spot_frustum(Vec3::Y * 5.0, Vec3::ZERO, &caster, &far_receiver).is_none());
    }

    proptest! {
        /// Every caster point that shadows a receiver lands inside the clip volume.
        #[test]
        fn casters_fit_inside_the_frustum(
            light in prop::array::uniform3(-20.0f32..20.0),
            c0 in prop::array::uniform3(-3.0f32..3.0), size in prop::array::uniform3(0.0f32..2.0),
            scale in prop::sample::select(vec![1e-3f32, 1.0, 1e4]),
        ) {
            let light = Vec3::from(light) * scale + Vec3::Y * 30.0 * scale;
            let min = Vec3::from(c0) * scale;
            let caster = Aabb { min, max: min + Vec3::from(size) * scale };
            let receivers: Vec<Vec3> = ground().iter().map(|p| *p * scale * 10.0).collect();
            let f = fit_spot_frustum(light, caster.center(), &caster.corners(), &receivers).unwrap();
            prop_assert!(f.window.iter().all(|v| v.is_finite()) && f.near > 0.0 && f.far > f.near);
            for c in caster.corners() {
                let clip = f.view_proj * c.extend(1.0);
                let ndc = clip.truncate() / clip.w;
                prop_assert!(clip.w > 0.0);
                prop_assert!(ndc.x.abs() <= 1.0 + 1e-4 && ndc.y.abs() <= 1.0 + 1e-4, "{:?}", ndc);
                prop_assert!(ndc.z >= -1e-4 && ndc.z <= 1.0 + 1e-4, "{:?}", ndc);
            }
        }
    }
}
