//! `softshadow view SCENE`: the interactive viewer, on the same windowed engine a game uses.
//! Left drag orbits, right drag pans, the wheel zooms, Ctrl + left drag moves the light; keys
//! are listed in [`KEYS`].

use std::collections::VecDeque;
use std::path::{Path, PathBuf};

use anyhow::{Context as _, Result};
use glam::Vec3;
use softshadow::gpu::ContextOptions;
use softshadow::measure::{Metrics, TimingReport};
use softshadow::technique::registry::ground_truth;
use softshadow::technique::{Kind, Params, Runs, TECHNIQUES};
use softshadow::{AppWindow, Capture, Engine, FrameSettings, FrameTimings, WindowOptions};
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::keyboard::{Key, ModifiersState, NamedKey};

/// What the keys do, printed at start.
const KEYS: &str = "Tab: next technique, [ ]: light radius, - +: the technique's first knob, \
                    S: screenshot, R: error against the reference, Esc: quit";

/// Frames the title's per-pass medians are taken over.
const MEDIAN_FRAMES: usize = 60;

#[derive(clap::Args)]
pub struct ViewArgs {
    /// The scene file (TOML).
    scene: PathBuf,
    /// Technique to start with; overrides the scene's `[render] technique`.
    #[arg(long)]
    technique: Option<String>,
    /// A knob of the starting technique, KEY=VALUE; repeatable.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<String>,
    /// Present this many frames, then exit (for scripts).
    #[arg(long)]
    frames: Option<u64>,
    /// With --frames: write the last presented image here (PNG).
    #[arg(long, requires = "frames")]
    screenshot: Option<PathBuf>,
}

/// The camera as an orbit around its target.
struct Orbit {
    target: Vec3,
    distance: f32,
    yaw: f32,
    pitch: f32,
}

impl Orbit {
    fn position(&self) -> Vec3 {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        self.target + self.distance * Vec3::new(cp * sy, sp, cp * cy)
    }
}

pub fn view(args: &ViewArgs) -> Result<()> {
    let (mut scene, settings) = super::load(&super::SceneArgs {
        scene: args.scene.clone(),
        technique: args.technique.clone(),
        set: args.set.clone(),
        width: None,
        height: None,
        frames: None,
    })?;
    let mut app = AppWindow::open("softshadow view", settings.width, settings.height)?;
    let mut engine = Engine::windowed(&ContextOptions::from_env(), app.window().clone(), WindowOptions::default())?;
    let techniques: Vec<_> = TECHNIQUES.iter().copied().filter(|t| t.kind == Kind::Realtime).collect();
    let mut params = settings.params;
    let offset = scene.camera.position - scene.camera.target;
    let mut orbit = Orbit {
        target: scene.camera.target,
        distance: offset.length(),
        yaw: offset.x.atan2(offset.z),
        pitch: (offset.y / offset.length()).asin(),
    };
    if args.frames.is_none() {
        println!("{KEYS}");
    }
    let (mut cursor, mut buttons, mut modifiers) = (None::<(f64, f64)>, [false; 2], ModifiersState::empty());
    let mut recent: VecDeque<FrameTimings> = VecDeque::new();
    let mut frame = 0u64;
    let mut shots = 0;
    'view: loop {
        let (mut screenshot, mut compare) = (false, false);
        for event in app.poll() {
            match event {
                WindowEvent::CloseRequested => break 'view,
                WindowEvent::ModifiersChanged(m) => modifiers = m.state(),
                WindowEvent::MouseInput { state, button, .. } => {
                    let down = state == ElementState::Pressed;
                    match button {
                        MouseButton::Left => buttons[0] = down,
                        MouseButton::Right => buttons[1] = down,
                        _ => {}
                    }
                }
                WindowEvent::CursorMoved { position, .. } => {
                    if let Some((x, y)) = cursor {
                        let (dx, dy) = ((position.x - x) as f32, (position.y - y) as f32);
                        let (forward, right) = frame_axes(&orbit);
                        let metres = orbit.distance * 0.002;
                        if buttons[0] && modifiers.control_key() {
                            let ground = |v: Vec3| Vec3::new(v.x, 0.0, v.z).normalize_or_zero();
                            scene.light.position += (ground(right) * dx - ground(forward) * dy) * metres;
                        } else if buttons[0] {
                            orbit.yaw -= dx * 0.01;
                            orbit.pitch = (orbit.pitch + dy * 0.01).clamp(-1.5, 1.5);
                        } else if buttons[1] {
                            let up = right.cross(forward);
                            orbit.target += (up * dy - right * dx) * metres;
                        }
                    }
                    cursor = Some((position.x, position.y));
                }
                WindowEvent::MouseWheel { delta, .. } => {
                    let lines = match delta {
                        MouseScrollDelta::LineDelta(_, y) => y,
                        MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
                    };
                    orbit.distance = (orbit.distance * 0.9f32.powf(lines)).max(0.01);
                }
                WindowEvent::KeyboardInput { event, .. } if event.state == ElementState::Pressed => {
                    match event.logical_key.as_ref() {
                        Key::Named(NamedKey::Escape) => break 'view,
                        Key::Named(NamedKey::Tab) => {
                            let i =
                                techniques.iter().position(|t| t.name == params.technique.name).map_or(0, |i| i + 1);
                            params = Params::defaults(techniques[i % techniques.len()]);
                        }
                        Key::Character("[") => scene.light.radius /= 1.25,
                        Key::Character("]") => scene.light.radius = (scene.light.radius * 1.25).max(0.01),
                        Key::Character("-") => step_first_knob(&mut params, 0.5),
                        Key::Character("+" | "=") => step_first_knob(&mut params, 2.0),
                        Key::Character("s" | "S") => screenshot = true,
                        Key::Character("r" | "R") => compare = true,
                        _ => {}
                    }
                }
                _ => {}
            }
        }
        scene.camera.position = orbit.position();
        scene.camera.target = orbit.target;

        frame += 1;
        let last = args.frames.is_some_and(|n| frame >= n);
        if screenshot || (last && args.screenshot.is_some()) {
            let Some(capture) = engine.present_and_capture(&scene, &params)? else { continue };
            let report = report(&engine, &params, &capture, recent.make_contiguous());
            match (&args.screenshot, last) {
                (Some(path), true) => capture.save_color(path)?,
                _ => {
                    shots += 1;
                    save_screenshot(&capture, &report, &format!("softshadow-view-{shots}"))?;
                }
            }
        } else {
            engine.present(&scene, &params)?;
        }
        if compare {
            compare_with_reference(&mut engine, &scene, &params)?;
        }
        for t in engine.take_timings() {
            if recent.len() == MEDIAN_FRAMES {
                recent.pop_front();
            }
            recent.push_back(t);
        }
        if frame % 15 == 1 {
            app.window().set_title(&title(&engine, &params, recent.make_contiguous()));
        }
        if last {
            break;
        }
    }
    super::finish(engine)
}

/// The camera's forward and right directions.
fn frame_axes(orbit: &Orbit) -> (Vec3, Vec3) {
    let forward = (orbit.target - orbit.position()).normalize();
    (forward, forward.cross(Vec3::Y).normalize_or_zero())
}

/// Halves or doubles the technique's first knob, within its range.
fn step_first_knob(params: &mut Params, factor: f64) {
    let Some(knob) = params.technique.knobs.first() else { return };
    let mut v = (params.get(knob) * factor).clamp(knob.min, knob.max);
    if knob.integer {
        v = v.round();
    }
    // In range by construction; a refusal would leave the knob as it was.
    let _ = params.set(knob.name, &v.to_string());
}

fn report(engine: &Engine, params: &Params, capture: &Capture, frames: &[FrameTimings]) -> TimingReport {
    TimingReport::new(engine.device(), params.technique.name, capture.width, capture.height, frames)
}

/// Technique, its first knob, and the median GPU ms of each pass over the recent frames.
fn title(engine: &Engine, params: &Params, frames: &[FrameTimings]) -> String {
    let stats = engine.window_stats();
    let (w, h) = stats.map_or((0, 0), |s| (s.width, s.height));
    let r = TimingReport::new(engine.device(), params.technique.name, w, h, frames);
    let knob = params.technique.knobs.first().map_or(String::new(), |k| format!(" {}={}", k.name, params.get(k)));
    let passes: Vec<String> = r.passes.iter().map(|p| format!("{} {:.2}", p.name, p.gpu_ms_median)).collect();
    format!("{}{knob}: {:.2} GPU ms ({}) {w}x{h}", params.technique.name, r.gpu_ms_total_median, passes.join(", "))
}

/// Color, 16-bit V and timings JSON, named after `stem`.
fn save_screenshot(capture: &Capture, report: &TimingReport, stem: &str) -> Result<()> {
    let color = PathBuf::from(format!("{stem}.png"));
    capture.save_color(&color)?;
    capture.save_visibility(Path::new(&format!("{stem}-visibility.png")))?;
    super::write_json(report, Path::new(&format!("{stem}-timings.json")))?;
    println!("wrote {} and its V and timings", color.display());
    Ok(())
}

/// Renders the technique and the GPU reference for the current view offscreen, and prints the
/// technique's error.
fn compare_with_reference(engine: &mut Engine, scene: &softshadow::scene::Scene, params: &Params) -> Result<()> {
    let stats = engine.window_stats().context("a windowed engine")?;
    let (width, height) = (stats.width, stats.height);
    let ours = engine.render_and_capture(scene, &FrameSettings { width, height, params: params.clone() })?;
    let truth = Params::defaults(ground_truth(Runs::Gpu));
    let truth = engine.render_and_capture(scene, &FrameSettings { width, height, params: truth })?;
    let m = Metrics::between(&ours, &truth)?;
    println!(
        "{} against the reference at {width}x{height}: RMSE {:.4}, penumbra RMSE {:.4}, max {:.3}",
        params.technique.name, m.rmse, m.penumbra_rmse, m.max_abs
    );
    Ok(())
}
