//! Low lights on lavapipe, against the GPU reference: the long edge a vertical edge casts away
//! from a light near the horizon (Haines §3's stretched footprints) has the true penumbra, on both
//! sides of its hard edge, for both silhouette techniques.

mod common;

use common::{crossing, engine, finish, reference, render_with, top_down};
use softshadow::Capture;
use softshadow::scene::Scene;

/// Half the ground seen, in metres: the camera looks straight down at (−4, 0, 0).
const HALF: f32 = 0.4;

/// V down the middle column, with each pixel's world z (rows run along +z).
fn column(c: &Capture) -> Vec<(f32, f32)> {
    let to_z = |px: u32| -HALF + (px as f32 + 0.5) / c.height as f32 * 2.0 * HALF;
    (0..c.height).map(|px| (to_z(px), c.visibility_at(c.width / 2, px))).collect()
}

/// The penumbra across the column: where V = ½, and its inner (V 0.05 → ½) and outer (½ → 0.95)
/// widths, in metres.
fn widths(profile: &[(f32, f32)]) -> (f32, f32, f32) {
    let at = |level| crossing(profile, level).expect("a penumbra across the column");
    let (start, middle, end) = (at(0.05), at(0.5), at(0.95));
    (middle, middle - start, end - middle)
}

/// Both techniques' penumbra across the column of `s` against the reference's (see
/// [`match_the_reference`]).
fn both_match_the_reference(s: &Scene, check: impl Fn(f32, f32)) {
    match_the_reference(s, &["plateau", "smoothie"], check);
}

/// The `techniques`' penumbra across the column of `s` against the reference's, whose inner and
/// outer widths pass `check` first: V = ½ within a tenth of the inner width of the truth's, each
/// half's width within 10 %.
fn match_the_reference(s: &Scene, techniques: &[&str], check: impl Fn(f32, f32)) {
    let mut e = engine();
    let (true_edge, true_inner, true_outer) = widths(&column(&reference(&mut e, s, 128)));
    check(true_inner, true_outer);
    for &technique in techniques {
        let (edge, inner, outer) = widths(&column(&render_with(&mut e, s, technique, &[], 128)));
        eprintln!(
            "{technique}: V = ½ at z {edge:.3} (truth {true_edge:.3}), inner {inner:.3} m (truth {true_inner:.3}), \
             outer {outer:.3} m (truth {true_outer:.3})"
        );
        assert!(
            (edge - true_edge).abs() <= 0.1 * true_inner,
            "{technique}: V = ½ at {edge}, the truth's at {true_edge}"
        );
        for (got, want, side) in [(inner, true_inner, "inner"), (outer, true_outer, "outer")] {
            assert!((got / want - 1.0).abs() <= 0.1, "{technique}: {side} width {got} m, the reference's {want} m");
        }
    }
    finish(e);
}

/// A wall 0.1 m thick along the light's direction, 1.2 m tall and 2 m across, under a light of
/// radius 0.4 m 8 m away and 2.2 m up (about 10° above the horizon from where the column's
/// penumbra comes from, 7° from the wall's top). Its end at z = −0.51 casts an edge that runs
/// away from the light and crosses the column at x = −4, z = 0, 4.1 m behind the edge: half
/// width R·4.1/8.0 = 0.2 m on each side. The end face and the wall's far side face away from
/// the light, so one silhouette edge casts the whole penumbra (no face seen edge-on).
#[test]
fn a_low_light_s_long_edge_has_the_true_penumbra_on_both_sides() {
    let wall = "[[object]]\nshape = \"box\"\nsize = [0.1, 1.2, 2.0]\nposition = [0.0, 0.6, -1.509]\n";
    let s = top_down(-4.0, HALF, [8.0, 2.2, -1.509], 0.4, wall);
    both_match_the_reference(&s, |inner, outer| {
        assert!(inner > 0.1 && outer > 0.1, "the reference's penumbra: {inner} + {outer} m");
    });
}

/// The same light beside a wall 0.8 m thick whose end face (z = 0) the light's centre sees 1°
/// from edge-on, inside its angular radius of 2.9°: for the part of the light behind the face's
/// plane the silhouette moves from the face's far vertical edge (x = −0.4, 3.6 m from the column
/// and 8.4 m from the light) to its near one (x = 0.4: 4.4 and 7.6 m), whose penumbra is wider
/// in the ratio (4.4/7.6) / (3.6/8.4) = 1.35 (the reference's outer half: 1.17× its inner).
/// Both techniques draw that edge's outer half (a partial silhouette); from the far edge alone
/// their outer half was 17 % short of the reference's.
#[test]
fn a_face_seen_nearly_edge_on_widens_the_outer_half() {
    both_match_the_reference(&beside_a_thick_wall(""), wider_outside);
}

/// The same on another caster: a slab 5 cm thick under all of the view, whose top the map holds
/// where the partial silhouette's outer half falls (the smoothie's receivers are every
/// surface). A partial smoothie kept only where the map is empty missed it, and its outer
/// half was as short as from the far edge alone (default's wingnut, whose wing's own
/// silhouettes shadow its body, leaked there too).
#[test]
fn a_face_seen_nearly_edge_on_widens_the_outer_half_on_a_caster_too() {
    let slab = "[[object]]\nshape = \"box\"\nsize = [2.0, 0.05, 2.0]\nposition = [-4.0, 0.025, 0.0]\n";
    match_the_reference(&beside_a_thick_wall(slab), &["smoothie"], wider_outside);
}

/// The thick wall whose end face the light sees nearly edge-on, and `more` objects.
fn beside_a_thick_wall(more: &str) -> Scene {
    let wall = "[[object]]\nshape = \"box\"\nsize = [0.8, 1.2, 2.0]\nposition = [0.0, 0.6, -1.0]\n";
    top_down(-4.0, HALF, [8.0, 2.2, 8.0 * 1f32.to_radians().tan()], 0.4, &format!("{wall}{more}"))
}

fn wider_outside(inner: f32, outer: f32) {
    assert!(outer > 1.1 * inner, "the reference's outer half is the wider: {inner} + {outer} m");
}
