//! The stability sweep (measure::extremes): every technique over the short grid of each axis,
//! at 64² (the size axis up to 4096²), with validation on. Each test fails on NaN or infinite
//! V, V outside [0, 1], a step that changes the error against the ray tracer by more than
//! `continuity_bound`, surfaces the tracer does not see, or any validation error.

mod common;

use softshadow::measure::extremes::{Axis, BASE, problems, sweep};

fn check(axis: Axis) {
    let mut engine = common::engine();
    let rows = sweep(&mut engine, axis, false, &[], &mut |_| {}).expect("the sweep renders");
    common::finish(engine);
    let per_technique = rows.iter().filter(|r| r.technique == rows[0].technique).count();
    assert_eq!(per_technique, axis.grid(false).len(), "every technique at every point");
    assert!(rows.iter().any(|r| r.technique == "plateau") && rows.iter().any(|r| r.technique == "raytrace"));
    let problems = problems(&rows);
    assert!(problems.is_empty(), "{} problem(s):\n{}", problems.len(), problems.join("\n"));
}

#[test]
fn grazing_to_overhead_lights() {
    check(Axis::Elevation);
}

#[test]
fn point_lights_to_lights_twice_the_caster() {
    check(Axis::LightRadius);
}

#[test]
fn casters_touching_the_ground_to_far_above_it() {
    check(Axis::CasterHeight);
}

#[test]
fn scene_scales_from_a_millimetre_to_ten_kilometres() {
    check(Axis::Scale);
}

#[test]
fn targets_from_64_to_4096_pixels() {
    check(Axis::Size);
}

/// The sweep reads V raw (R32F); what it checks must be what the R16_UNORM image holds.
#[test]
fn raw_visibility_quantizes_to_the_r16_image() {
    let scene = BASE.scene().unwrap();
    let mut engine = common::engine();
    for technique in ["smoothie", "parker"] {
        let stored = common::render_with(&mut engine, &scene, technique, &[], 64);
        engine.set_raw_visibility(true).unwrap();
        let raw = common::render_with(&mut engine, &scene, technique, &[], 64);
        engine.set_raw_visibility(false).unwrap();
        assert!(stored.raw_visibility.is_none());
        let floats = raw.raw_visibility.as_ref().expect("raw V");
        assert!(floats.iter().any(|&v| v > 0.0 && v < 1.0), "{technique}: a penumbra");
        for (i, (&r16, &v)) in stored.visibility.iter().zip(floats).enumerate() {
            let q = softshadow::frame::quantize(v);
            assert!(r16.abs_diff(q) <= 1, "{technique} pixel {i}: R16 {r16}, raw {v} quantizes to {q}");
        }
    }
    common::finish(engine);
}
