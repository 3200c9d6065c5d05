//! `planar`: Blinn's projected shadows on the ground plane, exact there under a point light,
//! counted once per pixel by the stencil, nothing on any other receiver, no anti-shadows.

mod common;

use common::{engine, finish, render_with, top_down};
use softshadow::Capture;

/// Seen from straight above at 12 m ([`top_down`]), the ground is what lies 12 m away.
fn ground(c: &Capture, i: usize) -> bool {
    c.surfaces.receives[i] && (c.surfaces.depth[i] - 12.0).abs() < 1e-3
}

/// Ground pixels where `a` and `b` disagree on shadowed, off the edges of both; other receivers'
/// pixels where `a` is not 1.
fn compare(a: &Capture, b: &Capture) -> (usize, Vec<usize>, Vec<usize>) {
    let w = b.width as i64;
    let dark = |c: &Capture, i: i64| c.visibility[i as usize] < 32768;
    let edge = |c: &Capture, i: i64| {
        let (x, y) = (i % w, i / w);
        (-1..=1).any(|dy| {
            (-1..=1).any(|dx| {
                let (u, v) = ((x + dx).clamp(0, w - 1), (y + dy).clamp(0, w - 1));
                dark(c, v * w + u) != dark(c, i)
            })
        })
    };
    let (mut on_ground, mut wrong, mut elsewhere) = (0, Vec::new(), Vec::new());
    for i in 0..b.visibility.len() as i64 {
        if ground(b, i as usize) {
            on_ground += 1;
            if dark(a, i) != dark(b, i) && !edge(a, i) && !edge(b, i) {
                wrong.push(i as usize);
            }
        } else if a.visibility[i as usize] != 65535 {
            elsewhere.push(i as usize);
        }
    }
    (on_ground, wrong, elsewhere)
}

/// Two boxes whose shadows overlap (and every closed caster's front and back project onto the
/// same pixels), a sphere, and a small box standing in the tall box's shadow: the ground's hard
/// shadow is the ray tracer's but at the edges, dark once where projections overlap, and the
/// small box, which the ray tracer shows shadowed, keeps V = 1 (the paper's limit).
#[test]
fn exact_on_the_plane_once_where_projections_overlap_and_nothing_elsewhere() {
    let objects = "[[object]]\nshape = \"box\"\nsize = [0.6, 2.0, 0.6]\nposition = [0.0, 1.0, 0.0]\n\
        [[object]]\nshape = \"box\"\nsize = [1.2, 0.2, 0.4]\nposition = [-0.4, 1.4, 0.7]\n\
        [[object]]\nshape = \"sphere\"\nradius = 0.4\nposition = [1.2, 0.8, -1.2]\n\
        [[object]]\nshape = \"box\"\nsize = [0.3, 0.3, 0.3]\nposition = [-1.2, 0.15, 0.0]\n";
    let s = top_down(0.0, 3.0, [3.0, 5.0, 0.5], 0.0, objects);
    let mut e = engine();
    let ray = render_with(&mut e, &s, "raytrace", &[], 96);
    let planar = render_with(&mut e, &s, "planar", &[], 96);
    let (on_ground, wrong, elsewhere) = compare(&planar, &ray);
    let dark_ground = (0..ray.visibility.len()).filter(|&i| ground(&ray, i) && ray.visibility[i] < 32768).count();
    assert!(on_ground > 5000 && dark_ground > 300, "{on_ground} ground px, {dark_ground} in shadow");
    assert!(
        wrong.is_empty(),
        "{} ground px differ from the ray tracer, first {:?}",
        wrong.len(),
        &wrong[..wrong.len().min(6)]
    );
    assert!(
        elsewhere.is_empty(),
        "{} px off the plane not 1, first {:?}",
        elsewhere.len(),
        &elsewhere[..elsewhere.len().min(6)]
    );
    // The small box's top (x = -1.2, z = 0: column 29, row 48) is shadowed in truth.
    assert!(!ground(&ray, 48 * 96 + 29), "the small box's top");
    assert!(ray.visibility_at(29, 48) < 0.5 && planar.visibility_at(29, 48) == 1.0);
    // Where the boxes' projections overlap the ground is dark once, not lit by a stencil that
    // went past "shadowed": the whole shadow is V = 0, never in between.
    let dark: Vec<u16> =
        (0..planar.visibility.len()).filter(|&i| ground(&ray, i)).map(|i| planar.visibility[i]).collect();
    assert!(dark.iter().all(|&v| v == 0 || v == 65535), "a hard shadow is 0 or 1");
    finish(e);
}

/// A post whose top is 4 m above the light, and a box wholly above it: the part above the light
/// gets w ≤ 0 and is clipped, so the post's shadow is the ray tracer's (running to the edge of
/// the view) and the box casts nothing, no anti-shadow on the light's side.
#[test]
fn no_anti_shadow_for_a_caster_above_the_light() {
    let objects = "[[object]]\nshape = \"box\"\nsize = [0.3, 6.0, 0.3]\nposition = [0.0, 3.0, 0.0]\n\
        [[object]]\nshape = \"box\"\nsize = [0.6, 0.6, 0.6]\nposition = [1.0, 3.0, 2.0]\n";
    let s = top_down(0.0, 4.0, [2.0, 2.0, 0.0], 0.0, objects);
    let mut e = engine();
    let ray = render_with(&mut e, &s, "raytrace", &[], 64);
    let planar = render_with(&mut e, &s, "planar", &[], 64);
    let (_, wrong, _) = compare(&planar, &ray);
    assert!(wrong.is_empty(), "{} ground px differ, first {:?}", wrong.len(), &wrong[..wrong.len().min(6)]);
    // Dark to the image's left edge behind the post, lit on the light's side.
    assert!(planar.visibility_at(0, 32) == 0.0 && planar.visibility_at(63, 32) == 1.0);
    finish(e);
}

/// A slab whose top is 0.5 m above the ground under a point light 1 km up and over, a box above it: the
/// slab's top is not the plane however high the light (a tolerance of a thousandth of the
/// light's height took it for the ground, issue 19), so the box's shadow lands on the ground
/// around the slab only and the slab keeps V = 1.
#[test]
fn a_raised_slab_is_not_the_plane_under_a_high_light() {
    let objects = "[[object]]\nshape = \"box\"\nsize = [3.0, 0.5, 3.0]\nposition = [0.0, 0.25, 0.0]\n\
        [[object]]\nshape = \"box\"\nsize = [4.0, 0.2, 1.0]\nposition = [0.0, 2.0, 0.0]\n";
    let s = top_down(0.0, 3.0, [0.0, 1000.0, 1000.0], 0.0, objects);
    let mut e = engine();
    let ray = render_with(&mut e, &s, "raytrace", &[], 64);
    let planar = render_with(&mut e, &s, "planar", &[], 64);
    let (_, wrong, elsewhere) = compare(&planar, &ray);
    let slab_in_shadow = (0..ray.visibility.len()).filter(|&i| !ground(&ray, i) && ray.visibility[i] < 32768).count();
    assert!(slab_in_shadow > 100, "the box shadows the slab in truth: {slab_in_shadow} px");
    assert!(wrong.is_empty(), "{} ground px differ, first {:?}", wrong.len(), &wrong[..wrong.len().min(6)]);
    assert!(
        elsewhere.is_empty(),
        "{} px off the plane not 1, first {:?}",
        elsewhere.len(),
        &elsewhere[..elsewhere.len().min(6)]
    );
    finish(e);
}
