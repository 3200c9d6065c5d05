//! What the classic planar techniques (`blob`, `concentric`) share with each other: the ground
//! as a receiver plane, the part of it a plan-view texture covers, and their view struct.

use glam::{Mat4, Vec2, Vec4};

use crate::frame::FrameInputs;
use crate::frame::interface::ClassicView;
use crate::geometry::plateau::ReceiverPlane;

/// The plane's frame for the resolves (which surfaces are on it: `on_plane`, glsl/common/camera.glsl).
pub(crate) fn view(plane: &ReceiverPlane, window: Vec4, params: Vec4) -> ClassicView {
    ClassicView {
        plane_origin: plane.origin.extend(0.0),
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
