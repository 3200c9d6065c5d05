//! Camera matrices following DESIGN.md §3: forward = normalize(target − position),
//! right = normalize(forward × up), up' = right × forward; image x grows with right, rows grow
//! with −up' (row 0 at the top). Depth is reversed (near 1, far 0) for float precision, and the
//! near and far planes are fitted to the scene's bounds every frame, never hard-coded.

use glam::{DMat4, DVec4, Mat4, Vec2, Vec3, Vec4};

use super::{Aabb, Hexahedron};

/// How the camera projects.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Vertical field of view in degrees, in (0, 180).
    Perspective { fov_y_deg: f32 },
    /// Half the view's height in world units; half width = half height × aspect.
    Orthographic { half_height: f32 },
}

/// A camera's matrices for one frame.
#[derive(Clone, Copy, Debug)]
pub struct CameraProjection {
    /// World → view and view → clip, in single precision as a renderer holds them: the same
    /// matrices handed to [`CameraProjection::from_matrices`] give this projection bit for bit.
    pub view: Mat4,
    pub projection: Mat4,
    /// The near and far distances along the view axis the view volume spans.
    pub near: f32,
    pub far: f32,
    pub view_proj: Mat4,
    pub inv_view_proj: Mat4,
    pub position: Vec3,
    pub forward: Vec3,
    /// `inv_view_proj` in double precision, for rays and positions rebuilt on the CPU.
    inv64: DMat4,
    /// The view volume between the fitted near and far planes.
    pub frustum: Hexahedron,
}

/// Reverse-Z perspective from view space (x right, y up, z forward) to Vulkan clip space.
fn reverse_z_perspective(tan_half_fov_y: f64, aspect: f64, near: f64, far: f64) -> DMat4 {
    let (a, b) = (-near / (far - near), near * far / (far - near));
    DMat4::from_cols(
        DVec4::new(1.0 / (tan_half_fov_y * aspect), 0.0, 0.0, 0.0),
        DVec4::new(0.0, -1.0 / tan_half_fov_y, 0.0, 0.0),
        DVec4::new(0.0, 0.0, a, 1.0),
        DVec4::new(0.0, 0.0, b, 0.0),
    )
}

impl CameraProjection {
    /// `up` must not be parallel to `target − position` (the scene loader checks). Errors as
    /// [`CameraProjection::from_matrices`] does, for a camera no finite matrices describe.
    pub fn new(
        position: Vec3,
        target: Vec3,
        up: Vec3,
        projection: Projection,
        aspect: f32,
        scene: &Aabb,
    ) -> Result<Self, String> {
        let (pos, forward) = (position.as_dvec3(), (target - position).as_dvec3().normalize());
        let right = forward.cross(up.as_dvec3()).normalize();
        let true_up = right.cross(forward);
        let view = DMat4::from_cols(
            DVec4::new(right.x, true_up.x, forward.x, 0.0),
            DVec4::new(right.y, true_up.y, forward.y, 0.0),
            DVec4::new(right.z, true_up.z, forward.z, 0.0),
            DVec4::new(-right.dot(pos), -true_up.dot(pos), -forward.dot(pos), 1.0),
        );
        let depths = scene.corners().map(|c| forward.dot(c.as_dvec3() - pos));
        let (dmin, dmax) = depths.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &d| (a.min(d), b.max(d)));
        let aspect = aspect as f64;
        let (proj, near, far) = match projection {
            Projection::Perspective { fov_y_deg } => {
                let far = if dmax > 0.0 { dmax * 1.01 } else { 1.0 };
                let tan_half = ((fov_y_deg as f64).to_radians() * 0.5).tan();
                // Nothing in view is nearer than the scene's box times the cosine of the view's
                // half diagonal: a fixed fraction of `far` would cut a caster 4 m away out of a
                // view over a ground 1e7 m wide. Reverse Z keeps its precision down to 1e-9 of it.
                let gap = (scene.min.as_dvec3() - pos).max(pos - scene.max.as_dvec3()).max(glam::DVec3::ZERO);
                let cos_diagonal = 1.0 / (1.0 + tan_half * tan_half * (1.0 + aspect * aspect)).sqrt();
                let near = (dmin * 0.99).max(gap.length() * cos_diagonal * 0.99).max(far * 1e-9);
                // Beyond that the scene lies wholly outside the view: any thin volume will do.
                let near = near.min(far * 0.999);
                (reverse_z_perspective(tan_half, aspect, near, far), near, far)
            }
            Projection::Orthographic { half_height } => {
                let pad = ((dmax - dmin) * 0.01).max(1e-6 * dmax.abs().max(1.0));
                let (near, far) = (dmin - pad, dmax + pad);
                let h = half_height as f64;
                let proj = DMat4::from_cols(
                    DVec4::new(1.0 / (h * aspect), 0.0, 0.0, 0.0),
                    DVec4::new(0.0, -1.0 / h, 0.0, 0.0),
                    DVec4::new(0.0, 0.0, -1.0 / (far - near), 0.0),
                    DVec4::new(0.0, 0.0, far / (far - near), 1.0),
                );
                (proj, near, far)
            }
        };
        // Through the embedder's constructor, from the matrices rounded as an embedder holds
        // them: an embedder passing the same camera gets the same frame, bit for bit.
        let (near, far) = (near as f32, far as f32);
        Self::from_matrices(view.as_mat4(), proj.as_mat4(), true, near, far)
    }

    /// An embedder's camera: `view` (world → view) and `projection` (view → Vulkan clip, y
    /// down, depth in [0, 1]) as they render with, depth reversed (near 1, far 0) or not, and
    /// the near and far distances along the view axis that bound what it sees (finite, also
    /// for an infinite projection). Forward-Z matrices are flipped (depth → 1 − depth) so that
    /// the result is reverse-Z like [`CameraProjection::new`]'s. Errors name what is wrong.
    pub fn from_matrices(view: Mat4, projection: Mat4, reverse_z: bool, near: f32, far: f32) -> Result<Self, String> {
        let finite = |m: &Mat4| m.to_cols_array().iter().all(|v| v.is_finite());
        if !finite(&view) || !finite(&projection) {
            return Err("the camera's view and projection matrices must be finite".into());
        }
        if !(near.is_finite() && far.is_finite() && far > near) {
            return Err(format!("the camera's near ({near}) and far ({far}) must be finite with near < far"));
        }
        let view64 = view.as_dmat4();
        // z' = w − z turns forward-Z clip depth d into 1 − d.
        let flip = Mat4::from_cols(Vec4::X, Vec4::Y, Vec4::new(0.0, 0.0, -1.0, 0.0), Vec4::new(0.0, 0.0, 1.0, 1.0));
        // The product in single precision, as the embedder multiplies it to rasterize its depth:
        // positions are rebuilt through the very matrix that placed them (the double-precision
        // product rounds differently in the last bit, which moved PCF's V by a few LSB; issue 15).
        let product = projection * view;
        let view_proj = if reverse_z { product } else { flip * product }.as_dmat4();
        let det = view_proj.determinant();
        if !(det.is_finite() && det.abs() > 1e-300) || view64.determinant().abs() < 1e-300 {
            return Err("the camera's view or projection matrix is singular".into());
        }
        let inv = view_proj.inverse();
        let unproject = |x: f64, y: f64, z: f64| {
            let w = inv * DVec4::new(x, y, z, 1.0);
            w.truncate() / w.w
        };
        let position = view64.inverse().w_axis.truncate();
        // The optical axis: where the projection maps x = y = 0, from near (1) toward far.
        let forward = (unproject(0.0, 0.0, 0.5) - unproject(0.0, 0.0, 1.0)).normalize();
        if !forward.is_finite() {
            return Err("the camera's projection has no view axis".into());
        }
        let ndc_z = |d: f32| {
            let c = view_proj * (position + forward * d as f64).extend(1.0);
            c.z / c.w
        };
        let (z_near, z_far) = (ndc_z(near), ndc_z(far));
        if !(z_near.is_finite() && z_far.is_finite()) {
            return Err(format!("near {near} or far {far} falls outside the camera's projection"));
        }
        let corners = std::array::from_fn(|i| {
            let x = if i & 1 == 0 { -1.0 } else { 1.0 };
            let y = if i & 2 == 0 { -1.0 } else { 1.0 };
            unproject(x, y, if i & 4 == 0 { z_near } else { z_far }).as_vec3()
        });
        Ok(CameraProjection {
            view,
            projection,
            near,
            far,
            view_proj: view_proj.as_mat4(),
            inv_view_proj: inv.as_mat4(),
            position: position.as_vec3(),
            forward: forward.as_vec3(),
            inv64: inv,
            frustum: Hexahedron { corners },
        })
    }

    fn unproject(&self, uv: Vec2, depth: f64) -> glam::DVec3 {
        let ndc = uv.as_dvec2() * 2.0 - 1.0;
        let w = self.inv64 * DVec4::new(ndc.x, ndc.y, depth, 1.0);
        w.truncate() / w.w
    }

    /// The ray through image point `uv` ((0, 0) the top-left corner, (1, 1) the bottom-right),
    /// from the near plane: the same ray the rasterizer samples there.
    pub fn ray(&self, uv: Vec2) -> (Vec3, Vec3) {
        let (near, far) = (self.unproject(uv, 1.0), self.unproject(uv, 0.0));
        (near.as_vec3(), (far - near).normalize().as_vec3())
    }

    /// Distance along the camera's forward axis of the point at `uv` with reverse-Z `depth`.
    pub fn view_depth(&self, uv: Vec2, depth: f32) -> f32 {
        (self.unproject(uv, depth as f64) - self.position.as_dvec3()).dot(self.forward.as_dvec3()) as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene() -> Aabb {
        Aabb { min: Vec3::splat(-1.0), max: Vec3::splat(1.0) }
    }

    fn ndc(m: &Mat4, p: Vec3) -> Vec3 {
        m.project_point3(p)
    }

    #[test]
    fn right_is_plus_x_and_up_is_minus_y_in_ndc() {
        for projection in [Projection::Perspective { fov_y_deg: 45.0 }, Projection::Orthographic { half_height: 2.0 }] {
            let cam = CameraProjection::new(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, projection, 1.0, &scene())
                .unwrap();
            // Looking down −Z with +Y up, world +X is to the right and +Y is the top row.
            assert!(ndc(&cam.view_proj, Vec3::X * 0.5).x > 0.0);
            assert!(ndc(&cam.view_proj, Vec3::Y * 0.5).y < 0.0);
        }
    }

    /// An embedder's matrices, forward Z or reverse (a right-handed look-at, a [0, 1] depth
    /// perspective with y flipped for Vulkan), give the camera [`CameraProjection::new`] makes:
    /// the same position, axis and reverse-Z depth of every point.
    #[test]
    fn an_embedders_matrices_give_the_same_camera() {
        let (eye, target) = (Vec3::new(3.0, 4.0, 5.0), Vec3::ZERO);
        let ours =
            CameraProjection::new(eye, target, Vec3::Y, Projection::Perspective { fov_y_deg: 60.0 }, 1.5, &scene())
                .unwrap();
        // A right-handed look-at (view down −z) and [0, 1]-depth perspectives, y flipped for
        // Vulkan: depth 0 at `z0`, 1 at `z1`.
        let (f, s) = ((target - eye).normalize(), (target - eye).normalize().cross(Vec3::Y).normalize());
        let u = s.cross(f);
        let view = Mat4::from_cols(
            glam::Vec4::new(s.x, u.x, -f.x, 0.0),
            glam::Vec4::new(s.y, u.y, -f.y, 0.0),
            glam::Vec4::new(s.z, u.z, -f.z, 0.0),
            glam::Vec4::new(-s.dot(eye), -u.dot(eye), f.dot(eye), 1.0),
        );
        let perspective = |z0: f32, z1: f32| {
            let g = 1.0 / 30f32.to_radians().tan();
            Mat4::from_cols(
                glam::Vec4::new(g / 1.5, 0.0, 0.0, 0.0),
                glam::Vec4::new(0.0, -g, 0.0, 0.0),
                glam::Vec4::new(0.0, 0.0, z1 / (z0 - z1), -1.0),
                glam::Vec4::new(0.0, 0.0, z0 * z1 / (z0 - z1), 0.0),
            )
        };
        let proj = perspective(0.5, 20.0);
        for (proj, reverse) in [(proj, false), (perspective(20.0, 0.5), true)] {
            let theirs = CameraProjection::from_matrices(view, proj, reverse, 0.5, 20.0).unwrap();
            assert!((theirs.position - eye).length() < 1e-4, "{:?}", theirs.position);
            assert!((theirs.forward - ours.forward).length() < 1e-5);
            for p in [Vec3::new(0.3, -0.2, 0.1), Vec3::new(-1.0, 0.5, 1.0)] {
                let (a, b) = (ndc(&ours.view_proj, p), ndc(&theirs.view_proj, p));
                assert!((a.x - b.x).abs() < 1e-5 && (a.y - b.y).abs() < 1e-5, "{a} {b}");
                // Reverse Z in both (near > far), whatever the fitted planes.
                assert!(ndc(&theirs.view_proj, p - ours.forward).z > b.z, "{b}");
                assert!((theirs.inv_view_proj.project_point3(b) - p).length() < 1e-3);
            }
        }
        assert!(CameraProjection::from_matrices(view, Mat4::ZERO, false, 0.5, 20.0).is_err());
        assert!(CameraProjection::from_matrices(view, proj, false, 20.0, 0.5).is_err());
    }

    #[test]
    fn reverse_z_covers_the_scene() {
        let cam = CameraProjection::new(
            Vec3::new(3.0, 4.0, 5.0),
            Vec3::ZERO,
            Vec3::Y,
            Projection::Perspective { fov_y_deg: 60.0 },
            1.5,
            &scene(),
        )
        .unwrap();
        let near = ndc(&cam.view_proj, Vec3::splat(1.0)).z;
        let far = ndc(&cam.view_proj, Vec3::splat(-1.0)).z;
        assert!(near > far && (0.0..=1.0).contains(&near) && (0.0..=1.0).contains(&far));
        let p = Vec3::new(0.3, -0.2, 0.1);
        let back = cam.inv_view_proj.project_point3(ndc(&cam.view_proj, p));
        assert!((back - p).length() < 1e-4);
    }

    /// The engine's camera is an embedder's camera: its own single-precision matrices and planes,
    /// handed back, give the same matrices and view volume bit for bit.
    #[test]
    fn the_engines_matrices_handed_back_give_the_same_camera() {
        for projection in [Projection::Perspective { fov_y_deg: 45.0 }, Projection::Orthographic { half_height: 2.0 }] {
            let ours = CameraProjection::new(Vec3::new(0.0, 5.0, 6.0), Vec3::ZERO, Vec3::Y, projection, 1.0, &scene())
                .unwrap();
            let back = CameraProjection::from_matrices(ours.view, ours.projection, true, ours.near, ours.far).unwrap();
            assert_eq!((back.view_proj, back.inv_view_proj), (ours.view_proj, ours.inv_view_proj));
            assert_eq!(
                (back.position, back.forward, back.frustum.corners),
                (ours.position, ours.forward, ours.frustum.corners)
            );
        }
    }
}
