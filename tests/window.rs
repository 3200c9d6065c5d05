//! The engine with a window, under a real X server (an Xvfb started here when no display is
//! set), on lavapipe with validation and synchronization validation: presenting, resizing,
//! reading back presented images, present modes and frame pacing. One winit event loop per
//! process, on the main thread: so this binary has its own `main` (harness = false) and runs
//! its checks in turn on one window.

mod common;

use std::time::{Duration, Instant};

use ash::vk;
use softshadow::gpu::{ContextOptions, FRAMES_IN_FLIGHT, PresentMode};
use softshadow::scene::Scene;
use softshadow::technique::Params;
use softshadow::{AppWindow, Engine, FrameSettings, Presented, WindowOptions};
use winit::dpi::PhysicalSize;

const W: u32 = 96;
const H: u32 = 64;

/// A check on the shared window.
type Check = fn(&mut AppWindow);

fn main() {
    let filter = std::env::args().skip(1).find(|a| !a.starts_with('-'));
    let xvfb = common::xvfb::ensure_display();
    without_a_display_opening_a_window_names_the_variables();
    let mut app = AppWindow::open("softshadow window tests", W, H).expect("a window on the X server");
    let checks: [(&str, Check); 7] = [
        ("a_moving_caster_is_presented_through_two_resizes", a_moving_caster_is_presented_through_two_resizes),
        ("a_presented_image_equals_the_headless_capture", a_presented_image_equals_the_headless_capture),
        ("the_present_mode_asked_for_is_taken", the_present_mode_asked_for_is_taken),
        ("fifo_keeps_the_cpu_within_the_frames_in_flight", fifo_keeps_the_cpu_within_the_frames_in_flight),
        ("softshadow_view_presents_and_writes_a_screenshot", softshadow_view_presents_and_writes_a_screenshot),
        (
            "a_c_program_presents_into_its_own_xlib_and_xcb_windows",
            a_c_program_presents_into_its_own_xlib_and_xcb_windows,
        ),
        // Last: it brings a window manager, which then manages the window.
        ("minimising_under_a_window_manager_never_errors", minimising_under_a_window_manager_never_errors),
    ];
    // A failed check must still stop the Xvfb: catch the panic, drop everything, then fail.
    let passed = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        for (name, check) in checks {
            if filter.as_ref().is_some_and(|f| !name.contains(f.as_str())) {
                continue;
            }
            let start = Instant::now();
            check(&mut app);
            println!("test {name} ... ok ({:.1} s)", start.elapsed().as_secs_f64());
        }
    }))
    .is_ok();
    drop(app);
    drop(xvfb);
    if !passed {
        std::process::exit(1);
    }
}

fn windowed(app: &AppWindow, request: WindowOptions) -> Engine {
    let options = ContextOptions { validation: true, device: None };
    Engine::windowed(&options, app.window().clone(), request).expect("a windowed engine on lavapipe")
}

/// A box over the ground, seen from above, at `x`.
fn scene(x: f32) -> Scene {
    let caster = format!(
        "[[object]]\nshape = \"box\"\nsize = [0.8, 0.4, 0.8]\nposition = [{x}, 0.6, 0.0]\nrotation_deg = [0.0, 20.0, 0.0]\n"
    );
    common::top_down(0.0, 2.0, [0.5, 6.0, 0.3], 0.3, &caster)
}

fn params(scene: &Scene) -> Params {
    FrameSettings::from_scene(scene).expect("valid settings").params
}

/// Resizes the window and polls until the X server has done it.
fn resize(app: &mut AppWindow, w: u32, h: u32) {
    let _ = app.window().request_inner_size(PhysicalSize::new(w, h));
    let start = Instant::now();
    while app.window().inner_size() != PhysicalSize::new(w, h) {
        app.poll();
        assert!(start.elapsed() < Duration::from_secs(5), "the window never became {w}x{h}");
        std::thread::sleep(Duration::from_millis(5));
    }
    app.poll();
}

fn without_a_display_opening_a_window_names_the_variables() {
    let display = std::env::var_os("DISPLAY");
    // SAFETY: no other thread runs yet.
    unsafe { std::env::remove_var("DISPLAY") };
    let error = AppWindow::open("no display", W, H).err().expect("no display, no window").to_string();
    unsafe { std::env::set_var("DISPLAY", display.expect("ensure_display set it")) };
    assert!(error.contains("DISPLAY") && error.contains("WAYLAND_DISPLAY"), "{error}");
}

/// 100 frames with the caster moving (its shadow must follow), then the window shrunk to 1×1
/// and grown back: each resize re-creates the swapchain once, frames keep being presented at
/// the new size, and nothing trips validation.
fn a_moving_caster_is_presented_through_two_resizes(app: &mut AppWindow) {
    let mut engine = windowed(app, WindowOptions::default());
    let params = params(&scene(0.0));
    let mut centroids = Vec::new();
    for frame in 0..100 {
        app.poll();
        let x = -1.0 + 2.0 * frame as f32 / 99.0;
        let s = scene(x);
        if frame % 33 == 0 {
            let c = engine.present_and_capture(&s, &params).unwrap().expect("a window with an area");
            centroids.push(common::shadow_centroid(&c).expect("a shadow in view").0);
        } else {
            assert_eq!(engine.present(&s, &params).unwrap(), Presented::Shown);
        }
    }
    assert!(centroids.windows(2).all(|p| p[1] > p[0] + 5.0), "the shadow follows the caster: {centroids:?}");
    let stats = engine.window_stats().unwrap().clone();
    assert_eq!((stats.width, stats.height, stats.recreations), (W, H, 0), "{stats:?}");

    for (size, recreations) in [((1, 1), 1), ((W, H), 2)] {
        resize(app, size.0, size.1);
        for _ in 0..3 {
            assert_eq!(engine.present(&scene(0.0), &params).unwrap(), Presented::Shown);
        }
        let stats = engine.window_stats().unwrap();
        assert_eq!((stats.width, stats.height), size, "{stats:?}");
        assert_eq!(stats.recreations, recreations, "one re-creation per resize: {stats:?}");
    }
    let c = engine.present_and_capture(&scene(0.0), &params).unwrap().expect("presented");
    assert_eq!((c.width, c.height), (W, H));
    println!("  re-creating the swapchain took {:.2} ms", engine.window_stats().unwrap().last_recreation_ms);
    common::finish(engine);
}

/// The presented image, read back from the swapchain, is the headless capture of the same
/// scene and camera within 1 LSB per channel: with the hardware encoding sRGB (the default
/// format), and with the composite encoding it for a linear format.
fn a_presented_image_equals_the_headless_capture(app: &mut AppWindow) {
    let s = scene(0.3);
    let params = params(&s);
    let mut headless = common::engine();
    let truth =
        headless.render_and_capture(&s, &FrameSettings { width: W, height: H, params: params.clone() }).unwrap();
    common::finish(headless);
    let lit = truth.visibility.iter().filter(|&&v| v == u16::MAX).count();
    assert!(lit > 0 && lit < truth.visibility.len(), "a scene with a shadow in view");
    for (format, encoded_by) in [(None, "the hardware"), (Some(vk::Format::B8G8R8A8_UNORM), "the composite")] {
        let mut engine = windowed(app, WindowOptions { format, ..Default::default() });
        app.poll();
        let presented = engine.present_and_capture(&s, &params).unwrap().expect("presented");
        let stats = engine.window_stats().unwrap().clone();
        common::finish(engine);
        if let Some(f) = format {
            assert_eq!(stats.format, f, "lavapipe's X11 surface offers {f:?}");
        } else {
            assert_eq!(stats.format, vk::Format::B8G8R8A8_SRGB);
        }
        assert_eq!(presented.visibility, truth.visibility, "the same frame code writes the same V");
        let worst = presented.color.iter().zip(&truth.color).map(|(a, b)| a.abs_diff(*b)).max().unwrap();
        assert!(worst <= 1, "{stats:?}, sRGB encoded by {encoded_by}: off by {worst} LSB");
    }
}

/// FIFO by default; IMMEDIATE and MAILBOX when asked for (lavapipe's X11 surface offers both).
fn the_present_mode_asked_for_is_taken(app: &mut AppWindow) {
    let s = scene(0.0);
    let params = params(&s);
    for (mode, expected) in [
        (PresentMode::Fifo, vk::PresentModeKHR::FIFO),
        (PresentMode::Immediate, vk::PresentModeKHR::IMMEDIATE),
        (PresentMode::Mailbox, vk::PresentModeKHR::MAILBOX),
    ] {
        let mut engine = windowed(app, WindowOptions { present_mode: mode, ..Default::default() });
        for _ in 0..10 {
            app.poll();
            assert_eq!(engine.present(&s, &params).unwrap(), Presented::Shown);
        }
        assert_eq!(engine.window_stats().unwrap().present_mode, expected);
        common::finish(engine);
    }
}

/// Under FIFO the CPU never has more than FRAMES_IN_FLIGHT frames submitted and unfinished:
/// after each present, every frame but the last FRAMES_IN_FLIGHT has come back with its GPU
/// times. And it does run that far ahead (the GPU is not drained every frame).
fn fifo_keeps_the_cpu_within_the_frames_in_flight(app: &mut AppWindow) {
    let mut engine = windowed(app, WindowOptions::default());
    let params = params(&scene(0.0));
    let (mut presented, mut finished, mut most_ahead) = (0usize, 0usize, 0usize);
    for frame in 0..40 {
        app.poll();
        assert_eq!(engine.present(&scene(frame as f32 * 0.02), &params).unwrap(), Presented::Shown);
        presented += 1;
        finished += engine.take_timings().len();
        let ahead = presented - finished;
        assert!(ahead <= FRAMES_IN_FLIGHT, "frame {frame}: {ahead} frames unfinished");
        most_ahead = most_ahead.max(ahead);
    }
    assert_eq!(most_ahead, FRAMES_IN_FLIGHT, "the CPU records while the GPU renders");
    common::finish(engine);
}

/// `softshadow view SCENE --frames N --screenshot FILE` presents N frames, writes the last one
/// at the scene's size and exits 0; without a display it says which variables it looked at.
fn softshadow_view_presents_and_writes_a_screenshot(_: &mut AppWindow) {
    let scene = format!("{}/scenes/plate.toml", env!("CARGO_MANIFEST_DIR"));
    let shot = std::env::temp_dir().join(format!("softshadow-view-{}.png", std::process::id()));
    let run = |display: bool| {
        let mut cmd = std::process::Command::new(env!("CARGO_BIN_EXE_softshadow"));
        cmd.args(["view", &scene, "--frames", "5", "--screenshot"]).arg(&shot).env("SOFTSHADOW_VALIDATION", "1");
        if !display {
            cmd.env_remove("DISPLAY").env_remove("WAYLAND_DISPLAY");
        }
        cmd.output().expect("softshadow runs")
    };
    let out = run(true);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let image = image::open(&shot).expect("a PNG screenshot");
    let s = Scene::load(&scene).unwrap();
    assert_eq!((image.width(), image.height()), (s.render.width, s.render.height));
    std::fs::remove_file(&shot).unwrap();
    let out = run(false);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("DISPLAY") && !stderr.contains("panicked"), "{stderr}");
}

/// The window's ICCCM state as the window manager set it (`Normal`, `Iconic`), read with xprop.
fn wm_state(app: &AppWindow) -> Option<String> {
    use winit::raw_window_handle::{HasWindowHandle, RawWindowHandle};
    let id = match app.window().window_handle().expect("a window handle").as_raw() {
        RawWindowHandle::Xlib(h) => h.window,
        RawWindowHandle::Xcb(h) => h.window.get() as u64,
        other => panic!("not an X11 window: {other:?}"),
    };
    let out = std::process::Command::new("xprop")
        .args(["-id", &id.to_string(), "WM_STATE"])
        .output()
        .expect("xprop (x11-utils; scripts/install-deps.sh installs it)");
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    text.lines().find_map(|l| l.trim().strip_prefix("window state: ").map(str::to_string))
}

/// Polls until the window manager reports `state`.
fn wait_for_state(app: &mut AppWindow, state: &str) {
    let start = Instant::now();
    while wm_state(app).as_deref() != Some(state) {
        app.poll();
        assert!(start.elapsed() < Duration::from_secs(10), "the window never became {state}: {:?}", wm_state(app));
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// A C program opens its own window, with Xlib and then with xcb, and hands its handles to
/// `softshadow_engine_create_window`: with validation on, every frame presents, at 96×64 and
/// after the program shrinks the window to 48×32, no validation error is printed, and the last
/// frame's passes have positive GPU times.
fn a_c_program_presents_into_its_own_xlib_and_xcb_windows(_: &mut AppWindow) {
    let exe = common::c::compile("window", &["-lX11", "-lxcb"]);
    for library in ["xlib", "xcb"] {
        let output = std::process::Command::new(&exe)
            .args([library, "scenes/default.toml"])
            .current_dir(common::c::root())
            .output()
            .expect("the C program runs");
        let (stdout, stderr) = (String::from_utf8_lossy(&output.stdout), String::from_utf8_lossy(&output.stderr));
        assert!(output.status.success(), "{library}: {stdout}\n{stderr}");
        assert!(!stderr.contains("validation error"), "{library}: {stderr}");
        for size in ["96x64", "48x32"] {
            let presented = format!("window {size}: 30 of 30 frames presented at {size}");
            assert!(stdout.contains(&presented), "{library}: {stdout}");
        }
        let passes = common::c::passes(&stdout, "pass ");
        assert!(!passes.is_empty() && passes.iter().all(|&(_, ms)| ms > 0.0), "{library}: {stdout}");
        let times: Vec<_> = stdout.lines().filter(|l| l.starts_with("pass ")).collect();
        println!("  {library}: {}", times.join(", "));
    }
    std::fs::remove_file(exe).unwrap();
}

/// Under a window manager (twm, started here; an X server's own one if it already has one),
/// the window iconified and restored: every frame presents or is skipped, none errors, frames
/// are presented again at the window's size once restored, and validation stays silent. On X11
/// an iconified window keeps its size (the surface reports it), so Mesa's swapchain goes on
/// presenting; a surface of no area (Windows' minimised windows) skips frames instead.
fn minimising_under_a_window_manager_never_errors(app: &mut AppWindow) {
    let config = std::env::temp_dir().join(format!("softshadow-twmrc-{}", std::process::id()));
    // Placed without asking, no title bar, and fonts every X server has (twm wants "variable").
    let fonts =
        ["TitleFont", "ResizeFont", "MenuFont", "IconFont", "IconManagerFont"].map(|f| format!("{f} \"fixed\"\n"));
    std::fs::write(&config, format!("RandomPlacement\nNoTitle\n{}", fonts.concat())).unwrap();
    let mut twm = std::process::Command::new("twm")
        .arg("-f")
        .arg(&config)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .expect("twm (scripts/install-deps.sh installs it)");
    wait_for_state(app, "Normal");
    let mut engine = windowed(app, WindowOptions::default());
    let params = params(&scene(0.0));
    for _ in 0..3 {
        assert_eq!(engine.present(&scene(0.0), &params).unwrap(), Presented::Shown);
    }
    app.window().set_minimized(true);
    wait_for_state(app, "Iconic");
    let (mut shown, mut skipped) = (0, 0);
    for frame in 0..20 {
        app.poll();
        match engine.present(&scene(frame as f32 * 0.05), &params).expect("a frame while iconified") {
            Presented::Shown => shown += 1,
            Presented::Skipped => skipped += 1,
        }
    }
    println!("  iconified: {shown} frames presented, {skipped} skipped");
    // winit restores through EWMH, which twm lacks: withdraw and map again, as ICCCM has it.
    app.window().set_visible(false);
    app.window().set_visible(true);
    wait_for_state(app, "Normal");
    let c = engine.present_and_capture(&scene(0.0), &params).unwrap().expect("presented once restored");
    assert_eq!((c.width, c.height), (W, H));
    common::finish(engine);
    let _ = twm.kill();
    let _ = twm.wait();
    std::fs::remove_file(&config).unwrap();
}
