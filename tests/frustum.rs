//! Issue 19: the spot frustum of the shadow-map family (shadow-map, pcf, pcss, smoothie) and of
//! the GPU reference is fitted to the casters that can shadow a receiver in view, so a wide
//! scene, a `light.target` pointing away or a light very far away no longer loses the shadows
//! silently. Each render is compared with the CPU ray tracer on the pixels it puts in shadow.

mod common;

use common::{engine, finish, render_with, scene};
use softshadow::Capture;
use softshadow::scene::Scene;

const SIZE: u32 = 64;

/// The techniques that render through a fitted spot frustum, with knobs that keep lavapipe quick.
const FITTED: [(&str, &[(&str, &str)]); 5] = [
    ("shadow-map", &[("shadow_map_size", "512")]),
    ("pcf", &[("shadow_map_size", "512")]),
    ("pcss", &[("shadow_map_size", "512")]),
    ("smoothie", &[]),
    ("reference", &[("samples", "16"), ("shadow_map_size", "256")]),
];

/// Two boxes and a plate near the origin, seen from straight above (6 m across), under a light
/// at `light` (with `target` when given), plus `extra` objects (TOML).
fn near_casters(light: [f64; 3], radius: f64, target: Option<[f64; 3]>, extra: &str) -> Scene {
    let target = target.map_or(String::new(), |t| format!("target = [{}, {}, {}]\n", t[0], t[1], t[2]));
    scene(&format!(
        "[camera]\nposition = [0.0, 12.0, 0.0]\ntarget = [0.0, 0.0, 0.0]\nup = [0.0, 0.0, -1.0]\n\
         ortho_half_height = 3.0\n[light]\nposition = [{}, {}, {}]\nradius = {radius}\n{target}\
         [ground]\nheight = 0.0\nhalf_size = 10.0\n\
         [[object]]\nshape = \"box\"\nsize = [1.0, 1.0, 1.0]\nposition = [0.0, 0.5, 0.0]\n\
         [[object]]\nshape = \"box\"\nsize = [0.6, 0.6, 0.6]\nposition = [-1.6, 0.3, 1.2]\n\
         [[object]]\nshape = \"plate\"\nsize = [0.8, 0.0, 0.8]\nposition = [1.4, 0.8, -1.3]\n{extra}",
        light[0], light[1], light[2]
    ))
}

/// The box 50 m away from the others (issue 19's wide scene): it shadows nothing in view.
const FAR_BOX: &str = "[[object]]\nshape = \"box\"\nsize = [1.0, 1.0, 1.0]\nposition = [50.0, 0.5, 0.0]\n";

/// Fraction of the ray tracer's shadow (V < 0.25) that `c` leaves lit (V > 0.5), the number
/// of such shadow pixels, and the fraction of its open ground (V > 0.9) that `c` darkens.
fn shadow_lit(c: &Capture, truth: &Capture) -> (f32, usize, f32) {
    let (mut shadow, mut lit, mut open, mut dark) = (0usize, 0usize, 0usize, 0usize);
    for y in 0..truth.height {
        for x in 0..truth.width {
            let (t, v) = (truth.visibility_at(x, y), c.visibility_at(x, y));
            if t < 0.25 {
                shadow += 1;
                lit += usize::from(v > 0.5);
            } else if t > 0.9 {
                open += 1;
                dark += usize::from(v < 0.5);
            }
        }
    }
    (lit as f32 / shadow.max(1) as f32, shadow, dark as f32 / open.max(1) as f32)
}

/// Renders every fitted technique on `s` and checks that each keeps the ray tracer's shadow.
fn shadows_kept(s: &Scene, what: &str) {
    shadows_kept_against(s, s, what)
}

/// [`shadows_kept`] with the truth traced on `truth_scene`, the same shadows in view.
fn shadows_kept_against(s: &Scene, truth_scene: &Scene, what: &str) {
    let mut e = engine();
    let truth = render_with(&mut e, truth_scene, "raytrace", &[("samples", "64")], SIZE);
    let mut failures = Vec::new();
    let mut figures = Vec::new();
    for (technique, sets) in FITTED {
        let c = render_with(&mut e, s, technique, sets, SIZE);
        let (lit, shadow, dark) = shadow_lit(&c, &truth);
        assert!(shadow > 100, "{what}: the ray tracer finds only {shadow} shadow pixels");
        figures.push(format!("{technique} {:.1}% (open ground darkened {:.1}%)", lit * 100.0, dark * 100.0));
        // A few pixels at the edges of the shadow may differ; losing the shadow may not, nor
        // may acne darken the open ground.
        if lit > 0.1 || dark > 0.05 {
            failures.push(format!(
                "{technique}: {:.0}% of the true shadow lit, {:.0}% of the open ground dark",
                lit * 100.0,
                dark * 100.0
            ));
        }
    }
    eprintln!("{what}: true shadow lit: {}", figures.join(", "));
    assert!(failures.is_empty(), "{what}: {}", failures.join("; "));
    finish(e);
}

#[test]
fn a_box_fifty_metres_away_keeps_the_near_shadows() {
    shadows_kept(&near_casters([1.0, 6.0, 0.5], 0.1, None, FAR_BOX), "wide scene");
}

#[test]
fn a_box_at_the_edge_of_the_world_keeps_the_near_shadows() {
    // 9e8 m: within MAX_COORDINATE (1e30 is refused by the scene checks).
    let far = "[[object]]\nshape = \"box\"\nsize = [1.0, 1.0, 1.0]\nposition = [9e8, 0.5, 0.0]\ncasts = true\n";
    // The CPU tracer itself loses its shadows beside a box that far (f32 bounds), and that box
    // shadows nothing in view: the truth is traced without it.
    let truth = near_casters([1.0, 6.0, 0.5], 0.1, None, "");
    shadows_kept_against(&near_casters([1.0, 6.0, 0.5], 0.1, None, far), &truth, "a box at 9e8 m");
}

#[test]
fn a_light_target_in_the_sky_is_only_a_hint() {
    shadows_kept(&near_casters([1.0, 6.0, 0.5], 0.1, Some([1.0, 100.0, 0.5]), ""), "light.target in the sky");
}

#[test]
fn a_light_target_beside_the_casters_is_only_a_hint() {
    // Aimed 30 m off to the side: the casters would sit beyond the 80° edge of that frustum.
    shadows_kept(&near_casters([1.0, 6.0, 0.5], 0.1, Some([40.0, 0.0, 0.0]), ""), "light.target beside");
}

#[test]
fn a_light_1e8_metres_away_still_casts_shadows() {
    // A point light (the sun, near enough): 60° up, shadows a few metres long at most.
    let d = 1e8;
    shadows_kept(&near_casters([0.3 * d, 0.8 * d, 0.2 * d], 0.0, None, ""), "light 1e8 m away");
}
