//! Points spread over a spherical light for Heckbert & Herf's accumulation (the `reference`
//! technique): half uniform in area over the part of the sphere that some receiver in view can
//! see, half uniform in the solid angle the light subtends at the receivers' centre, each
//! with the weight that makes the mixture an unbiased estimate of solid angle at every pixel.

use glam::{DVec3, Vec3};

/// Whether a light of `radius` at `center` is a point light to both ground truths: a radius 0
/// or subnormal (which GPUs flush to 0), or too small beside its coordinates for f32 to place
/// distinct points on it (q − centre would round to nothing), 1e-5 of them: such a light
/// subtends under 1e-5 rad from anything farther than its coordinates' size, a penumbra no
/// wider than 1e-5 of the caster's height.
pub fn point_like(center: Vec3, radius: f32) -> bool {
    radius < f32::MIN_POSITIVE || radius <= 1e-5 * center.abs().max_element()
}

/// A point of the light for the accumulation: where it is, the sphere's outward normal there
/// (zero for a point light), and its importance weight relative to uniform sampling of the
/// cap (1 for a point light).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightPoint {
    pub position: Vec3,
    pub normal: Vec3,
    pub weight: f32,
}

/// `n` points of the light sphere (`center`, `radius`) for receivers at `points`: one at the
/// centre for a [`point_like`] light; else `n − n/2` uniform in area over the [`visible_cap`]
/// and `n/2` uniform in the solid angle the sphere subtends at the receivers' mean, where a
/// huge light close to them puts nearly all of their solid angle (uniform area alone puts
/// almost no sample there: a light of radius 1e6 m 10 m above the ground shows a cap 4.5 km
/// wide, of which the 10 m under a point hold most of what it sees). Each point's weight is
/// (1 / cap area) / (the mixture's density at it), so that weighting it by its solid angle at
/// p, cos θ_q / |p − q|², times that weight is an unbiased estimate (the balance heuristic).
pub fn light_points(center: Vec3, radius: f32, points: &[Vec3], n: usize) -> Vec<LightPoint> {
    if point_like(center, radius) || n == 0 {
        return vec![LightPoint { position: center, normal: Vec3::ZERO, weight: 1.0 }];
    }
    let mean = points.iter().map(|p| p.as_dvec3()).sum::<DVec3>() / points.len().max(1) as f64;
    let (c, r) = (center.as_dvec3(), radius as f64);
    let d0 = (c - mean).length();
    // From inside the light (or with nothing in view) the whole cap is uniform in area.
    let towards = (!points.is_empty() && d0 > r).then_some(mean);
    let with_mean: Vec<Vec3> = points.iter().copied().chain(towards.map(|m| m.as_vec3())).collect();
    let cap = visible_cap(center, radius, &with_mean);
    let in_cone = if towards.is_some() { n / 2 } else { 0 };
    let uniform = n - in_cone;
    // 1 − cos of the cap's and of the cone's half-angles, without cancellation.
    let cap_height = 1.0 - cap.cos_half_angle as f64;
    let sin2 = (r / d0).powi(2);
    let cone_height = sin2 / (1.0 + (1.0 - sin2).max(0.0).sqrt());
    // The cap's area times the cone's density at q, per unit of the sphere's area r²:
    // A_cap · pdf_cone(q) = r² · cap_height · cos θ_q / (|p0 − q|² · cone_height).
    let cone_density = |q: DVec3, normal: DVec3| match towards {
        Some(p0) => {
            let to_p0 = p0 - q;
            let cos = normal.dot(to_p0) / to_p0.length();
            (r * r * cap_height * cos.max(0.0) / (to_p0.length_squared() * cone_height)).max(0.0)
        }
        None => 0.0,
    };
    let (fu, fc) = (uniform as f64 / n as f64, in_cone as f64 / n as f64);
    let golden_angle = std::f64::consts::PI * (3.0 - 5.0f64.sqrt());
    let point = |q: DVec3, normal: DVec3| LightPoint {
        position: q.as_vec3(),
        normal: normal.as_vec3(),
        weight: (1.0 / (fu + fc * cone_density(q, normal))) as f32,
    };
    let mut out = Vec::with_capacity(n);
    let axis = cap.axis.as_dvec3();
    let (u, v) = axis.any_orthonormal_pair();
    for i in 0..uniform {
        let one_minus_z = cap_height * (i as f64 + 0.5) / uniform as f64;
        let (z, ring) = (1.0 - one_minus_z, (one_minus_z * (2.0 - one_minus_z)).max(0.0).sqrt());
        let phi = golden_angle * i as f64;
        let normal = ring * (phi.cos() * u + phi.sin() * v) + z * axis;
        out.push(point(c + r * normal, normal));
    }
    if let Some(p0) = towards {
        let axis = (c - p0) / d0;
        let (u, v) = axis.any_orthonormal_pair();
        let c2 = (d0 - r) * (d0 + r);
        for i in 0..in_cone {
            let one_minus_cos = cone_height * (i as f64 + 0.5) / in_cone as f64;
            let (cos, sin) = (1.0 - one_minus_cos, (one_minus_cos * (2.0 - one_minus_cos)).max(0.0).sqrt());
            let phi = golden_angle * (i as f64 + 0.5);
            let dir = cos * axis + sin * (phi.cos() * u + phi.sin() * v);
            // The near side of the sphere along `dir`: t = (d² − r²) / (b + √(b² − d² + r²)).
            let b = dir.dot(c - p0);
            let q = p0 + dir * (c2 / (b + (b * b - c2).max(0.0).sqrt()));
            out.push(point(q, ((q - c) / r).normalize()));
        }
    }
    out
}

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
        fn light_points_lie_on_the_sphere_with_positive_weights(
            receivers in proptest::collection::vec(vec3(), 1..6), radius in 0.01f32..2.0, n in 1usize..300,
        ) {
            let center = Vec3::new(1.0, 12.0, 3.0);
            let points = light_points(center, radius, &receivers, n);
            prop_assert_eq!(points.len(), n);
            for q in &points {
                prop_assert!(((q.position - center).length() - radius).abs() < 1e-4 * (1.0 + radius));
                prop_assert!((q.normal.length() - 1.0).abs() < 1e-5);
                prop_assert!(q.weight.is_finite() && q.weight > 0.0 && q.weight <= n as f32);
            }
        }
    }

    /// The weighted points estimate the solid angle of the light at any receiver: Σ w · cos θ_q
    /// / |p − q|² over the points, normalised as the accumulation does, matches 2π(1 − cos α).
    #[test]
    fn weighted_points_estimate_the_solid_angle() {
        for (radius, height) in [(0.5f32, 10.0f32), (1e6, 1e6 + 10.0), (2.0, 3.0)] {
            let center = Vec3::new(0.3, height, -0.2);
            let receivers = [Vec3::new(-1.0, 0.0, -1.0), Vec3::new(1.0, 0.0, 1.0), Vec3::new(0.5, 0.0, -0.7)];
            let points = light_points(center, radius, &receivers, 4096);
            let cap = visible_cap(center, radius, &[&receivers[..], &[Vec3::new(1.0 / 6.0, 0.0, -0.7 / 3.0)]].concat());
            let cap_area = std::f64::consts::TAU * (radius as f64).powi(2) * (1.0 - cap.cos_half_angle as f64);
            for p in receivers {
                let sum: f64 = points
                    .iter()
                    .map(|q| {
                        let to_p = (p - q.position).as_dvec3();
                        let cos = q.normal.as_dvec3().dot(to_p) / to_p.length();
                        cos.max(0.0) / to_p.length_squared() * q.weight as f64
                    })
                    .sum();
                let estimate = sum * cap_area / points.len() as f64;
                let d = (center - p).length() as f64;
                let sin2 = (radius as f64 / d).powi(2);
                let exact = std::f64::consts::TAU * sin2 / (1.0 + (1.0 - sin2).sqrt());
                assert!((estimate / exact - 1.0).abs() < 0.03, "r {radius} at {p}: {estimate} vs {exact}");
            }
        }
    }

    #[test]
    fn lights_too_small_for_f32_are_points() {
        assert!(point_like(Vec3::new(3.0, 3.0, 0.0), 1e-8) && point_like(Vec3::ONE, 1e-40));
        assert!(!point_like(Vec3::new(3.0, 3.0, 0.0), 1e-3) && !point_like(Vec3::ZERO, 1e-30));
        let points = light_points(Vec3::new(3.0, 3.0, 0.0), 1e-8, &[Vec3::ZERO], 64);
        assert_eq!(points, vec![LightPoint { position: Vec3::new(3.0, 3.0, 0.0), normal: Vec3::ZERO, weight: 1.0 }]);
    }

    #[test]
    fn points_inside_the_light_see_all_of_it() {
        let cap = visible_cap(Vec3::ZERO, 1.0, &[Vec3::new(0.0, 0.5, 0.0), Vec3::new(0.0, -9.0, 0.0)]);
        assert_eq!(cap.cos_half_angle, -1.0);
    }
}
