//! The long soak of issue 19: 100 000 frames of a moving caster through the game-loop API at
//! 32×32, resident memory sampled every 10 000 frames; fails when it grows by more than 1 MB
//! after the first sample. `cargo run --release --example soak [FRAMES]`.

use softshadow::gpu::ContextOptions;
use softshadow::scene::Scene;
use softshadow::{Engine, FrameSettings};

/// Resident memory in bytes, from /proc/self/statm (pages).
fn resident() -> u64 {
    let statm = std::fs::read_to_string("/proc/self/statm").expect("Linux /proc");
    let pages: u64 = statm.split_whitespace().nth(1).and_then(|p| p.parse().ok()).expect("statm's resident field");
    pages * 4096
}

fn main() -> Result<(), softshadow::Error> {
    let frames: usize = std::env::args().nth(1).and_then(|f| f.parse().ok()).unwrap_or(100_000);
    let mut scene = Scene::load(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/plate.toml"))?;
    let mut settings = FrameSettings::from_scene(&scene)?;
    (settings.width, settings.height) = (32, 32);
    let mut engine = Engine::headless(&ContextOptions::from_env())?;
    let mut samples = Vec::new();
    for frame in 0..frames {
        scene.objects[0].transform.position.x = (frame as f32 * 0.01).sin();
        engine.render(&scene, &settings)?;
        if (frame + 1) % 10_000 == 0 {
            samples.push(resident());
            println!("frame {:>7}: resident {:.2} MB", frame + 1, *samples.last().unwrap() as f64 / 1e6);
        }
    }
    let errors = engine.finish();
    assert!(errors.is_empty(), "{errors:?}");
    if let (Some(first), Some(max)) = (samples.first(), samples.iter().max()) {
        let growth = max - first;
        println!("growth after the first sample: {:.3} MB", growth as f64 / 1e6);
        assert!(growth <= 1 << 20, "resident memory grew by {growth} bytes");
    }
    Ok(())
}
