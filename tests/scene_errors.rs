//! Bad scene files get an error that names the file and the key or line, never a panic.

use std::io::Write;

use softshadow::FrameSettings;
use softshadow::scene::Scene;

const GOOD: &str = r#"
[camera]
position = [0.0, 5.0, 8.0]
target = [0.0, 0.0, 0.0]
fov_y_deg = 45.0

[light]
position = [2.0, 8.0, 1.0]
radius = 0.25

[ground]
height = 0.0

[[object]]
shape = "box"
size = [1.0, 1.0, 1.0]
position = [0.0, 0.5, 0.0]
"#;

/// Loads `text` as `bad.toml` and builds its frame settings (which check the technique and its
/// knobs), expects an error, and checks it names the file and each `needle`.
fn rejects(text: &str, needles: &[&str]) {
    let settings = Scene::from_toml(text, "bad.toml").and_then(|s| FrameSettings::from_scene(&s));
    let err = settings.expect_err("the scene should be rejected").to_string();
    assert!(err.starts_with("bad.toml:"), "error does not name the file: {err}");
    for n in needles {
        assert!(err.contains(n), "error does not mention `{n}`: {err}");
    }
}

#[test]
fn the_good_scene_loads() {
    let s = Scene::from_toml(GOOD, "good.toml").unwrap();
    assert_eq!(s.objects.len(), 1);
    assert!(s.ground.is_some());
}

#[test]
fn unknown_keys_are_named_with_their_line() {
    rejects(&GOOD.replace("radius = 0.25", "radius = 0.25\nbrightness = 3"), &["brightness", "line 10"]);
    rejects(&format!("{GOOD}\n[fog]\ndensity = 1"), &["fog"]);
}

#[test]
fn non_finite_numbers_are_rejected() {
    rejects(&GOOD.replace("position = [0.0, 0.5, 0.0]", "position = [nan, 0.5, 0.0]"), &["position"]);
    rejects(&GOOD.replace("position = [2.0, 8.0, 1.0]", "position = [2.0, inf, 1.0]"), &["light.position"]);
    rejects(&GOOD.replace("fov_y_deg = 45.0", "fov_y_deg = nan"), &["fov_y_deg"]);
}

#[test]
fn camera_up_must_be_usable() {
    rejects(&GOOD.replace("fov_y_deg = 45.0", "fov_y_deg = 45.0\nup = [0.0, 0.0, 0.0]"), &["camera.up", "zero length"]);
    let down = GOOD.replace("position = [0.0, 5.0, 8.0]", "position = [0.0, 5.0, 0.0]");
    rejects(&down, &["camera.up", "parallel"]);
    rejects(&GOOD.replace("fov_y_deg = 45.0", "fov_y_deg = 45.0\northo_half_height = 2.0"), &["not both"]);
}

#[test]
fn negative_sizes_are_rejected() {
    rejects(&GOOD.replace("radius = 0.25", "radius = -1.0"), &["light.radius"]);
    rejects(&GOOD.replace("size = [1.0, 1.0, 1.0]", "size = [1.0, -1.0, 1.0]"), &["object", "size"]);
    let sphere = GOOD.replace("shape = \"box\"\nsize = [1.0, 1.0, 1.0]", "shape = \"sphere\"\nradius = 0.0");
    rejects(&sphere, &["radius", "(0, 1e9]"]);
    rejects(&GOOD.replace("position = [0.0, 0.5, 0.0]", "position = [0.0, 0.5, 0.0]\nscale = -2.0"), &["scale"]);
    rejects(&GOOD.replace("shape = \"box\"", "shape = \"box\"\nradius = 2.0"), &["radius", "does not apply"]);
}

#[test]
fn the_light_must_be_above_the_ground() {
    rejects(&GOOD.replace("position = [2.0, 8.0, 1.0]", "position = [2.0, -1.0, 1.0]"), &["inside the ground"]);
    // A sphere that dips into the ground counts too.
    rejects(
        &GOOD.replace("position = [2.0, 8.0, 1.0]\nradius = 0.25", "position = [2.0, 0.1, 1.0]\nradius = 0.5"),
        &["inside the ground"],
    );
}

#[test]
fn render_settings_are_checked() {
    rejects(&format!("{GOOD}\n[render]\nwidth = 0"), &["render size"]);
    rejects(&format!("{GOOD}\n[render]\nwidth = -5"), &["width"]);
    // The technique and each knob are reported at their line: GOOD's lines, a blank one, `[render]`.
    let technique_line = format!("line {}:", GOOD.lines().count() + 3);
    let knob_line = format!("line {}:", GOOD.lines().count() + 4);
    rejects(
        &format!("{GOOD}\n[render]\ntechnique = \"shadowmap\""),
        &["unknown technique", "shadowmap", &technique_line],
    );
    rejects(&format!("{GOOD}\n[render]\n[render.params]\nsamples = 4"), &["samples", "shadow_map_size", &knob_line]);
    rejects(
        &format!("{GOOD}\n[render]\n[render.params]\nshadow_map_size = 3.5"),
        &["shadow_map_size", "whole number", &knob_line],
    );
}

#[test]
fn meshes_must_exist_and_hold_triangles() {
    let dir = std::env::temp_dir().join(format!("softshadow-scene-errors-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let with_mesh = |mesh: &str| {
        GOOD.replace("shape = \"box\"\nsize = [1.0, 1.0, 1.0]", &format!("shape = \"mesh\"\nmesh = \"{mesh}\""))
    };

    let missing = Scene::from_toml(&with_mesh("nowhere.obj"), dir.join("s.toml")).unwrap_err().to_string();
    assert!(missing.contains("nowhere.obj") && missing.contains("cannot read"), "{missing}");

    let empty = dir.join("empty.obj");
    std::fs::File::create(&empty).unwrap().write_all(b"# nothing here\nv 0 0 0\n").unwrap();
    let err = Scene::from_toml(&with_mesh("empty.obj"), dir.join("s.toml")).unwrap_err().to_string();
    assert!(err.contains("empty.obj") && err.contains("no triangles"), "{err}");

    let broken = dir.join("broken.obj");
    std::fs::File::create(&broken).unwrap().write_all(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n").unwrap();
    assert!(Scene::from_toml(&with_mesh("broken.obj"), dir.join("s.toml")).is_err());

    let unreadable = Scene::load(dir.join("no-scene-here.toml")).unwrap_err().to_string();
    assert!(unreadable.contains("no-scene-here.toml"), "{unreadable}");
    std::fs::remove_dir_all(&dir).ok();
}
