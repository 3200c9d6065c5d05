//! The game loop to copy: create once; each iteration poll input, update transforms and the
//! light, render, read the last frames' GPU timings; destroy at the end.
//!
//! `cargo run --release --example game_loop` opens a window over the default scene: the casters
//! bob and turn, the light circles, Tab switches technique, Esc quits. `-- --frames N` exits
//! after N frames (switching technique every N/4), `SOFTSHADOW_VALIDATION=1` checks every call.

use std::time::Instant;

use glam::Vec3;
use softshadow::gpu::ContextOptions;
use softshadow::scene::Scene;
use softshadow::technique::{Kind, Params, TECHNIQUES};
use softshadow::{AppWindow, Engine, WindowOptions};
use winit::event::{ElementState, WindowEvent};
use winit::keyboard::{Key, NamedKey};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let frames: Option<u64> = match args.iter().position(|a| a == "--frames") {
        Some(i) => Some(args.get(i + 1).ok_or("--frames needs a number")?.parse()?),
        None => None,
    };

    // Create once: a window, an engine presenting to it, the scene and the techniques to cycle.
    let mut app = AppWindow::open("softshadow game loop", 800, 600)?;
    let mut engine = Engine::windowed(&ContextOptions::from_env(), app.window().clone(), WindowOptions::default())?;
    let mut scene = Scene::load(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/default.toml"))?;
    let techniques: Vec<_> = TECHNIQUES.iter().filter(|t| t.kind == Kind::Realtime).collect();
    let mut current = 0;
    let mut params = Params::defaults(techniques[current]);
    let rest: Vec<Vec3> = scene.objects.iter().map(|o| o.transform.position).collect();
    let light_height = scene.light.position.y;
    let start = Instant::now();
    let mut gpu_ms = 0.0;

    let mut frame: u64 = 0;
    'game: loop {
        // Input: everything the window reported since the last frame, without waiting.
        let mut switch = frames.is_some_and(|n| n >= 4 && frame > 0 && frame.is_multiple_of(n / 4));
        for event in app.poll() {
            match event {
                WindowEvent::CloseRequested => break 'game,
                WindowEvent::KeyboardInput { event, .. } if event.state == ElementState::Pressed => {
                    match event.logical_key {
                        Key::Named(NamedKey::Escape) => break 'game,
                        Key::Named(NamedKey::Tab) => switch = true,
                        _ => {}
                    }
                }
                _ => {}
            }
        }
        if switch {
            current = (current + 1) % techniques.len();
            params = Params::defaults(techniques[current]);
        }

        // Update: the casters bob and turn, the light circles above them. Only what moved is
        // recomputed by the engine (silhouettes, technique geometry).
        let t = start.elapsed().as_secs_f32();
        for (i, (object, rest)) in scene.objects.iter_mut().zip(&rest).enumerate() {
            let phase = t * 1.5 + i as f32;
            object.transform.position = *rest + Vec3::Y * (0.25 * phase.sin()).max(0.0);
            object.transform.rotation_deg.y = 20.0 * phase;
        }
        scene.light.position = Vec3::new(3.0 * (0.4 * t).cos(), light_height, 3.0 * (0.4 * t).sin());

        // Render: the frame is recorded and presented; a minimised window skips it.
        engine.present(&scene, &params)?;

        // Timings: GPU times come back a frame or two late, once the GPU has finished.
        if let Some(last) = engine.take_timings().last() {
            gpu_ms = last.passes.iter().map(|p| p.ms).sum::<f64>();
        }
        if frame.is_multiple_of(30) {
            app.window().set_title(&format!("softshadow game loop: {} {gpu_ms:.2} GPU ms", techniques[current].name));
        }

        frame += 1;
        if frames.is_some_and(|n| frame >= n) {
            break;
        }
    }

    // Destroy at the end: waits for the GPU; with validation on, any error or leak is reported.
    let seconds = start.elapsed().as_secs_f64();
    println!("{frame} frames in {seconds:.1} s ({:.1} fps), last GPU frame {gpu_ms:.2} ms", frame as f64 / seconds);
    let errors = engine.finish();
    if !errors.is_empty() {
        return Err(format!("{} validation errors:\n{}", errors.len(), errors.join("\n")).into());
    }
    Ok(())
}
