//! `softshadow view SCENE`: the interactive viewer, on the same windowed engine a game uses.
//! Left drag orbits, right drag pans, the wheel zooms, Ctrl + left drag moves the light; keys
//! are listed in [`KEYS`].

use std::collections::VecDeque;
use std::path::{Path, PathBuf};

use anyhow::{Context as _, Result};
use glam::Vec3;
use softshadow::gpu::ContextOptions;
use softshadow::measure::{FileTrace, Metrics, TimingReport};
use softshadow::scene::Scene;
use softshadow::technique::registry::ground_truth;
use softshadow::technique::{Kind, Params, Runs, TECHNIQUES, TechniqueInfo};
use softshadow::{AppWindow, Capture, Engine, FrameSettings, FrameTimings, WindowOptions};
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::keyboard::{Key, ModifiersState, NamedKey};

/// What the keys do, printed at start.
const KEYS: &str = "Tab: next technique, [ ]: light radius, - +: the technique's first knob, \
                    S: screenshot (colour, V, timings, trace), R: error against the reference, Esc: quit";

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

/// One input the viewer acts on, decoded from the window's events.
#[derive(Clone, Debug, PartialEq)]
enum Input {
    Close,
    Modifiers(ModifiersState),
    /// Left (`true`) or right mouse button, pressed or released.
    Button {
        left: bool,
        down: bool,
    },
    Cursor(f64, f64),
    /// Wheel lines toward the scene.
    Wheel(f32),
    Key(Key),
}

fn decode(event: WindowEvent) -> Option<Input> {
    Some(match event {
        WindowEvent::CloseRequested => Input::Close,
        WindowEvent::ModifiersChanged(m) => Input::Modifiers(m.state()),
        WindowEvent::MouseInput { state, button, .. } => {
            let left = match button {
                MouseButton::Left => true,
                MouseButton::Right => false,
                _ => return None,
            };
            Input::Button { left, down: state == ElementState::Pressed }
        }
        WindowEvent::CursorMoved { position, .. } => Input::Cursor(position.x, position.y),
        WindowEvent::MouseWheel { delta, .. } => Input::Wheel(match delta {
            MouseScrollDelta::LineDelta(_, y) => y,
            MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
        }),
        WindowEvent::KeyboardInput { event, .. } if event.state == ElementState::Pressed => {
            Input::Key(event.logical_key)
        }
        _ => return None,
    })
}

/// What the inputs of a frame asked for beyond moving the camera, the light and the knobs.
#[derive(Debug, Default, PartialEq)]
struct Requests {
    quit: bool,
    screenshot: bool,
    compare: bool,
}

/// The viewer's state between inputs: the orbit, the cursor, the buttons and modifiers held.
struct Controls {
    orbit: Orbit,
    cursor: Option<(f64, f64)>,
    /// Left, right.
    buttons: [bool; 2],
    modifiers: ModifiersState,
}

impl Controls {
    /// Orbiting the scene camera's target from where the camera stands.
    fn new(scene: &Scene) -> Self {
        let offset = scene.camera.position - scene.camera.target;
        let orbit = Orbit {
            target: scene.camera.target,
            distance: offset.length(),
            yaw: offset.x.atan2(offset.z),
            pitch: (offset.y / offset.length()).asin(),
        };
        Controls { orbit, cursor: None, buttons: [false; 2], modifiers: ModifiersState::empty() }
    }

    /// Left drag orbits, right drag pans, the wheel zooms, Ctrl + left drag moves the light over
    /// the ground; keys as [`KEYS`] says.
    fn handle(
        &mut self,
        input: Input,
        scene: &mut Scene,
        params: &mut Params,
        techniques: &[&'static TechniqueInfo],
        asked: &mut Requests,
    ) {
        let orbit = &mut self.orbit;
        match input {
            Input::Close => asked.quit = true,
            Input::Modifiers(m) => self.modifiers = m,
            Input::Button { left, down } => self.buttons[usize::from(!left)] = down,
            Input::Cursor(x, y) => {
                if let Some((x0, y0)) = self.cursor {
                    let (dx, dy) = ((x - x0) as f32, (y - y0) as f32);
                    let (forward, right) = frame_axes(orbit);
                    let metres = orbit.distance * 0.002;
                    if self.buttons[0] && self.modifiers.control_key() {
                        let ground = |v: Vec3| Vec3::new(v.x, 0.0, v.z).normalize_or_zero();
                        scene.light.position += (ground(right) * dx - ground(forward) * dy) * metres;
                    } else if self.buttons[0] {
                        orbit.yaw -= dx * 0.01;
                        orbit.pitch = (orbit.pitch + dy * 0.01).clamp(-1.5, 1.5);
                    } else if self.buttons[1] {
                        let up = right.cross(forward);
                        orbit.target += (up * dy - right * dx) * metres;
                    }
                }
                self.cursor = Some((x, y));
            }
            Input::Wheel(lines) => orbit.distance = (orbit.distance * 0.9f32.powf(lines)).max(0.01),
            Input::Key(key) => match key.as_ref() {
                Key::Named(NamedKey::Escape) => asked.quit = true,
                Key::Named(NamedKey::Tab) => {
                    let i = techniques.iter().position(|t| t.name == params.technique.name).map_or(0, |i| i + 1);
                    *params = Params::defaults(techniques[i % techniques.len()]);
                }
                Key::Character("[") => scene.light.radius /= 1.25,
                Key::Character("]") => scene.light.radius = (scene.light.radius * 1.25).max(0.01),
                Key::Character("-") => step_first_knob(params, 0.5),
                Key::Character("+" | "=") => step_first_knob(params, 2.0),
                Key::Character("s" | "S") => asked.screenshot = true,
                Key::Character("r" | "R") => asked.compare = true,
                _ => {}
            },
        }
    }

    fn place_camera(&self, scene: &mut Scene) {
        scene.camera.position = self.orbit.position();
        scene.camera.target = self.orbit.target;
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
    let mut controls = Controls::new(&scene);
    if args.frames.is_none() {
        out!("{KEYS}");
    }
    let mut recent: VecDeque<FrameTimings> = VecDeque::new();
    let mut frame = 0u64;
    let mut shots = 0;
    'view: loop {
        let mut asked = Requests::default();
        for input in app.poll().into_iter().filter_map(decode) {
            controls.handle(input, &mut scene, &mut params, &techniques, &mut asked);
        }
        if asked.quit {
            break 'view;
        }
        let (screenshot, compare) = (asked.screenshot, asked.compare);
        controls.place_camera(&mut scene);

        frame += 1;
        let last = args.frames.is_some_and(|n| frame >= n);
        if screenshot || (last && args.screenshot.is_some()) {
            let Some(capture) = engine.present_and_capture(&scene, &params)? else { continue };
            let report = report(&engine, &params, &capture, recent.make_contiguous());
            match (&args.screenshot, last) {
                (Some(path), true) => capture.save_color(path)?,
                _ => {
                    shots += 1;
                    save_screenshot(&capture, &report, recent.make_contiguous(), &format!("softshadow-view-{shots}"))?;
                }
            }
        } else {
            engine.present(&scene, &params)?;
        }
        if compare {
            let stats = engine.window_stats().context("a windowed engine")?;
            let (width, height) = (stats.width, stats.height);
            let m = compare_with_reference(&mut engine, &scene, &params, width, height)?;
            out!(
                "{} against the reference at {width}x{height}: RMSE {:.4}, penumbra RMSE {:.4}, max {:.3}",
                params.technique.name,
                m.rmse,
                m.penumbra_rmse,
                m.max_abs
            );
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
    let knob =
        params.technique.knobs.first().map_or(String::new(), |k| format!(" {}={}", k.name, k.show(params.get(k))));
    let passes: Vec<String> = r.passes.iter().map(|p| format!("{} {:.2}", p.name, p.gpu_ms_median)).collect();
    format!("{}{knob}: {:.2} GPU ms ({}) {w}x{h}", params.technique.name, r.gpu_ms_total_median, passes.join(", "))
}

/// Color, 16-bit V, timings JSON and a Chrome trace of the recent `frames` (the ones `report`
/// summarises), named after `stem`.
fn save_screenshot(capture: &Capture, report: &TimingReport, frames: &[FrameTimings], stem: &str) -> Result<()> {
    let color = PathBuf::from(format!("{stem}.png"));
    capture.save_color(&color)?;
    capture.save_visibility(Path::new(&format!("{stem}-visibility.png")))?;
    super::write_json(report, Path::new(&format!("{stem}-timings.json")))?;
    let mut trace = FileTrace::create(&report.device, Path::new(&format!("{stem}-trace.json")))?;
    trace.add_frames(frames, &serde_json::json!({ "technique": report.technique }));
    trace.finish()?;
    out!("wrote {} and its V, timings and trace", color.display());
    Ok(())
}

/// Renders the technique and the GPU reference for the current view offscreen at the window's
/// size, and returns the technique's error against the reference.
fn compare_with_reference(
    engine: &mut Engine,
    scene: &Scene,
    params: &Params,
    width: u32,
    height: u32,
) -> Result<Metrics> {
    let ours = engine.render_and_capture(scene, &FrameSettings { width, height, params: params.clone() })?;
    let truth = Params::defaults(ground_truth(Runs::Gpu));
    let truth = engine.render_and_capture(scene, &FrameSettings { width, height, params: truth })?;
    Ok(Metrics::between(&ours, &truth)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use softshadow::technique::find;

    fn setup() -> (Controls, Scene, Params, Vec<&'static TechniqueInfo>) {
        let scene = Scene::load(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/default.toml")).unwrap();
        let techniques = TECHNIQUES.iter().copied().filter(|t| t.kind == Kind::Realtime).collect();
        (Controls::new(&scene), scene, Params::defaults(find("pcss").unwrap()), techniques)
    }

    /// Feeds `inputs`, places the camera, returns what they asked for.
    fn feed(
        c: &mut Controls,
        scene: &mut Scene,
        params: &mut Params,
        t: &[&'static TechniqueInfo],
        inputs: &[Input],
    ) -> Requests {
        let mut asked = Requests::default();
        for input in inputs {
            c.handle(input.clone(), scene, params, t, &mut asked);
        }
        c.place_camera(scene);
        asked
    }

    fn drag(left: bool, from: (f64, f64), to: (f64, f64)) -> Vec<Input> {
        vec![
            Input::Cursor(from.0, from.1),
            Input::Button { left, down: true },
            Input::Cursor(to.0, to.1),
            Input::Button { left, down: false },
        ]
    }

    #[test]
    fn the_controls_start_at_the_scenes_camera() {
        let (mut c, mut scene, mut params, t) = setup();
        let before = scene.camera.clone();
        feed(&mut c, &mut scene, &mut params, &t, &[]);
        assert!(
            (scene.camera.position - before.position).length() < 1e-4,
            "{} {}",
            scene.camera.position,
            before.position
        );
        assert_eq!(scene.camera.target, before.target);
    }

    /// Left drag orbits: the camera moves around the target at the same distance, the light
    /// stays; moving the cursor with no button held does nothing.
    #[test]
    fn left_drag_orbits_around_the_target() {
        let (mut c, mut scene, mut params, t) = setup();
        let (start, light) = (scene.camera.position, scene.light.position);
        feed(&mut c, &mut scene, &mut params, &t, &[Input::Cursor(10.0, 10.0), Input::Cursor(300.0, 40.0)]);
        assert!((scene.camera.position - start).length() < 1e-4, "moved without a button");
        feed(&mut c, &mut scene, &mut params, &t, &drag(true, (10.0, 10.0), (110.0, 10.0)));
        let (d0, d1) = ((start - scene.camera.target).length(), (scene.camera.position - scene.camera.target).length());
        assert!((scene.camera.position - start).length() > 0.1, "the camera did not orbit");
        assert!((d0 - d1).abs() < 1e-3 * d0, "distance {d0} became {d1}");
        assert!((scene.camera.position.y - start.y).abs() < 1e-3, "a horizontal drag changed the height");
        assert_eq!(scene.light.position, light);
    }

    /// Right drag pans: target and camera move by the same vector, across the view.
    #[test]
    fn right_drag_pans_the_view() {
        let (mut c, mut scene, mut params, t) = setup();
        let (position, target) = (scene.camera.position, scene.camera.target);
        feed(&mut c, &mut scene, &mut params, &t, &drag(false, (50.0, 50.0), (0.0, 50.0)));
        let moved = scene.camera.target - target;
        assert!(moved.length() > 0.01, "the target did not move");
        assert!((scene.camera.position - position - moved).length() < 1e-4, "camera and target moved apart");
        assert!(
            moved.dot(target - position).abs() < 1e-4 * moved.length() * (target - position).length(),
            "not across"
        );
    }

    /// The wheel zooms: toward the target by 0.9 per line, the direction kept.
    #[test]
    fn the_wheel_zooms_toward_the_target() {
        let (mut c, mut scene, mut params, t) = setup();
        let before = scene.camera.position - scene.camera.target;
        feed(&mut c, &mut scene, &mut params, &t, &[Input::Wheel(2.0)]);
        let after = scene.camera.position - scene.camera.target;
        assert!((after.length() / before.length() - 0.81).abs() < 1e-4, "{} → {}", before.length(), after.length());
        assert!(after.normalize().dot(before.normalize()) > 0.9999);
    }

    /// Ctrl + left drag moves the light over the ground (its height kept), not the camera.
    #[test]
    fn ctrl_drag_moves_the_light_over_the_ground() {
        let (mut c, mut scene, mut params, t) = setup();
        let (light, camera) = (scene.light.position, scene.camera.position);
        let mut inputs = vec![Input::Modifiers(ModifiersState::CONTROL)];
        inputs.extend(drag(true, (0.0, 0.0), (80.0, -40.0)));
        feed(&mut c, &mut scene, &mut params, &t, &inputs);
        assert!((scene.light.position - light).length() > 0.05, "the light did not move");
        assert_eq!(scene.light.position.y, light.y);
        assert!((scene.camera.position - camera).length() < 1e-4, "the camera moved");
    }

    /// Tab cycles the real-time techniques (and wraps); [ ] change the light's radius; - +
    /// halve and double the first knob within its range; S, R and Esc ask for a screenshot, the
    /// reference comparison and quitting.
    #[test]
    fn keys_switch_techniques_and_knobs_and_ask_for_shots() {
        let (mut c, mut scene, mut params, t) = setup();
        let key = |k: &str| Input::Key(Key::Character(k.into()));
        let at = t.iter().position(|x| x.name == "pcss").unwrap();
        feed(&mut c, &mut scene, &mut params, &t, &[Input::Key(Key::Named(NamedKey::Tab))]);
        assert_eq!(params.technique.name, t[(at + 1) % t.len()].name);
        let tabs = vec![Input::Key(Key::Named(NamedKey::Tab)); t.len()];
        feed(&mut c, &mut scene, &mut params, &t, &tabs);
        assert_eq!(params.technique.name, t[(at + 1) % t.len()].name, "a full cycle comes back");

        let radius = scene.light.radius;
        feed(&mut c, &mut scene, &mut params, &t, &[key("]")]);
        assert!((scene.light.radius - radius * 1.25).abs() < 1e-6);
        feed(&mut c, &mut scene, &mut params, &t, &[key("["), key("[")]);
        assert!((scene.light.radius - radius / 1.25).abs() < 1e-6);

        params = Params::defaults(find("pcss").unwrap());
        let info = params.technique;
        let knob = &info.knobs[0];
        let halved = (params.get(knob) * 0.5).clamp(knob.min, knob.max);
        feed(&mut c, &mut scene, &mut params, &t, &[key("-")]);
        assert_eq!(params.get(knob), if knob.integer { halved.round() } else { halved });
        for _ in 0..64 {
            feed(&mut c, &mut scene, &mut params, &t, &[key("+")]);
        }
        assert_eq!(params.get(knob), knob.max, "doubling stops at the knob's maximum");

        assert_eq!(
            feed(&mut c, &mut scene, &mut params, &t, &[key("s")]),
            Requests { screenshot: true, ..Default::default() }
        );
        assert_eq!(
            feed(&mut c, &mut scene, &mut params, &t, &[key("R")]),
            Requests { compare: true, ..Default::default() }
        );
        let quit = feed(&mut c, &mut scene, &mut params, &t, &[Input::Key(Key::Named(NamedKey::Escape))]);
        assert!(quit.quit);
        assert!(feed(&mut c, &mut scene, &mut params, &t, &[Input::Close]).quit);
    }

    fn validated_engine() -> Engine {
        Engine::headless(&ContextOptions { validation: true, device: None }).expect("a Vulkan device (lavapipe)")
    }

    fn no_validation_errors(engine: Engine) {
        let errors = engine.finish();
        assert!(errors.is_empty(), "validation: {errors:?}");
    }

    /// What S writes (the key's request is checked above), for a frame of the default scene:
    /// the colour PNG, V as a 16-bit grey PNG equal to the frame's V, the timings JSON naming
    /// the technique and the frame's size, and a Chrome trace of the frame's passes.
    #[test]
    fn the_screenshot_writes_color_visibility_and_timings() {
        let (_, scene, params, _) = setup();
        let mut engine = validated_engine();
        let settings = FrameSettings { width: 64, height: 48, params };
        let capture = engine.render_and_capture(&scene, &settings).unwrap();
        engine.flush().unwrap();
        let timings = engine.take_timings();
        let dir = std::env::temp_dir().join(format!("softshadow-view-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let stem = dir.join("shot");
        let stem = stem.to_str().unwrap();
        save_screenshot(&capture, &report(&engine, &settings.params, &capture, &timings), &timings, stem).unwrap();

        let color = image::open(format!("{stem}.png")).unwrap();
        assert_eq!((color.width(), color.height()), (64, 48));
        assert_eq!(color.to_rgba8().into_raw(), capture.color, "the colour PNG is the frame");
        let v = image::open(format!("{stem}-visibility.png")).unwrap();
        let v = v.as_luma16().expect("V is 16-bit grey");
        assert_eq!(v.as_raw(), &capture.visibility, "the V PNG is the frame's V");
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(format!("{stem}-timings.json")).unwrap()).unwrap();
        assert_eq!(json["technique"], "pcss", "{json}");
        assert_eq!((json["width"].as_u64(), json["height"].as_u64()), (Some(64), Some(48)), "{json}");
        // The trace holds the frame's GPU passes, each named and timed, on the GPU track.
        let trace: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(format!("{stem}-trace.json")).unwrap()).unwrap();
        let gpu: Vec<&str> = trace["traceEvents"]
            .as_array()
            .expect("Chrome trace events")
            .iter()
            .filter(|e| e["cat"] == "gpu")
            .filter_map(|e| e["name"].as_str())
            .collect();
        let passes: Vec<&str> = timings.iter().flat_map(|t| t.passes.iter().map(|p| p.name)).collect();
        assert!(!passes.is_empty() && gpu == passes, "trace {gpu:?}, frames {passes:?}");
        std::fs::remove_dir_all(&dir).unwrap();
        no_validation_errors(engine);
    }

    /// What R computes: the reference against itself has no error; a hard shadow map, which has
    /// no penumbra, has some, in the penumbrae above all.
    #[test]
    fn the_comparison_measures_the_error_against_the_reference() {
        let (_, scene, _, _) = setup();
        let mut engine = validated_engine();
        let truth = Params::defaults(ground_truth(Runs::Gpu));
        let m = compare_with_reference(&mut engine, &scene, &truth, 64, 64).unwrap();
        assert_eq!((m.rmse, m.penumbra_rmse, m.max_abs), (0.0, 0.0, 0.0), "the reference against itself");
        let hard = Params::defaults(find("shadow-map").unwrap());
        let m = compare_with_reference(&mut engine, &scene, &hard, 64, 64).unwrap();
        assert!(m.rmse > 0.0 && m.penumbra_rmse > m.rmse, "a hard shadow: {m:?}");
        no_validation_errors(engine);
    }
}
