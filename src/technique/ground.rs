//! What the classic planar techniques (`blob`, `concentric`) share with each other: the ground
//! as a receiver plane, the part of it a plan-view texture covers, and their view struct.

use glam::{Mat4, Vec2, Vec4};

use crate::frame::FrameInputs;
use crate::frame::interface::ClassicView;
use crate::geometry::plateau::ReceiverPlane;

/// f32 roundings the rasterized ground's surface may be off its plane by, in units of the
/// largest coordinate its depths come from (its corners, the camera): 2^-23 each, a few of them.
const GROUND_ROUNDING: f32 = 8.0 * 1.1920929e-7;

/// How far off the receiver plane a surface of the camera prepass may be and still be on it,
/// for a light `light_height` above the plane: a thousandth of that, and at least the rounding
/// of the rasterized ground, whose depths near the camera are interpolated from corners
/// `half_size` away. A ground of half size 8.6e4 m came out millimetres off its plane there,
/// and every plane technique (blob, concentric, planar, plateau) lost the whole shadow
/// (issue 19).
pub(crate) fn on_plane_tolerance(frame: &FrameInputs<'_>, light_height: f32) -> f32 {
    let ground = frame.scene.ground.map_or(0.0, |g| g.half_size + g.height.abs());
    let reach = ground.max(frame.camera.position.abs().max_element());
    (1e-3 * light_height.abs()).max(GROUND_ROUNDING * reach)
}

/// The plane's frame for the resolves; a surface within `tolerance` of the plane is on it
/// ([`on_plane_tolerance`]).
pub(crate) fn view(plane: &ReceiverPlane, tolerance: f32, window: Vec4, params: Vec4) -> ClassicView {
    ClassicView {
        plane_origin: plane.origin.extend(tolerance),
        plane_normal: plane.normal.extend(0.0),
        plane_u: plane.u.extend(0.0),
        plane_v: plane.v.extend(0.0),
        window,
        params,
    }
}

/// The part of the plane a texture of `texels`² covers: the shadow's footprint (`lo`, `hi` in
/// plane coordinates; everything when `unbounded`) cut to the visible receivers' extent on
/// the plane, with a texel of margin. `None` when they do not meet.
pub(crate) fn window(
    plane: &ReceiverPlane,
    (lo, hi): (Vec2, Vec2),
    unbounded: bool,
    frame: &FrameInputs<'_>,
    texels: u32,
) -> Option<Vec4> {
    let (lo, hi) = if unbounded { (Vec2::MIN, Vec2::MAX) } else { (lo, hi) };
    let seen = frame.receivers_in_view.iter().map(|p| plane.coords(*p));
    let (seen_lo, seen_hi) = seen.fold((Vec2::MAX, Vec2::MIN), |(a, b), p| (a.min(p), b.max(p)));
    let (lo, hi) = (lo.max(seen_lo), hi.min(seen_hi));
    if lo.cmpge(hi).any() {
        return None;
    }
    let pad = (hi - lo) * 2.0 / texels as f32;
    Some(Vec4::new(lo.x - pad.x, lo.y - pad.y, hi.x + pad.x, hi.y + pad.y))
}

/// Plane coordinates → clip space of a texture covering `window`.
pub(crate) fn window_to_clip(window: Vec4) -> Mat4 {
    let scale = Vec2::new(2.0 / (window.z - window.x), 2.0 / (window.w - window.y));
    Mat4::from_cols(
        Vec4::new(scale.x, 0.0, 0.0, 0.0),
        Vec4::new(0.0, scale.y, 0.0, 0.0),
        Vec4::ZERO,
        Vec4::new(-1.0 - window.x * scale.x, -1.0 - window.y * scale.y, 0.0, 1.0),
    )
}
