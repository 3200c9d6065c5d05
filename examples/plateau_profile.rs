//! Issue 20's pictures: the penumbra profile across a plate's straight edge (the plateau's
//! centred and outer-only forms against the reference), and the penumbra RMSE of the centred
//! plateau against `penumbra_scale` on the plate and sphere scenes, minimal at the physical size.
//!
//! `cargo run --release --example plateau_profile [OUT_DIR]` writes plateau_profile.png and
//! plateau_scale.png (default: docs/) and prints the numbers behind them.

use std::path::{Path, PathBuf};

use softshadow::gpu::ContextOptions;
use softshadow::measure::{Metrics, lines};
use softshadow::scene::Scene;
use softshadow::technique::{Params, find};
use softshadow::{Capture, Engine, FrameSettings};

/// A plate of half size 1 m, 1 m up, under a light of radius 0.5 m 6 m above its centre: the
/// hard edge at x = 1.2 m, the penumbra W = D·h/(H − h) = 0.2 m wide; seen from above, x from
/// 0.8 to 1.6 m (the plate itself hides x < 1 at the middle row, so the profile starts there).
const PLATE_EDGE: &str = r#"
[camera]
position = [1.2, 12.0, 0.0]
target = [1.2, 0.0, 0.0]
up = [0.0, 0.0, -1.0]
ortho_half_height = 0.4
[light]
position = [0.0, 6.0, 0.0]
radius = 0.5
[ground]
height = 0.0
[[object]]
shape = "plate"
size = [2.0, 0.0, 2.0]
position = [0.0, 1.0, 0.0]
receives = false
"#;

const SIZE: u32 = 256;

fn render(e: &mut Engine, s: &Scene, technique: &str, sets: &[(&str, &str)], size: u32) -> softshadow::Result<Capture> {
    let mut frame = FrameSettings::from_scene(s)?;
    (frame.width, frame.height) = (size, size);
    frame.params = Params::defaults(find(technique)?);
    frame.params.apply(sets.iter().copied())?;
    e.render_and_capture(s, &frame)
}

fn truth(e: &mut Engine, s: &Scene, size: u32) -> softshadow::Result<Capture> {
    render(e, s, "reference", &[("samples", "256")], size)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out =
        PathBuf::from(std::env::args().nth(1).unwrap_or_else(|| concat!(env!("CARGO_MANIFEST_DIR"), "/docs").into()));
    let mut e = Engine::headless(&ContextOptions { validation: false, device: None })?;

    let plate = Scene::from_toml(PLATE_EDGE, "examples/plate_edge.toml")?;
    let forms: [(&str, &[(&str, &str)]); 3] = [
        ("plateau, centred (default)", &[]),
        ("plateau, outer only (physical size)", &[("penumbra", "0"), ("falloff", "0")]),
        (
            "plateau, outer only (scale 0.4, the old default)",
            &[("penumbra", "0"), ("falloff", "0"), ("penumbra_scale", "0.4")],
        ),
    ];
    let x = |px: u32| 0.8 + (px as f64 + 0.5) * 0.8 / SIZE as f64 - 1.2;
    let profile = |c: &Capture| -> Vec<(f64, f64)> {
        // The plate hides the ground left of x = 1 m: the profile starts past it.
        (SIZE / 4 + 2..SIZE).map(|px| (x(px), c.visibility_at(px, SIZE / 2) as f64)).collect()
    };
    let mut series = vec![("reference (256 light samples)", profile(&truth(&mut e, &plate, SIZE)?))];
    for (name, sets) in forms {
        series.push((name, profile(&render(&mut e, &plate, "plateau", sets, SIZE)?)));
    }
    for (name, points) in &series {
        let at = |want: f64| points.iter().min_by(|a, b| (a.0 - want).abs().total_cmp(&(b.0 - want).abs())).unwrap().1;
        println!("{name}: V at s = -0.1, -0.05, 0, 0.05, 0.1 m: {:.3?}", [-0.1, -0.05, 0.0, 0.05, 0.1].map(at));
    }
    let profile_png = out.join("plateau_profile.png");
    lines(
        &profile_png,
        "V across a plate's straight edge (W = 0.2 m; hard edge at s = 0)",
        ("s: distance from the hard edge, m (positive outside)", "V"),
        &series,
    )?;

    let scales = [0.5, 0.65, 0.8, 0.9, 1.0, 1.1, 1.25, 1.4, 1.6, 2.0];
    let mut curves = Vec::new();
    for name in ["plate", "sphere"] {
        let s = Scene::load(Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("scenes/{name}.toml")))?;
        let reference = truth(&mut e, &s, SIZE)?;
        let mut curve = Vec::new();
        for k in scales {
            let v = render(&mut e, &s, "plateau", &[("penumbra_scale", &k.to_string())], SIZE)?;
            curve.push((k, Metrics::between(&v, &reference)?.penumbra_rmse));
        }
        println!("{name}: penumbra RMSE by penumbra_scale {:.4?}", curve);
        curves.push((name, curve));
    }
    let scale_png = out.join("plateau_scale.png");
    lines(
        &scale_png,
        "centred plateau: penumbra RMSE against penumbra_scale (1 = physical)",
        ("penumbra_scale", "penumbra RMSE vs reference"),
        &curves,
    )?;
    let errors = e.finish();
    if !errors.is_empty() {
        return Err(errors.join("\n").into());
    }
    println!("wrote {} and {}", profile_png.display(), scale_png.display());
    Ok(())
}
