//! Headless frames on lavapipe with validation on: physics of the hard shadow, the image
//! orientation of DESIGN.md §3, the game loop, resizing, timings.

mod common;

use common::{engine, finish, scene, settings, shadow_centroid};

/// A box floating over the ground, seen from straight above with image top = −Z, under a
/// point light up and to the +X side, so the box's shadow falls on the visible ground at −X.
const BOX_OVER_GROUND: &str = r#"
[camera]
position = [0.0, 10.0, 0.0]
target = [0.0, 0.0, 0.0]
up = [0.0, 0.0, -1.0]
ortho_half_height = 4.0

[light]
position = [5.0, 10.0, 0.0]
radius = 0.0

[ground]
height = 0.0

[[object]]
shape = "box"
size = [1.0, 1.0, 1.0]
position = [0.0, 2.0, 0.0]
"#;

/// Pixel of world point (x, 0, z) for the top-down orthographic camera above, 4 units half-height.
fn pixel(x: f32, z: f32, size: u32) -> (u32, u32) {
    let s = size as f32 / 8.0;
    (((x + 4.0) * s) as u32, ((z + 4.0) * s) as u32)
}

#[test]
fn the_ground_under_a_box_is_dark_and_far_away_is_lit() {
    let s = scene(BOX_OVER_GROUND);
    let mut e = engine();
    let c = e.render_and_capture(&s, &settings(&s, 128, 128)).unwrap();
    // The shadow's centre: from the light through the box centre (0, 2, 0) to y = 0.
    let (ux, uy) = pixel(-1.25, 0.0, 128);
    assert!(c.visibility_at(ux, uy) < 0.02, "umbra V = {}", c.visibility_at(ux, uy));
    for (x, z) in [(3.0, 3.0), (-3.0, -3.0), (3.0, -3.0), (1.5, 0.0)] {
        let (px, py) = pixel(x, z, 128);
        assert!(c.visibility_at(px, py) > 0.98, "lit ground at ({x}, {z}) has V = {}", c.visibility_at(px, py));
    }
    // The box's top faces the light: lit.
    assert!(c.visibility_at(64, 64) > 0.98);
    finish(e);
}

#[test]
fn pixels_that_see_no_surface_have_v_one() {
    // No ground: most of the view is sky.
    let s = scene(&BOX_OVER_GROUND.replace("[ground]\nheight = 0.0\n", ""));
    let mut e = engine();
    let c = e.render_and_capture(&s, &settings(&s, 64, 64)).unwrap();
    assert_eq!(c.visibility[0], 65535);
    assert_eq!(c.visibility[c.visibility.len() - 1], 65535);
    finish(e);
}

/// A caster off-centre at (cx, cz) with the light across the origin from it: the shadow falls
/// further out in the caster's own quadrant.
fn quadrant_scene(projection: &str, cx: f32, cz: f32) -> String {
    format!(
        r#"
[camera]
position = [0.0, 10.0, 0.0]
target = [0.0, 0.0, 0.0]
up = [0.0, 0.0, -1.0]
{projection}

[light]
position = [{lx}, 10.0, {lz}]
radius = 0.0

[ground]

[[object]]
shape = "box"
size = [1.0, 1.0, 1.0]
position = [{cx}, 2.0, {cz}]
"#,
        lx = -cx,
        lz = -cz
    )
}

#[test]
fn shadows_land_in_the_expected_image_quadrant() {
    let mut e = engine();
    for projection in ["fov_y_deg = 60.0", "ortho_half_height = 6.0"] {
        // Right is +X and the top row is −Z (up' = −Z).
        for (cx, cz, right, top) in [(2.0, -2.0, true, true), (-2.0, 2.0, false, false), (2.0, 2.0, true, false)] {
            let s = scene(&quadrant_scene(projection, cx, cz));
            let c = e.render_and_capture(&s, &settings(&s, 96, 64)).unwrap();
            let (x, y) = shadow_centroid(&c).expect("a shadow in view");
            assert_eq!(x > 48.0, right, "{projection}: caster ({cx}, {cz}): shadow centroid x = {x}");
            assert_eq!(y < 32.0, top, "{projection}: caster ({cx}, {cz}): shadow centroid y = {y}");
        }
    }
    finish(e);
}

#[test]
fn a_hundred_frames_of_a_moving_caster_allocate_nothing_new() {
    let mut s = scene(BOX_OVER_GROUND);
    let set = settings(&s, 64, 64);
    let mut e = engine();
    // The first frame captures too, so the readback buffer exists before counting starts.
    e.render_and_capture(&s, &set).unwrap();
    let after_first = e.context().live_allocations();
    let mut last_shadow_x = None;
    for frame in 0..100 {
        s.objects[0].transform.position.x = (frame as f32 * 0.1).sin() * 1.5;
        s.objects[0].transform.rotation_deg.y = frame as f32 * 3.6;
        if frame % 25 == 24 {
            let c = e.render_and_capture(&s, &set).unwrap();
            last_shadow_x = shadow_centroid(&c).map(|(x, _)| x);
        } else {
            e.render(&s, &set).unwrap();
        }
        assert_eq!(e.context().live_allocations(), after_first, "frame {frame} changed the number of allocations");
    }
    assert!(last_shadow_x.is_some(), "the moving caster still casts a shadow");
    e.flush().unwrap();
    assert!(e.take_timings().len() >= 100, "every frame reports its timings");
    finish(e);
}

#[test]
fn the_image_can_change_size_between_frames() {
    let s = scene(BOX_OVER_GROUND);
    let mut e = engine();
    for (w, h) in [(64, 64), (96, 48), (64, 64)] {
        let c = e.render_and_capture(&s, &settings(&s, w, h)).unwrap();
        assert_eq!((c.width, c.height, c.visibility.len()), (w, h, (w * h) as usize));
        assert!(shadow_centroid(&c).is_some());
    }
    finish(e);
}

#[test]
fn an_image_larger_than_the_device_allows_is_an_error() {
    let s = scene(BOX_OVER_GROUND);
    let mut e = engine();
    let max = e.device().max_image_dimension_2d;
    let err = e.render(&s, &settings(&s, max + 1, 16)).unwrap_err().to_string();
    assert!(err.contains(&(max + 1).to_string()) && err.contains(&max.to_string()), "{err}");
    // The engine still works afterwards.
    e.render_and_capture(&s, &settings(&s, 32, 32)).unwrap();
    finish(e);
}

#[test]
fn a_nan_transform_is_an_error_not_a_nan_image() {
    let mut s = scene(BOX_OVER_GROUND);
    s.objects[0].transform.position.y = f32::NAN;
    let mut e = engine();
    let err = e.render(&s, &settings(&s, 32, 32)).unwrap_err().to_string();
    assert!(err.contains("[[object]] 1 (box1)") && err.contains("`position`") && err.contains("NaN"), "{err}");
    finish(e);
}

#[test]
fn every_pass_reports_a_positive_gpu_time() {
    let s = scene(BOX_OVER_GROUND);
    let set = settings(&s, 64, 64);
    let mut e = engine();
    for _ in 0..4 {
        e.render(&s, &set).unwrap();
    }
    e.flush().unwrap();
    let timings = e.take_timings();
    assert_eq!(timings.len(), 4);
    for t in &timings {
        let names: Vec<_> = t.passes.iter().map(|p| p.name).collect();
        assert_eq!(names, ["prepass", "shadow_map", "resolve", "composite"]);
        assert!(t.passes.iter().all(|p| p.ms > 0.0 && p.ms.is_finite()), "{t:?}");
    }
    finish(e);
}

#[test]
fn a_scene_without_casters_runs_no_shadow_pass() {
    let s = scene(&BOX_OVER_GROUND.replace("position = [0.0, 2.0, 0.0]", "position = [0.0, 2.0, 0.0]\ncasts = false"));
    let mut e = engine();
    let c = e.render_and_capture(&s, &settings(&s, 64, 64)).unwrap();
    assert!(c.visibility.iter().all(|&v| v == 65535), "nothing casts: V = 1 everywhere");
    e.flush().unwrap();
    let passes: Vec<_> = e.take_timings().pop().unwrap().passes.iter().map(|p| p.name).collect();
    assert!(!passes.contains(&"shadow_map"), "{passes:?}");
    finish(e);
}
