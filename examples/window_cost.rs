//! What the window costs over headless: the same scene and technique rendered in a loop
//! offscreen and presented (FIFO), at 512² and 1024²; median wall ms per frame, the CPU spent
//! acquiring and presenting, and the swapchain re-creation on a resize. One run; on lavapipe
//! the GPU is the CPU, so read ratios.
//!
//! `cargo run --release --example window_cost [SCENE]` (needs a display; `xvfb-run -s
//! "-screen 0 2048x2048x24"` will do).

use std::time::Instant;

use softshadow::gpu::ContextOptions;
use softshadow::measure::TimingReport;
use softshadow::scene::Scene;
use softshadow::{AppWindow, Engine, FrameSettings, WindowOptions};
use winit::dpi::PhysicalSize;

const FRAMES: usize = 60;
const WARMUP: usize = 5;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Median wall ms between the ends of consecutive frames.
fn time(mut frame: impl FnMut() -> softshadow::Result<()>) -> softshadow::Result<f64> {
    let mut ms = Vec::new();
    for i in 0..WARMUP + FRAMES {
        let start = Instant::now();
        frame()?;
        if i >= WARMUP {
            ms.push(start.elapsed().as_secs_f64() * 1e3);
        }
    }
    Ok(median(ms))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path =
        std::env::args().nth(1).unwrap_or_else(|| concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/default.toml").into());
    let scene = Scene::load(&path)?;
    let mut settings = FrameSettings::from_scene(&scene)?;
    let options = ContextOptions::from_env();
    let mut app = AppWindow::open("softshadow window cost", 512, 512)?;
    let mut headless = Engine::headless(&options)?;
    let mut windowed = Engine::windowed(&options, app.window().clone(), WindowOptions::default())?;
    println!(
        "{} on {} ({}), technique {}",
        path,
        headless.device().name,
        headless.device().driver,
        settings.params.technique.name
    );
    for side in [512, 1024] {
        let _ = app.window().request_inner_size(PhysicalSize::new(side, side));
        while app.window().inner_size() != PhysicalSize::new(side, side) {
            app.poll();
        }
        (settings.width, settings.height) = (side, side);
        let offscreen = time(|| headless.render(&scene, &settings))?;
        windowed.take_timings();
        let presented = time(|| {
            app.poll();
            windowed.present(&scene, &settings.params).map(|_| ())
        })?;
        windowed.flush()?;
        let timings = windowed.take_timings();
        let report = TimingReport::new(windowed.device(), settings.params.technique.name, side, side, &timings);
        let cpu = |name: &str| report.cpu_ms.get(name).copied().unwrap_or(0.0);
        let stats = windowed.window_stats().expect("windowed");
        println!(
            "{side}²: headless {offscreen:.2} ms/frame, windowed {presented:.2} ms/frame ({:+.2}); acquire {:.3} ms, \
             present {:.3} ms CPU; swapchain ({:?}, {:?}) re-created in {:.2} ms",
            presented - offscreen,
            cpu("acquire"),
            cpu("present"),
            stats.format,
            stats.present_mode,
            stats.last_recreation_ms
        );
    }
    for errors in [headless.finish(), windowed.finish()] {
        if !errors.is_empty() {
            return Err(errors.join("\n").into());
        }
    }
    Ok(())
}
