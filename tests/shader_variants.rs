//! A caster moving from frame to frame compiles no shader after the first frames, in every
//! real-time technique and both compute paths. lavapipe inlines a uniform that a branch or a
//! loop's end depends on alone and compiles the shader again for each new value: fed per-frame
//! values (a light view fitted to the moving caster), a shader was compiled every frame (PCSS's
//! resolve, 190 ms a frame at 32², and the smoothie's silhouette pass, 5 s). What the driver
//! compiles shows in Mesa's shader cache, which this test points at a directory of its own.

mod common;

use std::path::Path;
use std::time::{Duration, Instant};

use common::{engine, finish, realtime_runs, suite_scene};
use softshadow::FrameSettings;

/// The files under `dir`, however deep.
fn files(dir: &Path) -> usize {
    std::fs::read_dir(dir)
        .map_or(0, |entries| entries.flatten().map(|e| if e.path().is_dir() { files(&e.path()) } else { 1 }).sum())
}

/// The cache's file count once the driver's writer thread has stopped adding to it.
fn settled(dir: &Path) -> usize {
    let start = Instant::now();
    let mut count = files(dir);
    let mut still = 0;
    while still < 5 && start.elapsed() < Duration::from_secs(30) {
        std::thread::sleep(Duration::from_millis(100));
        let now = files(dir);
        still = if now == count { still + 1 } else { 0 };
        count = now;
    }
    count
}

#[test]
fn a_moving_caster_compiles_nothing_after_its_first_frames() {
    let cache = std::env::temp_dir().join(format!("softshadow-shader-cache-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&cache);
    // SAFETY: this binary's one test writes the environment before the driver is loaded, while
    // the harness's main thread only waits for it.
    unsafe {
        std::env::remove_var("MESA_SHADER_CACHE_DISABLE");
        std::env::set_var("MESA_SHADER_CACHE_DIR", &cache);
    }
    let mut e = engine();
    let mut scene = suite_scene("plate");
    let start = scene.objects[0].transform.position;
    let mut frame = 0;
    for (name, params) in realtime_runs() {
        let settings = FrameSettings { width: 32, height: 32, params };
        let mut moved = |e: &mut softshadow::Engine, frames: usize| {
            for _ in 0..frames {
                frame += 1;
                scene.objects[0].transform.position.x = start.x + 0.01 * (frame as f32 * 0.7).sin();
                e.render(&scene, &settings).unwrap();
            }
            e.flush().unwrap();
        };
        moved(&mut e, 2);
        let first = settled(&cache);
        assert!(first > 0, "{name}: nothing in Mesa's shader cache at {}: is the driver lavapipe?", cache.display());
        moved(&mut e, 4);
        let after = settled(&cache);
        assert_eq!(after, first, "{name}: shaders compiled while the caster moved (Mesa's cache entries)");
    }
    finish(e);
    let _ = std::fs::remove_dir_all(&cache);
}
