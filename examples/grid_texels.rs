//! How many texels a centred smoothie's narrowest penumbra must span before a halved grid costs
//! accuracy on straight edges: the evidence for the smoothie's `penumbra_texels`
//! (src/technique/smoothie.rs, its `PENUMBRA_TEXELS`).
//!
//! The plate and sphere scenes under lights from a quarter to twice their radius: the centred
//! smoothie at fixed grids of 1024², 512² and 256² against the reference, and the narrowest
//! smoothie the technique estimates, in texels of 1024² (found from the grid it picks for each
//! `penumbra_texels`: it halves exactly while that many texels fit). Each halving is one point:
//! the narrowest in texels of the coarser grid, and what the halving added to the penumbra RMSE.
//!
//! `cargo run --release --example grid_texels [OUT_DIR]` (default docs/): prints the table and
//! plots OUT_DIR/grid_texels.png.

use std::path::PathBuf;

use softshadow::gpu::ContextOptions;
use softshadow::measure::{Metrics, lines};
use softshadow::scene::Scene;
use softshadow::technique::{Params, find};
use softshadow::{Capture, Engine, FrameSettings};

const SIZE: u32 = 256;
/// The size the grid picks are told apart at: any size shows which grid was used.
const PROBE_SIZE: u32 = 64;

fn render(
    e: &mut Engine,
    s: &Scene,
    technique: &str,
    sets: &[(&str, String)],
    size: u32,
) -> softshadow::Result<Capture> {
    let mut frame = FrameSettings::from_scene(s)?;
    (frame.width, frame.height) = (size, size);
    frame.params = Params::defaults(find(technique)?);
    frame.params.apply(sets.iter().map(|(k, v)| (*k, v.as_str())))?;
    e.render_and_capture(s, &frame)
}

/// The centred smoothie on a fixed grid of `grid`² (map and buffer).
fn fixed(grid: u32) -> Vec<(&'static str, String)> {
    let g = grid.to_string();
    vec![("shadow_map_size", g.clone()), ("smoothie_size", g), ("penumbra_texels", "0".into())]
}

/// The narrowest smoothie in texels of 1024², to 1 %: the grid halves once `penumbra_texels` is
/// at most half of it (src/technique/grid.rs), which shows as a frame that differs from the
/// full grid's.
fn narrowest(e: &mut Engine, s: &Scene) -> softshadow::Result<f32> {
    let full = render(e, s, "smoothie", &fixed(1024), PROBE_SIZE)?;
    let (mut halves, mut keeps) = (0.25f32, 512.0f32);
    while keeps / halves > 1.01 {
        let t = (halves * keeps).sqrt();
        let c = render(e, s, "smoothie", &[("penumbra_texels", t.to_string())], PROBE_SIZE)?;
        if c.visibility == full.visibility { keeps = t } else { halves = t }
    }
    Ok(2.0 * halves)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out =
        PathBuf::from(std::env::args().nth(1).unwrap_or_else(|| concat!(env!("CARGO_MANIFEST_DIR"), "/docs").into()));
    let mut e = Engine::headless(&ContextOptions { validation: false, device: None })?;
    let reference = [("samples", "256".to_string())];
    let mut curves = Vec::new();
    println!(
        "scene, light radius, narrowest (texels of 1024²) | per grid 1024², 512², 256²: penumbra RMSE, p99 |error|, leak rate"
    );
    for (name, radius) in [("plate", 0.4f32), ("sphere", 0.5)] {
        let path = format!("{}/scenes/{name}.toml", env!("CARGO_MANIFEST_DIR"));
        let text = std::fs::read_to_string(&path)?;
        let line = format!("radius = {radius}\n");
        assert!(text.contains(&line), "{path}: the light's radius is not {radius}");
        let mut points = Vec::new();
        for k in [0.25f32, 0.375, 0.5, 0.75, 1.0, 1.5, 2.0] {
            let s = Scene::from_toml(&text.replacen(&line, &format!("radius = {}\n", k * radius), 1), &path)?;
            let truth = render(&mut e, &s, "reference", &reference, SIZE)?;
            let mut metrics = |grid| Metrics::between(&render(&mut e, &s, "smoothie", &fixed(grid), SIZE)?, &truth);
            let [m1024, m512, m256] = [metrics(1024)?, metrics(512)?, metrics(256)?];
            let n = narrowest(&mut e, &s)?;
            print!("{name} {:.3} {n:.1}", k * radius);
            for m in [&m1024, &m512, &m256] {
                print!(" | {:.4} {:.4} {:.5}", m.penumbra_rmse, m.p99_abs, m.leak_rate);
            }
            println!();
            points.push((f64::from(n / 2.0), m512.penumbra_rmse - m1024.penumbra_rmse));
            points.push((f64::from(n / 4.0), m256.penumbra_rmse - m512.penumbra_rmse));
        }
        points.sort_by(|a, b| a.0.total_cmp(&b.0));
        curves.push((name, points));
    }
    let caption = "centred smoothie: penumbra RMSE a halving adds, against the narrowest smoothie's texels after it";
    lines(
        &out.join("grid_texels.png"),
        caption,
        ("narrowest smoothie, texels of the halved grid", "Δ penumbra RMSE"),
        &curves,
    )?;
    let errors = e.finish();
    assert!(errors.is_empty(), "{errors:?}");
    Ok(())
}
