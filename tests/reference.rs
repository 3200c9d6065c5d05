//! Ground truth checked against analytic visibility, and the GPU reference against the CPU
//! tracer: the half-plane penumbra, the overlap of two spherical caps, convergence with the
//! number of light samples, Parker et al.'s single-sample shadows.

mod common;

use std::f64::consts::PI;

use common::{engine, finish, render_with, scene, suite_scene};
use glam::Vec3;
use softshadow::Capture;
use softshadow::measure::Metrics;
use softshadow::reference::{Surface, TraceScene};
use softshadow::scene::Scene;

/// The ground under a light at `light` of radius `r` and one object (its TOML keys).
fn over_ground(light: Vec3, r: f32, object: &str) -> Scene {
    scene(&format!(
        "[camera]\nposition = [0.0, 6.0, 6.0]\ntarget = [0.0, 0.0, 0.0]\nfov_y_deg = 40.0\n\
         [light]\nposition = [{}, {}, {}]\nradius = {r}\n\
         [ground]\nheight = 0.0\nhalf_size = 30.0\n\
         [[object]]\n{object}",
        light.x, light.y, light.z
    ))
}

/// A plate covering x < 0 (40 m square, a half-plane for any light footprint near x = 0) at
/// height `h` over the ground, under a light of radius `r` at height `big_h` above x = 0.
fn half_plane(h: f32, big_h: f32, r: f32) -> Scene {
    let plate = format!("shape = \"plate\"\nsize = [40.0, 0.0, 40.0]\nposition = [-20.0, {h}, 0.0]\n");
    over_ground(Vec3::new(0.0, big_h, 0.0), r, &plate)
}

/// V under a half-plane edge (the light seen as a disk, its footprint cut by the edge): the
/// circular-segment area fraction.
fn half_plane_v(x: f64, h: f64, big_h: f64, r: f64) -> f64 {
    let u = (-x * (big_h - h) / (h * r)).clamp(-1.0, 1.0);
    (u.acos() - u * (1.0 - u * u).sqrt()) / PI
}

/// Solid angle of the intersection of two spherical caps of angular radii `a` and `b` whose
/// centres are `g` apart (Tovchigrechko & Vakser 2001).
fn cap_overlap(a: f64, b: f64, g: f64) -> f64 {
    if g >= a + b {
        return 0.0;
    }
    if g <= (a - b).abs() {
        return 2.0 * PI * (1.0 - a.min(b).cos());
    }
    let (ca, cb, cg, sa, sb, sg) = (a.cos(), b.cos(), g.cos(), a.sin(), b.sin(), g.sin());
    2.0 * (PI
        - ((cg - ca * cb) / (sa * sb)).clamp(-1.0, 1.0).acos()
        - ca * ((cb - cg * ca) / (sg * sa)).clamp(-1.0, 1.0).acos()
        - cb * ((ca - cg * cb) / (sg * sb)).clamp(-1.0, 1.0).acos())
}

/// V at `p` under a light sphere (`light`, `r`) partly hidden by a ball (`ball`, `rb`).
fn sphere_v(p: Vec3, light: Vec3, r: f32, ball: Vec3, rb: f32) -> f64 {
    let (to_l, to_b) = ((light - p).as_dvec3(), (ball - p).as_dvec3());
    let a = (r as f64 / to_l.length()).asin();
    let b = (rb as f64 / to_b.length()).asin();
    let g = to_l.angle_between(to_b);
    1.0 - cap_overlap(a, b, g) / (2.0 * PI * (1.0 - a.cos()))
}

fn sphere_scene(light: Vec3, r: f32, ball: Vec3, rb: f32) -> Scene {
    let sphere = format!("shape = \"sphere\"\nradius = {rb}\nposition = [{}, {}, {}]\n", ball.x, ball.y, ball.z);
    over_ground(light, r, &sphere)
}

#[test]
fn raytrace_matches_the_half_plane_penumbra() {
    let (h, big_h, r) = (2.0, 20.0, 1.0);
    let s = half_plane(h, big_h, r);
    let tracer = TraceScene::new(&s).unwrap();
    let half_width = h * r / (big_h - h);
    for i in 0..=40 {
        let x = (i as f32 / 20.0 - 1.0) * 1.5 * half_width;
        for z in [0.0, 0.7] {
            let v = tracer.visibility(Surface::free(Vec3::new(x, 0.0, z)), &s.light, 1024, i) as f64;
            let expected = half_plane_v(x as f64, h as f64, big_h as f64, r as f64);
            assert!((v - expected).abs() < 0.01, "x = {x}, z = {z}: traced {v}, analytic {expected}");
        }
    }
}

#[test]
fn raytrace_matches_the_overlap_of_two_spherical_caps() {
    let (light, r, ball, rb) = (Vec3::new(1.0, 8.0, 0.5), 0.8, Vec3::new(0.0, 1.5, 0.0), 0.5);
    let s = sphere_scene(light, r, ball, rb);
    let tracer = TraceScene::new(&s).unwrap();
    // The UV sphere (24 segments, 16 rings) lies between the ball and the ball shrunk to its
    // faces' nearest distance, and V only grows as the occluder shrinks.
    let inner = rb * (std::f32::consts::PI / 24.0).cos() * (std::f32::consts::PI / 32.0).cos();
    let shadow_centre = ball + (ball - light) * (ball.y / (light.y - ball.y));
    let mut penumbra = 0;
    for i in 0..=60 {
        for dir in [Vec3::X, Vec3::Z, Vec3::new(-0.6, 0.0, 0.8)] {
            let p = Vec3::new(shadow_centre.x, 0.0, shadow_centre.z) + dir * (i as f32 * 0.025);
            let v = tracer.visibility(Surface::free(p), &s.light, 1024, i) as f64;
            let (low, high) = (sphere_v(p, light, r, ball, rb), sphere_v(p, light, r, ball, inner));
            assert!(v > low - 0.01 && v < high + 0.01, "p = {p}: traced {v}, analytic {low}..{high}");
            penumbra += usize::from(low > 0.05 && high < 0.95);
        }
    }
    assert!(penumbra > 20, "the probes must cross the penumbra ({penumbra})");
}

/// Width of Parker's penumbra across the half-plane edge: the x range where 0 < V < 1.
fn parker_penumbra_width(h: f32, big_h: f32, r: f32) -> f32 {
    let s = half_plane(h, big_h, r);
    let tracer = TraceScene::new(&s).unwrap();
    let step = 1e-4;
    let soft: Vec<f32> = (-3000..6000)
        .map(|i| i as f32 * step)
        .filter(|&x| {
            let v = tracer.parker(Surface::free(Vec3::new(x, 0.0, 0.0)), &s.light);
            v > 0.001 && v < 0.999
        })
        .collect();
    soft.last().map_or(0.0, |last| last - soft[0] + step)
}

#[test]
fn parker_penumbra_vanishes_at_contact_and_grows_linearly_with_height() {
    let (big_h, r) = (20.0, 1.0);
    // Parker §3: b = a·D/A, so the penumbra on the ground spans D·h/(H − h).
    for h in [0.1, 0.2, 0.4] {
        let width = parker_penumbra_width(h, big_h, r);
        let expected = 2.0 * r * h / (big_h - h);
        assert!((width - expected).abs() < 0.05 * expected + 2e-4, "h = {h}: width {width}, expected {expected}");
    }
    let contact = parker_penumbra_width(1e-4, big_h, r);
    assert!(contact <= 2e-4, "a caster touching the ground casts a hard edge, width {contact}");
}

#[test]
fn parker_is_never_lighter_than_the_light_allows() {
    let half = half_plane(1.0, 10.0, 1.0);
    let ball = sphere_scene(Vec3::new(1.0, 8.0, 0.5), 0.8, Vec3::new(0.0, 1.5, 0.0), 0.5);
    for s in [&half, &ball] {
        let tracer = TraceScene::new(s).unwrap();
        for i in 0..60 {
            let p = Vec3::new(i as f32 * 0.02 - 0.6, 0.0, (i % 7) as f32 * 0.05 - 0.15);
            let exact = tracer.visibility(Surface::free(p), &s.light, 1024, i);
            let parker = tracer.parker(Surface::free(p), &s.light);
            assert!(parker.is_finite() && (0.0..=1.0).contains(&parker));
            // The inner object is the occluder itself and the outer one only darkens more.
            assert!(parker <= exact + 0.01, "p = {p}: parker {parker} lighter than exact {exact}");
        }
    }
}

fn test_scenes() -> [Scene; 2] {
    [suite_scene("plate"), suite_scene("sphere")]
}

/// Fewer texels than the default keep the 1024-sample runs short on lavapipe.
const MAP: (&str, &str) = ("shadow_map_size", "512");

#[test]
fn the_reference_agrees_with_raytrace_and_converges() {
    let mut e = engine();
    for s in test_scenes() {
        let truth = render_with(&mut e, &s, "raytrace", &[("samples", "1024")], 64);
        let mut last = f64::INFINITY;
        for n in ["16", "64", "256", "1024"] {
            let v = render_with(&mut e, &s, "reference", &[("samples", n), MAP], 64);
            let m = Metrics::between(&v, &truth).unwrap();
            assert!(m.pixels > 1000 && m.penumbra_pixels > 50, "{m:?}");
            assert!(m.excluded * 100 < m.pixels, "surfaces agree almost everywhere: {m:?}");
            assert!(m.rmse < last, "N = {n}: RMSE {} did not fall below {last}", m.rmse);
            last = m.rmse;
        }
        assert!(last < 0.01, "N = 1024: RMSE {last} against raytrace");
    }
    finish(e);
}

#[test]
fn a_point_light_makes_every_ground_truth_a_hard_shadow() {
    let mut s = test_scenes()[0].clone();
    s.light.radius = 0.0;
    let mut e = engine();
    let hard = render_with(&mut e, &s, "shadow-map", &[MAP], 64);
    let reference = render_with(&mut e, &s, "reference", &[("samples", "64"), MAP], 64);
    let traced = render_with(&mut e, &s, "raytrace", &[], 64);
    // One point: the reference is one hard shadow map's test, against the receiver's plane
    // where the shadow map's is against one biased depth; the two differ only on the edge.
    let (_, _, stray) = edge_disagreement(&reference, &hard, &traced);
    let first = &stray[..stray.len().min(8)];
    assert!(
        stray.is_empty(),
        "the reference differs from the shadow map off its edge at {} px, first {first:?}",
        stray.len()
    );
    assert!(traced.visibility.iter().all(|&v| v == 0 || v == 65535), "a point light leaves no penumbra");
    let m = Metrics::between(&reference, &traced).unwrap();
    assert!(m.rmse < 0.1, "{m:?}");
    // Both are hard shadows of the same caster from the same point, so they can disagree only
    // where the map's texel grid moves the edge: by the bilinear's texel plus the depth bias,
    // about two texels. The map is fitted around the plate (~2.8 m over 512 texels, ~0.7 cm on
    // the ground) and a pixel of the 64² view is ~10 cm, so the edge moves by ~0.15 px. Hence
    // every pixel the reference gets wrong lies on the true shadow's boundary (a traced
    // neighbour has the other value), and is wrong only when the true edge passes that close to
    // its centre: ~0.15 of the pixels the edge crosses, which are about half the boundary (it
    // holds both sides), so at most an eighth of the boundary.
    let (boundary, wrong, stray) = edge_disagreement(&reference, &traced, &traced);
    assert!(boundary > 20, "the plate's shadow must have an edge in view ({boundary} px)");
    let first = &stray[..stray.len().min(8)];
    assert!(stray.is_empty(), "{} px wrong away from the true shadow's edge, first {first:?} ({m:?})", stray.len());
    assert!(
        8 * wrong <= boundary,
        "{wrong} of {boundary} edge pixels wrong: the edge moved by more than a texel and the bias ({m:?})"
    );
    finish(e);
}

/// Along a binary `truth`: its boundary pixels (receivers with an 8-neighbour of the other
/// V), how many receivers `v` and `other` differ at, and those off the boundary.
fn edge_disagreement(v: &Capture, other: &Capture, truth: &Capture) -> (usize, usize, Vec<(u32, u32)>) {
    let (w, h) = (truth.width as i64, truth.height as i64);
    let at = |x: i64, y: i64| (y * w + x) as usize;
    let (mut boundary, mut wrong, mut stray) = (0, 0, Vec::new());
    for y in 0..h {
        for x in 0..w {
            let i = at(x, y);
            if !(truth.surfaces.receives[i] && v.surfaces.receives[i]) {
                continue;
            }
            let on_edge = (-1..=1).flat_map(|dy| (-1..=1).map(move |dx| (x + dx, y + dy))).any(|(nx, ny)| {
                (0..w).contains(&nx)
                    && (0..h).contains(&ny)
                    && truth.surfaces.receives[at(nx, ny)]
                    && truth.visibility[at(nx, ny)] != truth.visibility[i]
            });
            boundary += usize::from(on_edge);
            if v.visibility[i] != other.visibility[i] {
                wrong += 1;
                if !on_edge {
                    stray.push((x as u32, y as u32));
                }
            }
        }
    }
    (boundary, wrong, stray)
}
