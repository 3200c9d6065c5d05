//! The spot frustum a shadow map is rendered through, fitted every frame.
//!
//! A point can only be shadowed if the segment to the light crosses a caster, so only the
//! casters that meet the hull of the light and the receivers in view matter; of those, the
//! frustum covers their angular extent from the light where a receiver is in view behind them:
//! the window is the union, over those casters, of each caster's window cut to the receivers'.
//! Everything outside it is lit. The aim follows the window (it is re-centred on it), so a far
//! caster that shadows nothing in view, or a `light.target` pointing away, cannot push the
//! casters that matter out of the frustum. What one frustum cannot hold (a light among its
//! casters) is reported by caster, never dropped silently.

use glam::{DMat4, DVec3, DVec4, Mat4, Vec3, Vec4};

use super::Aabb;

/// Widest half-angle a single frustum covers (tan 80°); casters beyond it (a light among its
/// casters) are clipped and reported in [`SpotFit::clipped`], which a cube map would fix.
const MAX_TAN: f64 = 5.671;

/// The projection centre is kept within this many times the extent of what is fitted (casters
/// that matter and receivers in view): farther, linear depth in f32 cannot tell a caster from
/// the receiver behind it (the ulp at 1e8 m is 8 m), so a farther light is moved towards the
/// scene along its own direction. Its rays then change direction by at most 1/256 rad across
/// the scene, while the depth ulp stays below a tenth of a 2048² texel.
const MAX_RANGE: f64 = 256.0;

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
    /// The projection centre's distance from the scene over the light's: 1, or less where a far
    /// light was moved closer. Techniques that size penumbrae from light depths by similar
    /// triangles (smoothies' t = R / b) take the light's radius times this, the light of the
    /// same angular size at the projection centre; a 5e5 m sun 1e8 m away seen from 5 km with
    /// its own radius would span 90° instead of 0.3°.
    pub light_scale: f32,
}

/// What [`fit_spot_frustum`] found.
#[derive(Clone, Debug, PartialEq)]
pub struct SpotFit {
    /// `None` when no caster can shadow a receiver in view (nothing to render).
    pub frustum: Option<LightFrustum>,
    /// Indices into the casters of those that can shadow a receiver in view but reach beyond
    /// what one frustum holds (±80° around its axis, or behind the light): their shadows are
    /// cut at the frustum's edge. Empty when every shadow in view is covered.
    pub clipped: Vec<usize>,
}

/// Fits the frustum from `light` to the `casters` (world boxes) that can shadow one of the
/// `receivers`' points in view (their hull). `hint` (`light.target`) is where the spot looks
/// first; the aim is then re-centred on the window, so it cannot make the frustum miss a
/// caster that matters.
pub fn fit_spot_frustum(light: Vec3, hint: Option<Vec3>, casters: &[Aabb], receivers: &[Vec3]) -> SpotFit {
    let none = SpotFit { frustum: None, clipped: Vec::new() };
    if casters.is_empty() || receivers.is_empty() {
        return none;
    }
    let l = light.as_dvec3();
    let receivers: Vec<DVec3> = receivers.iter().map(|p| p.as_dvec3()).collect();
    let (rmin, rmax) = bounds(receivers.iter().copied());
    let relevant: Vec<usize> = (0..casters.len()).filter(|&i| can_shadow(l, &casters[i], rmin, rmax)).collect();
    if relevant.is_empty() {
        return none;
    }
    let boxes: Vec<[DVec3; 8]> = relevant.iter().map(|&i| casters[i].corners().map(Vec3::as_dvec3)).collect();

    // A light much farther than the scene is wide is moved closer along its direction.
    let (smin, smax) = bounds(boxes.iter().flatten().copied().chain([rmin, rmax]));
    let centre = (smin + smax) * 0.5;
    let extent = (smax - smin).length().max(f64::MIN_POSITIVE);
    let distance = (l - centre).length();
    let light_scale = nearer_light_scale(distance, extent);
    let origin = centre + (l - centre) * light_scale;

    // Start from the hint and from the casters' mean direction; keep the narrower window.
    let mean = boxes.iter().flatten().filter_map(|c| (*c - origin).try_normalize()).sum::<DVec3>();
    let fallback = receivers.iter().filter_map(|r| (*r - origin).try_normalize()).sum::<DVec3>();
    let starts =
        [hint.and_then(|t| (t.as_dvec3() - l).try_normalize()), mean.try_normalize(), fallback.try_normalize()];
    let mut best: Option<(f64, Frame)> = None;
    for start in starts.into_iter().flatten() {
        let mut frame = Frame::new(origin, start, &boxes, &receivers);
        for _ in 0..6 {
            let score = frame.half_width();
            if best.as_ref().is_none_or(|(b, _)| score < *b) {
                best = Some((score, frame.clone()));
            }
            let Some(next) = frame.recentred() else { break };
            frame = Frame::new(origin, next, &boxes, &receivers);
        }
    }
    let Some((_, frame)) = best else {
        return none;
    };

    let clipped: Vec<usize> = relevant
        .iter()
        .zip(&frame.windows)
        .filter(|(_, w)| w.is_some_and(|w| w.iter().any(|v| v.abs() > MAX_TAN)))
        .map(|(&i, _)| i)
        .collect();
    let Some(w) = frame.window() else {
        return SpotFit { frustum: None, clipped };
    };
    let mut w = [w[0].max(-MAX_TAN), w[1].max(-MAX_TAN), w[2].min(MAX_TAN), w[3].min(MAX_TAN)];
    if w[0] >= w[2] || w[1] >= w[3] {
        return SpotFit { frustum: None, clipped };
    }
    // Pad by 1% (the 2×2 filter reads one texel beyond) and keep a point-like caster non-degenerate.
    let pad_x = ((w[2] - w[0]) * 0.01).max(1e-6);
    let pad_y = ((w[3] - w[1]) * 0.01).max(1e-6);
    w = [w[0] - pad_x, w[1] - pad_y, w[2] + pad_x, w[3] + pad_y];
    let caster_z = boxes.iter().flatten().map(|p| frame.view.transform_point3(*p).z);
    let far = caster_z.clone().fold(f64::NEG_INFINITY, f64::max);
    let near = caster_z.fold(f64::INFINITY, f64::min).max(far * 1e-4);
    // The depth range reaches the receivers too: `far` is then the farthest receiver, which
    // bounds how far a smoothie can matter; depth is linear in the colour target anyway.
    let far = receivers.iter().map(|p| frame.view.transform_point3(*p).z).fold(far, f64::max) * 1.001;
    SpotFit { frustum: Some(frustum(frame.view, w, near, far, light_scale as f32)), clipped }
}

/// How much nearer a light `distance` from the centre of a scene `extent` wide is taken, along
/// its own direction, for f32 to resolve the scene in its depths or projections ([`MAX_RANGE`]):
/// 1, or the factor that brings it to `MAX_RANGE` extents. Its radius scales by the same, which
/// keeps the light's angular size from the scene.
pub fn nearer_light_scale(distance: f64, extent: f64) -> f64 {
    (MAX_RANGE * extent / distance).min(1.0)
}

/// A light at `light` of `radius`, taken nearer for f32 projections ([`nearer_light_scale`])
/// to the scene that matters: the `receivers` in view and the `casters` (world boxes) that can
/// shadow them (a ball 53 km off kept a light 2e6 m away where a 1.7 cm cube lost its shadow).
/// The position and radius of the light of the same direction and angular size from there.
pub fn nearer_light(light: Vec3, radius: f32, casters: &[Aabb], receivers: &[Vec3]) -> (Vec3, f32) {
    let l = light.as_dvec3();
    let seen = Aabb::from_points(receivers.iter().copied());
    let (rmin, rmax) = (seen.min.as_dvec3(), seen.max.as_dvec3());
    let scene = casters.iter().filter(|c| can_shadow(l, c, rmin, rmax)).fold(seen, |b, c| b.union(c));
    if scene.is_empty() {
        return (light, radius);
    }
    let centre = scene.center().as_dvec3();
    let extent = (scene.max - scene.min).as_dvec3().length().max(f64::MIN_POSITIVE);
    let k = nearer_light_scale((l - centre).length(), extent);
    ((centre + (l - centre) * k).as_vec3(), (f64::from(radius) * k) as f32)
}

/// Whether the box meets the hull of `light` and the box `rmin`..`rmax`: some t ≥ 1 scales
/// the caster's box about the light onto the receivers' (a segment from the light to a
/// receiver crosses the caster). Exact for boxes, in f64.
fn can_shadow(light: DVec3, caster: &Aabb, rmin: DVec3, rmax: DVec3) -> bool {
    let (cmin, cmax) = (caster.min.as_dvec3() - light, caster.max.as_dvec3() - light);
    let (mut lo, mut hi) = (1.0f64, f64::INFINITY);
    for k in 0..3 {
        // t·cmin ≤ rmax − light and t·cmax ≥ rmin − light, on each axis.
        for (a, b) in [(cmin[k], rmax[k] - light[k]), (-cmax[k], light[k] - rmin[k])] {
            if a > 0.0 {
                hi = hi.min(b / a);
            } else if a < 0.0 {
                lo = lo.max(b / a);
            } else if b < 0.0 {
                return false;
            }
        }
    }
    lo <= hi
}

fn bounds(points: impl Iterator<Item = DVec3>) -> (DVec3, DVec3) {
    points.fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| (lo.min(p), hi.max(p)))
}

/// A light view and, per caster that matters, its window cut to the receivers' (`None`: they
/// do not overlap in this view).
#[derive(Clone)]
struct Frame {
    view: DMat4,
    windows: Vec<Option<[f64; 4]>>,
}

impl Frame {
    fn new(origin: DVec3, z_axis: DVec3, boxes: &[[DVec3; 8]], receivers: &[DVec3]) -> Frame {
        let view = look_along(origin, z_axis);
        let to_view = |p: &DVec3| view.transform_point3(*p);
        let receiver = tangent_window(receivers.iter().map(to_view));
        let windows = boxes
            .iter()
            .map(|b| {
                let c = tangent_window(b.iter().map(to_view));
                let w = [c[0].max(receiver[0]), c[1].max(receiver[1]), c[2].min(receiver[2]), c[3].min(receiver[3])];
                (w[0] < w[2] && w[1] < w[3]).then_some(w)
            })
            .collect();
        Frame { view, windows }
    }

    /// The union of the casters' windows.
    fn window(&self) -> Option<[f64; 4]> {
        self.windows.iter().flatten().fold(None, |acc: Option<[f64; 4]>, w| {
            Some(acc.map_or(*w, |a| [a[0].min(w[0]), a[1].min(w[1]), a[2].max(w[2]), a[3].max(w[3])]))
        })
    }

    /// The largest tangent the window reaches (infinite: beyond the light's side plane).
    fn half_width(&self) -> f64 {
        self.window().map_or(f64::INFINITY, |w| w.iter().fold(0.0, |m, v| m.max(v.abs())))
    }

    /// The direction through the window's centre, when it is bounded.
    fn recentred(&self) -> Option<DVec3> {
        let w = self.window().filter(|w| w.iter().all(|v| v.is_finite()))?;
        let centre = DVec3::new((w[0] + w[2]) * 0.5, (w[1] + w[3]) * 0.5, 1.0);
        self.view.inverse().transform_vector3(centre).try_normalize()
    }
}

/// World → view from `origin` with +Z along `z_axis`.
fn look_along(origin: DVec3, z_axis: DVec3) -> DMat4 {
    let hint = if z_axis.y.abs() < 0.99 { DVec3::Y } else { DVec3::X };
    let x_axis = hint.cross(z_axis).normalize();
    let y_axis = z_axis.cross(x_axis);
    DMat4::from_cols(
        DVec4::new(x_axis.x, y_axis.x, z_axis.x, 0.0),
        DVec4::new(x_axis.y, y_axis.y, z_axis.y, 0.0),
        DVec4::new(x_axis.z, y_axis.z, z_axis.z, 0.0),
        DVec4::new(-x_axis.dot(origin), -y_axis.dot(origin), -z_axis.dot(origin), 1.0),
    )
}

fn frustum(view: DMat4, w: [f64; 4], near: f64, far: f64, light_scale: f32) -> LightFrustum {
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
        light_scale,
    }
}

impl LightFrustum {
    /// The projection centre in world space: the light's centre, or the point a far light was
    /// moved to along its direction (`light_scale` < 1). Depths are distances from it.
    pub fn centre(&self) -> Vec3 {
        self.view.inverse().transform_point3(Vec3::ZERO)
    }

    /// The tangent window (x/z, y/z) of a box seen through this view; unbounded if part of it
    /// lies at or behind the light.
    pub fn window_of(&self, bounds: &Aabb) -> [f32; 4] {
        let view = self.view.as_dmat4();
        tangent_window(bounds.corners().into_iter().map(|c| view.transform_point3(c.as_dvec3()))).map(|v| v as f32)
    }

    /// `LightView::depths`: near, far, log2(far / near), 0.
    pub fn depths(&self) -> Vec4 {
        Vec4::new(self.near, self.far, (self.far / self.near).log2(), 0.0)
    }

    /// The same frustum with its window grown by `pad` tangent units on every side (geometry
    /// drawn around the casters, such as smoothies), still within ±tan 80°.
    pub fn grown(&self, pad: f32) -> LightFrustum {
        let [x0, y0, x1, y1] = self.window.map(f64::from);
        let pad = f64::from(pad);
        let w = [(x0 - pad).max(-MAX_TAN), (y0 - pad).max(-MAX_TAN), (x1 + pad).min(MAX_TAN), (y1 + pad).min(MAX_TAN)];
        frustum(self.view.as_dmat4(), w, f64::from(self.near), f64::from(self.far), self.light_scale)
    }
}

/// Bounds of x/z and y/z over points in front of the light; unbounded (±∞) if one is not.
fn tangent_window(points: impl Iterator<Item = DVec3>) -> [f64; 4] {
    let mut w = [f64::INFINITY, f64::INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY];
    for p in points {
        if p.z <= 0.0 {
            return [f64::NEG_INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::INFINITY];
        }
        let (tx, ty) = (p.x / p.z, p.y / p.z);
        w = [w[0].min(tx), w[1].min(ty), w[2].max(tx), w[3].max(ty)];
    }
    w
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn ground() -> Vec<Vec3> {
        Aabb { min: Vec3::new(-10.0, 0.0, -10.0), max: Vec3::new(10.0, 0.0, 10.0) }.corners().to_vec()
    }

    fn cube(c: Vec3, half: f32) -> Aabb {
        Aabb { min: c - Vec3::splat(half), max: c + Vec3::splat(half) }
    }

    /// Whether world point `p` lands inside the frustum's clip volume.
    fn inside(f: &LightFrustum, p: Vec3) -> bool {
        let clip = f.view_proj * p.extend(1.0);
        let ndc = clip.truncate() / clip.w;
        clip.w > 0.0 && ndc.x.abs() <= 1.0 + 1e-4 && ndc.y.abs() <= 1.0 + 1e-4 && ndc.z >= -1e-4 && ndc.z <= 1.0 + 1e-4
    }

    #[test]
    fn no_casters_needs_no_frustum() {
        assert!(fit_spot_frustum(Vec3::Y * 5.0, None, &[], &ground()).frustum.is_none());
    }

    #[test]
    fn receivers_away_from_the_casters_need_no_frustum() {
        let caster = Aabb { min: Vec3::new(-0.5, 1.0, -0.5), max: Vec3::new(0.5, 2.0, 0.5) };
        let far_receiver = Aabb { min: Vec3::new(50.0, 0.0, 50.0), max: Vec3::new(51.0, 0.0, 51.0) }.corners();
        let fit = fit_spot_frustum(Vec3::Y * 5.0, None, &[caster], &far_receiver);
        assert!(fit.frustum.is_none() && fit.clipped.is_empty());
    }

    #[test]
    fn a_caster_that_shadows_nothing_in_view_is_left_out() {
        let near = cube(Vec3::new(0.0, 0.5, 0.0), 0.5);
        let far = cube(Vec3::new(50.0, 0.5, 0.0), 0.5);
        let view: Vec<Vec3> = ground().iter().map(|p| *p * 0.3).collect();
        let light = Vec3::new(1.0, 6.0, 0.5);
        let alone = fit_spot_frustum(light, None, &[near], &view);
        let both = fit_spot_frustum(light, None, &[near, far], &view);
        assert_eq!(alone, both, "the far box changes nothing");
        assert!(both.clipped.is_empty());
    }

    #[test]
    fn a_hint_pointing_away_cannot_lose_the_casters() {
        let caster = cube(Vec3::new(0.0, 0.5, 0.0), 0.5);
        let light = Vec3::new(1.0, 6.0, 0.5);
        for hint in [Vec3::new(1.0, 100.0, 0.5), Vec3::new(40.0, 0.0, 0.0), light] {
            let f = fit_spot_frustum(light, Some(hint), &[caster], &ground()).frustum.unwrap();
            assert!(caster.corners().iter().all(|c| inside(&f, *c)), "hint {hint}");
        }
    }

    #[test]
    fn a_light_among_its_casters_names_those_it_cuts() {
        // Just above the ground between two walls, the light sees them 170° apart.
        let walls = [
            Aabb { min: Vec3::new(-4.0, 0.0, -1.0), max: Vec3::new(-3.9, 1.0, 1.0) },
            Aabb { min: Vec3::new(3.9, 0.0, -1.0), max: Vec3::new(4.0, 1.0, 1.0) },
            cube(Vec3::new(30.0, 30.0, 30.0), 0.5), // behind the light from the ground: no shadow
        ];
        let fit = fit_spot_frustum(Vec3::new(0.0, 0.2, 0.0), None, &walls, &ground());
        assert!(fit.frustum.is_some());
        assert!(!fit.clipped.is_empty() && fit.clipped.iter().all(|&i| i < 2), "{:?}", fit.clipped);
    }

    #[test]
    fn a_light_1e8_away_keeps_f32_depth_sound() {
        let caster = cube(Vec3::new(0.0, 0.5, 0.0), 0.5);
        let view: Vec<Vec3> = ground().iter().map(|p| *p * 0.3).collect();
        let light = Vec3::new(0.3, 0.8, 0.2) * 1e8;
        let f = fit_spot_frustum(light, None, &[caster], &view).frustum.unwrap();
        // The projection centre is at most MAX_RANGE scene widths away (f32 depth ulp ≪ 1 cm).
        assert!(f.far < 1e4, "far {}", f.far);
        assert!(caster.corners().iter().all(|c| inside(&f, *c)));
        // Its rays keep the light's direction.
        let axis = f.view.inverse().transform_vector3(Vec3::Z);
        assert!(axis.dot(-light.normalize()) > 0.99, "{axis}");
        // A light's radius times light_scale spans the same angle from the scene at the centre.
        let ratio = (f.centre() - caster.center()).length() / (light - caster.center()).length();
        assert!((f.light_scale / ratio - 1.0).abs() < 0.01, "scale {} for {ratio}", f.light_scale);
        // A caster's top is nearer than the ground below it, by more than the f32 depth ulp.
        let z = |p: Vec3| (f.view * p.extend(1.0)).z;
        assert!(z(Vec3::ZERO) - z(Vec3::Y) > 0.5, "{} {}", z(Vec3::ZERO), z(Vec3::Y));
    }

    /// Random boxes near the origin (up to 4), a light at `light`, receivers on a ground patch.
    fn layout(boxes: &[([f32; 3], [f32; 3])]) -> Vec<Aabb> {
        boxes.iter().map(|(c, s)| Aabb { min: Vec3::from(*c), max: Vec3::from(*c) + Vec3::from(*s) }).collect()
    }

    /// Whether every caster direction from `light` lies within 70° of their mean.
    fn within_one_frustum(light: Vec3, casters: &[Aabb]) -> bool {
        let dirs: Vec<Vec3> = casters.iter().flat_map(|c| c.corners()).map(|c| (c - light).normalize()).collect();
        let mean = dirs.iter().sum::<Vec3>().normalize_or_zero();
        dirs.iter().all(|d| d.dot(mean) > 70f32.to_radians().cos())
    }

    /// Points of caster `casters` on segments from `light` to points of the receivers' hull,
    /// from `(r, s)` pairs: a receiver point as weights of the receiver points, a fraction of
    /// the segment.
    fn shadowing_points(light: Vec3, casters: &[Aabb], receivers: &[Vec3], samples: &[(Vec<f32>, f32)]) -> Vec<Vec3> {
        samples
            .iter()
            .filter_map(|(weights, s)| {
                let total: f32 = weights.iter().sum();
                let r = receivers.iter().zip(weights).map(|(p, w)| *p * *w).sum::<Vec3>() / total.max(1e-6);
                let c = light + (r - light) * *s;
                casters
                    .iter()
                    .any(|b| (b.min - Vec3::splat(1e-5)).cmple(c).all() && c.cmple(b.max + 1e-5).all())
                    .then_some(c)
            })
            .collect()
    }

    fn samples() -> impl Strategy<Value = Vec<(Vec<f32>, f32)>> {
        prop::collection::vec((prop::collection::vec(0.0f32..1.0, 8), 0.0f32..1.0), 300)
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
            // Above the ground it shadows (below it, nothing in view is behind it).
            let min = Vec3::new(c0[0], c0[1].abs(), c0[2]) * scale;
            let caster = Aabb { min, max: min + Vec3::from(size) * scale };
            let receivers: Vec<Vec3> = ground().iter().map(|p| *p * scale * 10.0).collect();
            let fit = fit_spot_frustum(light, Some(caster.center()), &[caster], &receivers);
            let f = fit.frustum.unwrap();
            prop_assert!(fit.clipped.is_empty());
            prop_assert!(f.window.iter().all(|v| v.is_finite()) && f.near > 0.0 && f.far > f.near);
            for c in caster.corners() {
                prop_assert!(inside(&f, c), "{:?}", c);
            }
        }

        /// Random layouts that one frustum can hold (the light anywhere, low ones too): every
        /// caster point on a segment from the light to a receiver in view is inside the window,
        /// and nothing is reported clipped.
        #[test]
        fn every_shadowing_caster_point_is_inside(
            light in prop::array::uniform3(-8.0f32..8.0), height in 0.3f32..12.0,
            boxes in prop::collection::vec((prop::array::uniform3(-3.0f32..3.0), prop::array::uniform3(0.0f32..1.5)), 1..5),
            patch in prop::array::uniform3(-6.0f32..6.0), half in 0.5f32..8.0,
            hint in prop::option::of(prop::array::uniform3(-50.0f32..50.0)),
            points in samples(),
        ) {
            let light = Vec3::new(light[0], height + 3.0 * light[1].abs() / 8.0, light[2]);
            let casters: Vec<Aabb> = layout(&boxes).into_iter().map(|b| Aabb { min: b.min.max(Vec3::new(-9.0, 0.0, -9.0)), ..b }).collect();
            prop_assume!(casters.iter().all(|b| !(b.min.cmple(light).all() && light.cmple(b.max).all())));
            prop_assume!(within_one_frustum(light, &casters));
            let c = Vec3::new(patch[0], 0.0, patch[2]);
            let receivers: Vec<Vec3> = Aabb { min: c - Vec3::new(half, 0.0, half), max: c + Vec3::new(half, patch[1].abs() * 0.3, half) }.corners().to_vec();
            let fit = fit_spot_frustum(light, hint.map(Vec3::from), &casters, &receivers);
            prop_assert!(fit.clipped.is_empty(), "{:?}", fit.clipped);
            let shadowing = shadowing_points(light, &casters, &receivers, &points);
            if let Some(f) = fit.frustum {
                for p in shadowing {
                    prop_assert!(inside(&f, p), "{:?} outside {:?}", p, f.window);
                }
            } else {
                prop_assert!(shadowing.is_empty(), "no frustum, yet {:?} shadows", shadowing);
            }
        }

        /// Adding a caster far away never pushes a shadowing point of the others out of the
        /// window, whether the new caster matters or not; if it is out of every shadow in view
        /// (behind the light, or 50 m to the side of a high light) nothing is clipped either.
        #[test]
        fn a_far_caster_excludes_none_of_the_others(
            light in prop::array::uniform3(-4.0f32..4.0),
            boxes in prop::collection::vec((prop::array::uniform3(-3.0f32..3.0), prop::array::uniform3(0.0f32..1.5)), 1..4),
            side in prop::array::uniform3(-1.0f32..1.0), behind in any::<bool>(),
            points in samples(),
        ) {
            let light = Vec3::new(light[0], 8.0 + light[1], light[2]);
            let casters: Vec<Aabb> = layout(&boxes).into_iter().map(|b| Aabb { min: b.min.max(Vec3::new(-9.0, 0.0, -9.0)), ..b }).collect();
            let receivers = ground().iter().map(|p| *p * 0.5).collect::<Vec<_>>();
            let dir = Vec3::new(side[0], 0.0, side[2]).normalize_or(Vec3::X);
            let far = if behind {
                cube(light + Vec3::new(side[0], 1.0, side[2]).normalize() * 40.0, 1.0)
            } else {
                cube(Vec3::new(0.0, 0.5 + side[1].abs(), 0.0) + dir * 50.0, 0.5 + side[1].abs())
            };
            let mut all = casters.clone();
            all.push(far);
            let fit = fit_spot_frustum(light, None, &all, &receivers);
            prop_assert!(fit.clipped.is_empty(), "{:?}", fit.clipped);
            prop_assert_eq!(&fit, &fit_spot_frustum(light, None, &casters, &receivers), "the far caster changed the fit");
            let shadowing = shadowing_points(light, &casters, &receivers, &points);
            if let Some(f) = fit.frustum {
                for p in shadowing {
                    prop_assert!(inside(&f, p), "{:?} outside {:?}", p, f.window);
                }
            } else {
                prop_assert!(shadowing.is_empty());
            }
        }
    }
}
