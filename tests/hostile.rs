//! A hostile-input corpus: every numeric field of the scene file given non-finite, huge,
//! mistyped and misshapen values, bad OBJ files and paths, and command-line misuse. Each case
//! must give a clear error naming the file and the key (or line) — never a panic, a hang or a
//! silently wrong scene.

use std::io::Write;
use std::process::Command;

use softshadow::FrameSettings;
use softshadow::scene::Scene;

/// A valid scene in which `{key}` placeholders take each field's value.
const TEMPLATE: &str = r#"
[camera]
position = {camera.position}
target = {camera.target}
up = {camera.up}
fov_y_deg = {camera.fov_y_deg}

[light]
position = {light.position}
radius = {light.radius}
target = {light.target}

[ground]
height = {ground.height}
half_size = {ground.half_size}

[[object]]
shape = "box"
size = {size}
position = {position}
rotation_deg = {rotation_deg}
scale = {scale}
color = {color}

[[object]]
shape = "sphere"
radius = {radius}
position = [1.0, 1.0, 0.0]

[[object]]
shape = "cylinder"
radius = 0.3
height = {height}
position = [-1.0, 1.0, 0.0]

[render]
width = {width}
height = 64
"#;

/// Each field, its valid value, and whether it is a triple.
const FIELDS: &[(&str, &str, bool)] = &[
    ("camera.position", "[0.0, 5.0, 8.0]", true),
    ("camera.target", "[0.0, 0.0, 0.0]", true),
    ("camera.up", "[0.0, 1.0, 0.0]", true),
    ("camera.fov_y_deg", "45.0", false),
    ("light.position", "[2.0, 8.0, 1.0]", true),
    ("light.radius", "0.25", false),
    ("light.target", "[0.0, 0.0, 0.0]", true),
    ("ground.height", "0.0", false),
    ("ground.half_size", "10.0", false),
    ("size", "[1.0, 1.0, 1.0]", true),
    ("position", "[0.0, 0.5, 0.0]", true),
    ("rotation_deg", "[0.0, 30.0, 0.0]", true),
    ("scale", "1.0", false),
    ("color", "[0.5, 0.5, 0.5]", true),
    ("radius", "0.5", false),
    ("height", "1.0", false),
    ("width", "64", false),
];

const BAD_SCALARS: &[&str] = &["nan", "inf", "-inf", "1e30", "-1e30", "\"ten\"", "true", "[1.0, 2.0]"];
const BAD_TRIPLES: &[&str] = &[
    "[nan, 0.0, 0.0]",
    "[0.0, inf, 0.0]",
    "[1e30, 1.0, 1.0]",
    "[-1e30, 1.0, 1.0]",
    "[1.0, 2.0]",
    "[1, 1, 1, 99, \"junk\", true]",
    "[\"a\", 0.0, 0.0]",
    "5.0",
];

fn scene_text(key: &str, value: &str) -> String {
    FIELDS.iter().fold(TEMPLATE.to_string(), |text, (k, v, _)| {
        text.replace(&format!("{{{k}}}"), if *k == key { value } else { v })
    })
}

/// The error of loading `text` as `bad.toml` and building its frame settings.
fn error_of(text: &str) -> Option<String> {
    let settings = Scene::from_toml(text, "bad.toml").and_then(|s| FrameSettings::from_scene(&s));
    settings.err().map(|e| e.to_string())
}

#[test]
fn the_template_is_valid() {
    assert_eq!(error_of(&scene_text("", "")), None);
}

#[test]
fn every_field_refuses_every_bad_value_by_name() {
    let mut cases = 0;
    let mut failures = Vec::new();
    for (key, _, triple) in FIELDS {
        for value in if *triple { BAD_TRIPLES } else { BAD_SCALARS } {
            // A per-axis scale is a triple too.
            if *key == "scale" && *value == "[1.0, 2.0]" {
                continue;
            }
            cases += 1;
            let leaf = key.rsplit('.').next().unwrap();
            match error_of(&scene_text(key, value)) {
                None => failures.push(format!("{key} = {value}: accepted")),
                Some(e) if !(e.starts_with("bad.toml:") && e.contains(leaf)) => {
                    failures.push(format!("{key} = {value}: the error names neither the file nor `{leaf}`: {e}"))
                }
                Some(e) if e.len() > 1000 => failures.push(format!("{key} = {value}: {} bytes of error", e.len())),
                Some(_) => {}
            }
        }
    }
    assert!(cases >= 100, "{cases} cases");
    assert!(failures.is_empty(), "{} of {cases} cases:\n{}", failures.len(), failures.join("\n"));
}

#[test]
fn structure_errors_name_the_key() {
    let good = scene_text("", "");
    for (text, needle) in [
        (good.replace("[camera]", "[camra]"), "camra"),
        (good.replace("fov_y_deg = 45.0\n", ""), "fov_y_deg"),
        (good.replace("radius = 0.25\n", ""), "radius"),
        (good.replace("shape = \"box\"", "shape = \"cube\""), "cube"),
        (good.replace("shape = \"box\"", ""), "shape"),
        (good.replace("[render]", "[render]\nfps = 60"), "fps"),
        (good.replace("[render]", "[render]\ntechnique = 3"), "technique"),
        (format!("{good}\n[render.params]\nshadow_map_size = [1]"), "shadow_map_size"),
        (good.replace("size = [1.0, 1.0, 1.0]", "size = [1.0, 1.0, 1.0]\nradius = 1.0"), "radius"),
        (good.replace("[[object]]\nshape = \"sphere\"\nradius = 0.5", "[[object]]\nshape = \"sphere\""), "radius"),
        ("[camera".to_string(), "line 1"),
        (format!("{good}\nname = \"{}\"", "x".repeat(200_000)), "name"),
    ] {
        let e = error_of(&text).unwrap_or_else(|| panic!("accepted: {needle}"));
        assert!(e.starts_with("bad.toml:") && e.contains(needle), "`{needle}` not named: {e}");
        assert!(e.len() < 2000, "a {} byte error for `{needle}`", e.len());
    }
}

/// A scratch folder for files the cases write.
fn scratch(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("softshadow-hostile-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn bad_obj_files_are_refused_by_name() {
    let dir = scratch("obj");
    let good = scene_text("", "");
    let with_mesh = good.replace("shape = \"box\"\nsize = [1.0, 1.0, 1.0]", "shape = \"mesh\"\nmesh = \"m.obj\"");
    let long_line = format!("v 0 0 0\nv 1 0 0\nv 0 1 0\n# {}\nf 1 2 3\n", "x".repeat(100_000));
    for (content, needle) in [
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\np 1 2 3\n", "no triangles"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\nl 2 3\n", "has area"),
        ("v 0 0 0\nv 1 0 0\nf 1 2\nf 1 1 2\n", "has area"),
        ("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n", "has area"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", "line 4"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n", "line 4"),
        ("v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "finite"),
        ("v 0 0 x\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "line 1"),
        ("\u{0}\u{1}binary", "m.obj"),
        ("", "no triangles"),
        (long_line.as_str(), "line 4"),
    ] {
        std::fs::File::create(dir.join("m.obj")).unwrap().write_all(content.as_bytes()).unwrap();
        let e = Scene::from_toml(&with_mesh, dir.join("s.toml")).err().map(|e| e.to_string());
        let e = e.unwrap_or_else(|| panic!("accepted an OBJ of {content:?}"));
        assert!(e.contains("m.obj") && e.contains(needle), "`{needle}` not named: {e}");
    }
    // Found by tests/fuzz.rs: tobj multiplied this normal index and overflowed. Only the
    // shape is read, so the face loads.
    let overflow = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//99999999999999999999 2 3\n";
    std::fs::write(dir.join("m.obj"), overflow).unwrap();
    assert!(Scene::from_toml(&with_mesh, dir.join("s.toml")).is_ok());
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn paths_that_are_not_regular_files_are_refused_without_blocking() {
    let dir = scratch("paths");
    let fifo = dir.join("fifo");
    let made = Command::new("mkfifo").arg(&fifo).status().is_ok_and(|s| s.success());
    assert!(made, "mkfifo is part of coreutils");
    for path in [fifo.clone(), dir.clone(), "/dev/zero".into(), dir.join("missing.toml")] {
        let e = Scene::load(&path).err().map(|e| e.to_string()).unwrap_or_default();
        assert!(e.contains(&path.display().to_string()) && e.contains("cannot read"), "{}: {e}", path.display());
    }
    let good = scene_text("", "");
    let mesh = good.replace("shape = \"box\"\nsize = [1.0, 1.0, 1.0]", "shape = \"mesh\"\nmesh = \"fifo\"");
    let e = Scene::from_toml(&mesh, dir.join("s.toml")).err().map(|e| e.to_string()).unwrap_or_default();
    assert!(e.contains("fifo") && e.contains("not a regular file"), "{e}");
    std::fs::remove_dir_all(dir).unwrap();
}

/// One vertex shared by every triangle: building the render normals was quadratic in the
/// vertex's valence (minutes for this fan), and is linear now.
#[test]
fn a_vertex_of_huge_valence_loads() {
    let n = 200_000u32;
    let mut positions = vec![glam::Vec3::ZERO];
    positions.extend((0..=n).map(|i| {
        let a = i as f32 / n as f32 * std::f32::consts::TAU;
        glam::Vec3::new(a.cos(), 0.1 * (7.0 * a).sin(), a.sin())
    }));
    let triangles: Vec<[u32; 3]> = (1..=n).map(|i| [0, i + 1, i]).collect();
    let mesh = softshadow::scene::Mesh::new("fan", positions, triangles).unwrap();
    let (vertices, indices) = mesh.render_geometry();
    assert_eq!(indices.len(), 3 * n as usize);
    assert!(vertices.iter().all(|v| v.normal.iter().all(|c| c.is_finite())));
}

#[test]
fn command_line_misuse_is_refused_by_name() {
    let bin = env!("CARGO_BIN_EXE_softshadow");
    for (args, needle) in [
        (vec!["render", "scenes/default.toml", "--set", "shadow_map_size"], "KEY=VALUE"),
        (vec!["render", "scenes/default.toml", "--set", "nope=1"], "nope"),
        (vec!["render", "scenes/default.toml", "--width", "0"], "0"),
        (vec!["render", "scenes/default.toml", "--frames", "0"], "--frames"),
        (vec!["render", "no/such/scene.toml"], "no/such/scene.toml"),
        (vec!["compare", "scenes/plate.toml", "--against", "pcf"], "ground truth"),
        (vec!["render", "scenes/plate.toml", "--out", "/no/such/dir/c.png"], "/no/such/dir"),
        (vec!["render", "scenes/plate.toml", "--technique", "plateu"], "plateu"),
    ] {
        let out = Command::new(bin).args(&args).output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && stderr.contains(needle), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    }
}
