//! The classic systems' geometry, after Dr. Dobb's "Dynamic Shadows: Five Algorithms" (2005)
//! and Gooch et al.'s concentric shadows ("Interactive Technical Illustration", 1998, as
//! Komura's lecture presents them): the blob under a caster, the heights of the concentric
//! planes, and the per-caster light frame of a projective shadow texture (the DDJ's Example 2).

use glam::{Mat2, Mat4, Vec2, Vec3, Vec4};

use super::Aabb;
use super::plateau::ReceiverPlane;

/// A blob stretches at most this many times its width: towards the horizon the caster's
/// projection runs to infinity, a dark spot does not.
pub const MAX_STRETCH: f32 = 4.0;

/// The most a blob's corner is pushed away from the light (a corner at or above its height).
const MAX_SCALE: f32 = 1000.0;

/// Widest half-angle a caster's image covers (tan 80°, as the shadow map's frustum): a light
/// inside the caster's bounding sphere sees only part of it.
const MAX_TAN: f32 = 5.671;

/// A soft ellipse on the receiver plane, { centre + axes·x : |x| ≤ 1 } in plane coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Blob {
    pub centre: Vec2,
    /// Columns: the semi-axis along the light's direction and the one across it.
    pub axes: Mat2,
}

impl Blob {
    /// The matrix taking plane coordinates relative to the centre to the unit disk's.
    pub fn to_unit(&self) -> Mat2 {
        self.axes.inverse()
    }
}

/// The DDJ's "dark spot" under a caster whose (oriented) bounding box has the world corners
/// `corners`, elongated away from the light: the corners are projected from the light onto
/// the plane, and the ellipse has their mean for centre and their second moments, scaled as
/// a uniform square's are to its corners' (semi-axes 2/√3 times the standard deviations): a
/// square's shadow gets the circle of nearly its area, whatever its turn, and a low light's
/// long projection a long ellipse along the light's direction. Corners at or above the light
/// project as if a little below it, and the ellipse is at most [`MAX_STRETCH`] times longer
/// than wide. `None` when the light is not above the plane or the caster lies wholly under it.
pub fn blob(plane: &ReceiverPlane, light: Vec3, corners: &[Vec3; 8]) -> Option<Blob> {
    let hl = plane.height(light);
    if hl <= 0.0 || corners.iter().all(|c| plane.height(*c) <= 0.0) {
        return None;
    }
    // Scale of the projection about the light, capped (continuously) where a corner nears the
    // light's height: a caster just below a light still throws its spot where the shadow is.
    let projected =
        corners.map(|p| plane.coords(light + (p - light) * (hl / (hl - plane.height(p)).max(hl / MAX_SCALE))));
    let centre = projected.iter().sum::<Vec2>() / 8.0;
    let (mut xx, mut xy, mut yy) = (0.0, 0.0, 0.0);
    for q in projected {
        let d = q - centre;
        (xx, xy, yy) = (xx + d.x * d.x / 8.0, xy + d.x * d.y / 8.0, yy + d.y * d.y / 8.0);
    }
    // Eigenvalues of the 2x2 covariance, the larger first, and the larger one's axis.
    let (mean, diff) = ((xx + yy) * 0.5, ((xx - yy) * 0.5).hypot(xy));
    let (major, minor) = (mean + diff, (mean - diff).max(0.0));
    let dir =
        Vec2::new(major - yy, xy).try_normalize().or(Vec2::new(xy, major - xx).try_normalize()).unwrap_or(Vec2::X);
    let scale = 2.0 / 3f32.sqrt();
    let along = (scale * major.sqrt()).max(f32::MIN_POSITIVE);
    let across = (scale * minor.sqrt()).max(along / MAX_STRETCH);
    Some(Blob { centre, axes: Mat2::from_cols(dir * along, dir.perp() * across) })
}

/// The half spread of the concentric planes that gives a caster the physical penumbra width.
///
/// A vertex p at height h projected onto the plane at height y instead of 0 moves by
/// y·|p − l|ₕ/(H − h) along the ray's horizontal direction (H the light's height, |·|ₕ the
/// horizontal distance), so planes at ±d spread its edge over 2d·|p − l|ₕ/(H − h); a light of
/// radius ρ spreads it over about 2ρ·h/(H − h). They agree for d = ρ·h/|p − l|ₕ, taken at the
/// caster's centre, with the distance at least the caster's horizontal half extent (its
/// silhouette is that far from the light's foot when the light is overhead), and d at most
/// half the light's height so that no plane reaches the light.
pub fn concentric_spread(plane: &ReceiverPlane, light: Vec3, radius: f32, bounds: &Aabb) -> f32 {
    let hl = plane.height(light);
    let c = bounds.center();
    let h = plane.height(c).clamp(0.0, hl.max(0.0));
    let half = (bounds.max - bounds.min) * 0.5;
    let extent = (half - plane.normal * half.dot(plane.normal)).length();
    let reach = (plane.coords(c) - plane.coords(light)).length().max(extent);
    if reach <= 0.0 || hl <= 0.0 {
        return 0.0;
    }
    (radius * h / reach).min(0.5 * hl)
}

/// Heights of `n` planes spread evenly over [−d, d] about the receiver plane, each at the
/// centre of its share (one plane: the receiver plane itself).
pub fn concentric_heights(n: u32, d: f32) -> impl Iterator<Item = f32> {
    (0..n).map(move |k| d * (2.0 * (k as f32 + 0.5) / n as f32 - 1.0))
}

/// A caster's view from the light (the DDJ's Example 2): k from the caster's centre to the
/// light, i perpendicular to the caster's up axis, j = k × i, and a perspective fitted to the
/// bounding sphere so that its image fills the texture.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CasterView {
    /// World → the image's clip space: x, y in [−w, w] over the image, w the distance in
    /// front of the light along −k, z = w/2 (no depth is kept).
    pub view_proj: Mat4,
    /// Distance from the light to the sphere's nearest point (0 with the light inside it).
    pub near: f32,
}

/// The view of a caster with bounding sphere (`centre`, `radius`) and up axis `up` from
/// `light`; `None` when the light is at the centre. A light inside the sphere gets the widest
/// image one frustum holds (80° half-angle).
pub fn caster_view(light: Vec3, centre: Vec3, radius: f32, up: Vec3) -> Option<CasterView> {
    let to_light = light - centre;
    let distance = to_light.length();
    let k = to_light.try_normalize()?;
    // Example 2(a): i ⊥ up; any other axis when up is parallel to k (the image's turn is free).
    let i = up.cross(k).try_normalize().or_else(|| Vec3::X.cross(k).try_normalize()).unwrap_or(Vec3::Z);
    let j = k.cross(i);
    let tan = if distance > radius * 1.0001 {
        (radius / (distance * distance - radius * radius).sqrt()).min(MAX_TAN)
    } else {
        MAX_TAN
    };
    // Rows: x = i·(p − l)/tan, y = j·(p − l)/tan, z = w/2, w = −k·(p − l).
    let row = |a: Vec3, s: f32| (a * s).extend(-a.dot(light) * s);
    let (x, y, w) = (row(i, 1.0 / tan), row(j, 1.0 / tan), row(-k, 1.0));
    let view_proj = Mat4::from_cols(
        Vec4::new(x.x, y.x, 0.5 * w.x, w.x),
        Vec4::new(x.y, y.y, 0.5 * w.y, w.y),
        Vec4::new(x.z, y.z, 0.5 * w.z, w.z),
        Vec4::new(x.w, y.w, 0.5 * w.w, w.w),
    );
    Some(CasterView { view_proj, near: (distance - radius).max(0.0) })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_box(at: Vec3) -> Aabb {
        Aabb { min: at - 0.5, max: at + 0.5 }
    }

    fn blob_of(light: Vec3, at: Vec3) -> Option<Blob> {
        blob(&ReceiverPlane::ground(0.0), light, &unit_box(at).corners())
    }

    #[test]
    fn a_blob_under_an_overhead_light_is_round_and_stretches_away_from_a_low_one() {
        let b = blob_of(Vec3::new(0.0, 10.0, 0.0), Vec3::new(0.0, 0.5, 0.0)).unwrap();
        assert!(b.centre.length() < 1e-5, "{b:?}");
        let (a0, a1) = (b.axes.col(0).length(), b.axes.col(1).length());
        // Corners at ±0.5 and ±0.5·10/9: a circle of radius 2/√3 times their spread.
        let spread = ((0.25 + 0.25 * (10.0f32 / 9.0).powi(2)) / 2.0).sqrt();
        assert!((a0 - a1).abs() < 1e-4 && (a0 - 2.0 / 3f32.sqrt() * spread).abs() < 1e-4, "{b:?}");
        let low = blob_of(Vec3::new(10.0, 2.0, 0.0), Vec3::new(0.0, 0.5, 0.0)).unwrap();
        let (along, across) = (low.axes.col(0), low.axes.col(1));
        assert!(along.x.abs() > 0.99 * along.length() && along.length() > 1.2 * across.length(), "{low:?}");
        assert!(low.centre.x < 0.0, "away from the light: {low:?}");
        // A corner above the light: finite, and no longer than MAX_STRETCH widths.
        let grazing = blob_of(Vec3::new(10.0, 0.8, 0.0), Vec3::new(0.0, 0.5, 0.0)).unwrap();
        let (along, across) = (grazing.axes.col(0).length(), grazing.axes.col(1).length());
        assert!(along.is_finite() && along <= MAX_STRETCH * across * 1.0001, "{grazing:?}");
        assert!(blob_of(Vec3::new(0.0, 10.0, 0.0), Vec3::new(0.0, -2.0, 0.0)).is_none());
    }

    #[test]
    fn the_concentric_spread_matches_the_physical_penumbra_at_the_casters_centre() {
        let plane = ReceiverPlane::ground(0.0);
        let (light, centre) = (Vec3::new(4.0, 8.0, 0.0), Vec3::new(0.0, 2.0, 0.0));
        let d = concentric_spread(&plane, light, 0.5, &Aabb { min: centre - 0.1, max: centre + 0.1 });
        // Planes at ±d spread the centre's shadow over 2d·4/6; the light's, over 2·0.5·2/6.
        assert!((2.0 * d * 4.0 / 6.0 - 2.0 * 0.5 * 2.0 / 6.0).abs() < 1e-5, "{d}");
        assert_eq!(concentric_spread(&plane, light, 0.0, &unit_box(centre)), 0.0);
        let heights: Vec<f32> = concentric_heights(4, 1.0).collect();
        assert_eq!(heights, [-0.75, -0.25, 0.25, 0.75]);
        assert_eq!(concentric_heights(1, 1.0).collect::<Vec<_>>(), [0.0]);
    }

    #[test]
    fn a_casters_image_fills_the_frame_with_its_bounding_sphere() {
        let (light, centre) = (Vec3::new(1.0, 9.0, 2.0), Vec3::new(0.0, 1.0, 0.0));
        let view = caster_view(light, centre, 1.0, Vec3::Y).unwrap();
        let ndc = |p: Vec3| {
            let c = view.view_proj * p.extend(1.0);
            (c.truncate() / c.w, c.w)
        };
        let (c, w) = ndc(centre);
        assert!(c.truncate().length() < 1e-5 && (w - (light - centre).length()).abs() < 1e-4);
        // A tangent point of the sphere lands on the image's edge.
        let k = (light - centre).normalize();
        let side = k.cross(Vec3::X).normalize();
        let d = (light - centre).length();
        let tangent = centre + (k / d + side * (1.0 - 1.0 / (d * d)).sqrt());
        let (t, _) = ndc(tangent);
        assert!((t.truncate().length() - 1.0).abs() < 1e-3, "{t}");
        assert!((view.near - (d - 1.0)).abs() < 1e-5);
        // Behind the light: w < 0, clipped.
        assert!(ndc(light + k).1 < 0.0);
        assert!(caster_view(centre, centre, 1.0, Vec3::Y).is_none());
        assert!(caster_view(Vec3::new(0.0, 5.0, 0.0), Vec3::ZERO, 1.0, Vec3::Y).is_some(), "up ∥ k");
    }
}
