//! Parker, Shirley & Smits, "Single Sample Soft Shadows" (1998): one shadow ray per pixel, to
//! the light's centre. Each occluder is its own opaque inner object plus a semi-opaque outer
//! object grown by b = a·D/A (§3, Figure 3: a the distance from p to the occluder along the ray,
//! A the distance to the light, D the light's diameter), so the penumbra is the shadow of the
//! outer shell. τ runs from 0 at the inner surface to 1 at the outer one; the attenuation is
//! the Bernstein interpolant s = 3τ² − 2τ³ of the straight-edge sinusoid (§3). Occluders combine
//! by thresholding, s = min(s₁, s₂, …), which §3 prefers because a ray grazing many objects
//! then never makes the shadow darker than it should be.
//!
//! Spheres are exact (Appendix: the outer object is a sphere of radius R + b). Triangles follow
//! the Appendix's "triangle with rounded corners" whose per-edge offset depends on the angle
//! between the triangle and the ray: measured in the plane perpendicular to the ray, the outer
//! object is exactly the projected triangle grown by b, corners rounded, which is what the
//! distance from the ray to the projected triangle gives.

use glam::{Vec2, Vec3};
use parry3d::bounding_volume::Aabb as ParryAabb;
use parry3d::partitioning::TraversalAction;

use super::{Surface, TraceScene};
use crate::scene::Light;

/// The Bernstein interpolant of §3.
fn profile(tau: f32) -> f32 {
    let t = tau.clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// The shadow ray of one pixel: from `origin` along unit `dir` to the light at `length`.
struct ShadowRay {
    origin: Vec3,
    dir: Vec3,
    length: f32,
    /// The light's diameter D.
    diameter: f32,
    /// A basis of the plane perpendicular to the ray.
    u: Vec3,
    v: Vec3,
}

impl ShadowRay {
    /// b at ray distance `t` (Appendix: a ≈ t₀, A ≈ |l − o|).
    fn outer_offset(&self, t: f32) -> f32 {
        self.diameter * t / self.length
    }

    /// Attenuation by a sphere (Appendix).
    fn sphere(&self, center: Vec3, radius: f32) -> f32 {
        let t0 = (center - self.origin).dot(self.dir);
        if t0 <= 0.0 || t0 - radius >= self.length {
            return 1.0;
        }
        let d = (self.origin + t0 * self.dir - center).length();
        if d < radius {
            return 0.0;
        }
        let b = self.outer_offset(t0);
        if d >= radius + b { 1.0 } else { profile((d - radius) / b) }
    }

    /// Attenuation by a triangle: 0 when the ray crosses it between the point and the light,
    /// else the profile of (distance from the ray to the projected triangle) / b, with b taken
    /// at the triangle's nearest point.
    fn triangle(&self, corners: [Vec3; 3]) -> f32 {
        let rel = corners.map(|c| c - self.origin);
        let flat = rel.map(|r| Vec2::new(r.dot(self.u), r.dot(self.v)));
        let along = rel.map(|r| r.dot(self.dir));
        let (distance, [w0, w1, w2]) = distance_to_triangle(flat);
        let t = w0 * along[0] + w1 * along[1] + w2 * along[2];
        if t <= 0.0 || t >= self.length {
            return 1.0;
        }
        if distance == 0.0 {
            return 0.0;
        }
        let b = self.outer_offset(t);
        if distance >= b { 1.0 } else { profile(distance / b) }
    }

    /// Whether anything within this box could attenuate the ray: the box's bounding sphere
    /// must come within b of the ray somewhere between the point and the light.
    fn may_reach(&self, aabb: &ParryAabb) -> bool {
        let center = aabb.center() - self.origin;
        let radius = aabb.half_extents().length();
        let t = center.dot(self.dir);
        if t + radius <= 0.0 || t - radius >= self.length {
            return false;
        }
        let off_axis = (center - t * self.dir).length();
        off_axis - radius <= self.outer_offset((t + radius).min(self.length))
    }
}

/// Distance from the origin to a 2D triangle (0 inside) and the barycentric weights of the
/// triangle's nearest point. Degenerate (edge-on) triangles reduce to their edges.
fn distance_to_triangle(p: [Vec2; 3]) -> (f32, [f32; 3]) {
    let area = (p[1] - p[0]).perp_dot(p[2] - p[0]);
    if area != 0.0 {
        // Signed areas of the sub-triangles opposite each corner.
        let w = [p[1].perp_dot(p[2]) / area, p[2].perp_dot(p[0]) / area, p[0].perp_dot(p[1]) / area];
        if w.iter().all(|&x| x >= 0.0) {
            return (0.0, w);
        }
    }
    let mut best = (f32::INFINITY, [1.0, 0.0, 0.0]);
    for (i, j) in [(0, 1), (1, 2), (2, 0)] {
        let e = p[j] - p[i];
        let s = if e.length_squared() > 0.0 { (-p[i].dot(e) / e.length_squared()).clamp(0.0, 1.0) } else { 0.0 };
        let d = (p[i] + s * e).length();
        if d < best.0 {
            let mut w = [0.0; 3];
            w[i] = 1.0 - s;
            w[j] = s;
            best = (d, w);
        }
    }
    best
}

impl TraceScene {
    /// Parker et al.'s attenuation at `s`: one ray to the light's centre.
    pub fn parker(&self, s: Surface, light: &Light) -> f32 {
        let p = s.point;
        let to_light = light.position - p;
        let length = to_light.length();
        if length <= light.radius {
            return 1.0;
        }
        let dir = to_light / length;
        if s.solid_side.is_some_and(|n| n.dot(dir) <= 0.0) {
            return 0.0; // the caster's own surface faces away from the light
        }
        let (u, v) = dir.any_orthonormal_pair();
        let ray = ShadowRay { origin: p, dir, length, diameter: 2.0 * light.radius, u, v };
        let mut v = 1.0f32;
        for (center, radius) in self.spheres.iter().flatten() {
            v = v.min(ray.sphere(*center, *radius));
        }
        let Some(casters) = &self.casters else { return v };
        casters.bvh().traverse(|node| {
            if v == 0.0 {
                return TraversalAction::EarlyExit;
            }
            if !ray.may_reach(&node.aabb()) {
                return TraversalAction::Prune;
            }
            if let Some(tri) = node.leaf_data() {
                // Exact spheres were handled above; their tessellation must not count twice.
                if self.spheres[self.caster_object_of[tri as usize] as usize].is_none() {
                    let t = casters.triangle(tri);
                    v = v.min(ray.triangle([t.a, t.b, t.c]));
                }
            }
            TraversalAction::Continue
        });
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// §3's Bernstein interpolant in closed form, in f64: s = 3τ² − 2τ³.
    fn bernstein(t: f64) -> f64 {
        3.0 * t * t - 2.0 * t * t * t
    }

    /// §3's straight-edge sinusoid, s = (1 + sin(πτ − π/2)) / 2, which the cubic stands in for.
    fn sinusoid(t: f64) -> f64 {
        (1.0 + (std::f64::consts::PI * t - std::f64::consts::FRAC_PI_2).sin()) / 2.0
    }

    #[test]
    fn the_profile_is_the_bernstein_cubic_at_every_tau() {
        // Exact rationals inside the shell: 3/16 − 2/64 = 5/32 and 27/16 − 54/64 = 27/32 (the
        // sinusoid gives 0.1464 and 0.8536 there, the identity 1/4 and 3/4).
        assert!((profile(0.25) - 5.0 / 32.0).abs() < 1e-6, "s(1/4) = {}", profile(0.25));
        assert!((profile(0.75) - 27.0 / 32.0).abs() < 1e-6, "s(3/4) = {}", profile(0.75));
        for i in 0..=512 {
            let t = i as f64 / 512.0;
            let s = profile(t as f32) as f64;
            assert!((s - bernstein(t)).abs() < 1e-6, "s({t}) = {s}, 3τ² − 2τ³ = {}", bernstein(t));
        }
        // Outside the shell: fully dark inside the inner object, fully lit past the outer one.
        assert_eq!((profile(-0.5), profile(1.5)), (0.0, 1.0));
    }

    #[test]
    fn the_profile_shares_the_sinusoids_ends_but_is_a_polynomial() {
        // §3: the same values and derivatives as the sinusoid at τ = 0 and τ = 1 (both slopes
        // 0, so the shadow has no crease at the penumbra's borders)...
        let h = 1e-3f32;
        for (t, s) in [(0.0, 0.0), (1.0, 1.0)] {
            assert!((profile(t) as f64 - sinusoid(t as f64)).abs() < 1e-6 && profile(t) == s);
        }
        let (slope0, slope1) = (profile(h) / h, (1.0 - profile(1.0 - h)) / h);
        assert!(slope0 < 1e-2 && slope1 < 1e-2, "end slopes {slope0} {slope1}, should be 0");
        // ... and the cubic's slope at ½ is 3/2 where the sinusoid's is π/2 and the identity's 1.
        let mid = (profile(0.5 + h) - profile(0.5 - h)) as f64 / (2.0 * h as f64);
        assert!((mid - 1.5).abs() < 1e-2, "slope at 1/2: {mid}");
        // Between the ends it is not the sinusoid: they part by about 0.01 (at τ ≈ 0.2, 0.8).
        let apart = (0..=100).map(|i| i as f64 / 100.0).map(|t| (profile(t as f32) as f64 - sinusoid(t)).abs());
        let apart = apart.fold(0.0, f64::max);
        assert!(apart > 5e-3 && apart < 2e-2, "max |cubic − sinusoid| = {apart}");
    }

    #[test]
    fn the_profile_rises_monotonically_and_symmetrically_about_a_half() {
        let mut last = profile(0.0);
        for i in 1..=1000 {
            let t = i as f32 / 1000.0;
            let s = profile(t);
            assert!(s >= last, "falls at τ = {t}: {s} < {last}");
            // Point-symmetric about (½, ½): s(τ) + s(1 − τ) = 1.
            assert!((s + profile(1.0 - t) - 1.0).abs() < 1e-6, "not symmetric at τ = {t}");
            last = s;
        }
    }

    #[test]
    fn distances_to_a_triangle() {
        let tri = [Vec2::new(1.0, -1.0), Vec2::new(3.0, -1.0), Vec2::new(1.0, 1.0)];
        let (d, w) = distance_to_triangle(tri);
        assert!((d - 1.0).abs() < 1e-6 && (w[0] + w[2] - 1.0).abs() < 1e-6, "{d} {w:?}");
        let inside = tri.map(|p| p - Vec2::new(1.5, 0.0));
        assert_eq!(distance_to_triangle(inside).0, 0.0);
        // Edge-on: the triangle collapses to a segment.
        let (d, _) = distance_to_triangle([Vec2::new(2.0, -1.0), Vec2::new(2.0, 1.0), Vec2::new(2.0, 0.0)]);
        assert!((d - 2.0).abs() < 1e-6);
    }

    #[test]
    fn a_sphere_shadow_is_hard_inside_and_soft_at_its_rim() {
        let ray = ShadowRay { origin: Vec3::ZERO, dir: Vec3::Y, length: 10.0, diameter: 1.0, u: Vec3::X, v: Vec3::Z };
        assert_eq!(ray.sphere(Vec3::new(0.5, 5.0, 0.0), 1.0), 0.0);
        // b = D·t0/A = 0.5: halfway through the outer shell.
        assert!((ray.sphere(Vec3::new(1.25, 5.0, 0.0), 1.0) - 0.5).abs() < 1e-5);
        // A quarter and three quarters through the shell: the cubic's 5/32 and 27/32.
        assert!((ray.sphere(Vec3::new(1.125, 5.0, 0.0), 1.0) - 5.0 / 32.0).abs() < 1e-5);
        assert!((ray.sphere(Vec3::new(1.375, 5.0, 0.0), 1.0) - 27.0 / 32.0).abs() < 1e-5);
        assert_eq!(ray.sphere(Vec3::new(1.6, 5.0, 0.0), 1.0), 1.0);
        // Behind the point: no shadow.
        assert_eq!(ray.sphere(Vec3::new(0.0, -5.0, 0.0), 1.0), 1.0);
    }
}
