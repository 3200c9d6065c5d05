//! The figures of issue 20 in docs/: `smoothie_profile.png`, V across a straight plate edge's
//! penumbra (centred and outer-only smoothies against the reference), and
//! `smoothie_t_scale.png`, the penumbra RMSE against `t_scale` on the plate and sphere scenes.
//!
//! `cargo run --release --example smoothie_profile [OUT_DIR]` (default docs/).

use std::path::PathBuf;

use softshadow::gpu::ContextOptions;
use softshadow::measure::{Metrics, lines};
use softshadow::scene::Scene;
use softshadow::technique::{Params, find};
use softshadow::{Capture, Engine, FrameSettings};

const SIZE: u32 = 256;

fn render(e: &mut Engine, s: &Scene, technique: &str, sets: &[(&str, &str)]) -> softshadow::Result<Capture> {
    let mut frame = FrameSettings::from_scene(s)?;
    (frame.width, frame.height) = (SIZE, SIZE);
    frame.params = Params::defaults(find(technique)?);
    frame.params.apply(sets.iter().copied())?;
    e.render_and_capture(s, &frame)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out =
        PathBuf::from(std::env::args().nth(1).unwrap_or_else(|| concat!(env!("CARGO_MANIFEST_DIR"), "/docs").into()));
    let mut e = Engine::headless(&ContextOptions { validation: false, device: None })?;
    let reference: &[(&str, &str)] = &[("samples", "256"), ("shadow_map_size", "512")];

    // A 2 m strip at 2 m, lit from (−3, 10, 0) by a light of radius 1.5: its shadow's right
    // edge falls beside it, the hard edge at x = 2; seen from above over x in [0.5, 3.5].
    let (centre, half) = (2.0f32, 1.5f32);
    let strip = Scene::from_toml(
        &format!(
            "[camera]\nposition = [{centre}, 12.0, 0.0]\ntarget = [{centre}, 0.0, 0.0]\nup = [0.0, 0.0, -1.0]\n\
             ortho_half_height = {half}\n[light]\nposition = [-3.0, 10.0, 0.0]\nradius = 1.5\n\
             [ground]\nheight = 0.0\n[[object]]\nshape = \"plate\"\nsize = [2.0, 0.0, 6.0]\n\
             position = [0.0, 2.0, 0.0]\nreceives = false\n"
        ),
        "strip.toml",
    )?;
    let row = |c: &Capture| -> Vec<(f64, f64)> {
        (0..SIZE)
            .map(|px| {
                let x = centre - half + (px as f32 + 0.5) / SIZE as f32 * 2.0 * half;
                (f64::from(x), f64::from(c.visibility_at(px, SIZE / 2)))
            })
            .filter(|(x, _)| *x > 1.05)
            .collect()
    };
    let profiles = [
        ("reference (256 light samples)", row(&render(&mut e, &strip, "reference", reference)?)),
        ("smoothie, centred (default)", row(&render(&mut e, &strip, "smoothie", &[])?)),
        (
            "smoothie, outer only (the paper)",
            row(&render(&mut e, &strip, "smoothie", &[("penumbra", "0"), ("falloff", "0")])?),
        ),
        ("hard shadow map", row(&render(&mut e, &strip, "shadow-map", &[])?)),
    ];
    let caption = "a plate edge's penumbra (hard edge at x = 2 m), 256², lavapipe";
    lines(&out.join("smoothie_profile.png"), caption, ("world x (m)", "V"), &profiles)?;

    let scales = [0.5, 0.65, 0.8, 0.9, 1.0, 1.1, 1.25, 1.5, 2.0];
    let mut errors = Vec::new();
    for name in ["plate", "sphere"] {
        let s = Scene::load(format!("{}/scenes/{name}.toml", env!("CARGO_MANIFEST_DIR")))?;
        let truth = render(&mut e, &s, "reference", reference)?;
        let mut curve = Vec::new();
        for k in scales {
            let c = render(&mut e, &s, "smoothie", &[("t_scale", &k.to_string())])?;
            let m = Metrics::between(&c, &truth)?;
            println!("{name} t_scale {k}: penumbra RMSE {:.4}", m.penumbra_rmse);
            curve.push((k, m.penumbra_rmse));
        }
        errors.push((name, curve));
    }
    let caption = "centred smoothie: penumbra RMSE against t_scale (1 = physical), 256²";
    lines(&out.join("smoothie_t_scale.png"), caption, ("t_scale", "penumbra RMSE"), &errors)?;
    let errors = e.finish();
    assert!(errors.is_empty(), "{errors:?}");
    Ok(())
}
