//! The scale scenes (issue 18) are what they claim: the scanned meshes closed and large, the
//! open koala open, the knot as many triangles as asked; a knot's size is checked on load.

use softshadow::scene::Scene;

fn load(name: &str) -> Scene {
    Scene::load(format!("{}/scenes/scale/{name}.toml", env!("CARGO_MANIFEST_DIR"))).expect("a scale scene")
}

#[test]
fn the_scale_scenes_hold_what_they_claim() {
    for (name, at_least) in [("hammer", 60_000), ("koala", 99_000)] {
        let s = load(name);
        let mesh = &s.objects[0].mesh;
        assert!(mesh.triangles.len() >= at_least && mesh.adjacency.is_closed(), "{name}");
    }
    let open = load("koala_open");
    assert!(open.objects[0].mesh.adjacency.boundary > 0 && open.objects[0].mesh.triangles.len() > 90_000);
    let knot = load("knot");
    let mesh = &knot.objects[0].mesh;
    let n = mesh.triangles.len() as f64;
    assert!((n / 100_000.0 - 1.0).abs() < 0.01 && mesh.adjacency.is_closed(), "{n}");
}

#[test]
fn a_knot_needs_a_triangle_count_in_range() {
    let text = std::fs::read_to_string(format!("{}/scenes/scale/knot.toml", env!("CARGO_MANIFEST_DIR"))).unwrap();
    for (bad, needle) in [("triangles = 3", "triangles"), ("triangles = 100000000", "triangles"), ("", "triangles")] {
        let err = Scene::from_toml(&text.replace("triangles = 100000", bad), "knot.toml").unwrap_err().to_string();
        assert!(err.contains(needle) && err.starts_with("knot.toml"), "{err}");
    }
    let sphere = text.replace("shape = \"knot\"", "shape = \"sphere\"\nradius = 1.0");
    let err = Scene::from_toml(&sphere, "knot.toml").unwrap_err().to_string();
    assert!(err.contains("`triangles` does not apply"), "{err}");
}
