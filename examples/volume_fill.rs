//! The shadow volumes' fill cost (issue 16): how the GPU time of `shadow-volume` grows with
//! the screen its volumes cover and with the light points of its accumulated soft form,
//! against the hard `shadow-map` frame of the same scene, all in one run.
//!
//! The scene: a row of K posts on a ground, lit from above and behind, seen from in front, so
//! that each post's volume sweeps a wedge of the screen towards the camera. Coverage is the
//! screen the volumes' triangles fill per hard shadow, in screens (`screen_fill`: every volume
//! fragment the stencil counts); K doubles from 1 to 32. At each K: the shadow map's frame, the
//! volumes with z-pass and z-fail (its caps add fill), on the CPU and the GPU silhouette path,
//! and `samples` N = 4, 16, 64. Median GPU ms over the measured frames; read ratios.
//!
//! `cargo run --release --example volume_fill [SIZE] [FRAMES]` (default 512, 8).

use softshadow::geometry::shadow_volume::{is_open, screen_fill, shadow_volume};
use softshadow::geometry::silhouette::Caster;
use softshadow::geometry::{Aabb, CameraProjection};
use softshadow::gpu::ContextOptions;
use softshadow::measure::TimingReport;
use softshadow::scene::Scene;
use softshadow::technique::{Params, find};
use softshadow::{Engine, FrameSettings};

const WARMUP: usize = 2;

fn posts(k: usize) -> Result<Scene, Box<dyn std::error::Error>> {
    let mut text = String::from(
        "[camera]\nposition = [0.0, 2.5, 9.0]\ntarget = [0.0, 0.8, 0.0]\nfov_y_deg = 50.0\n\
         [light]\nposition = [0.0, 7.0, -4.0]\nradius = 0.5\n[ground]\nheight = 0.0\nhalf_size = 12.0\n",
    );
    for i in 0..k {
        let x = if k == 1 { 0.0 } else { -4.0 + 8.0 * i as f32 / (k - 1) as f32 };
        text += &format!(
            "[[object]]\nshape = \"box\"\nsize = [0.2, 2.5, 0.2]\nposition = [{x}, 1.25, 0.0]\nreceives = false\n"
        );
    }
    Ok(Scene::from_toml(&text, "volume_fill.toml")?)
}

/// Screens of volume fill from the light's centre: the sides (z-pass) and the sides and caps
/// (z-fail).
fn fill(scene: &Scene, aspect: f32) -> Result<(f64, f64), String> {
    let bounds =
        scene.objects.iter().fold(Aabb::EMPTY, |b, o| b.union(&o.mesh.bounds.transformed(&o.transform.matrix())));
    let c = &scene.camera;
    let camera = CameraProjection::new(c.position, c.target, c.up, c.projection, aspect, &bounds)?;
    let light = scene.light.position;
    let (mut sides, mut all) = (0.0, 0.0);
    for o in scene.objects.iter().filter(|o| o.casts) {
        let model = o.transform.matrix();
        let positions: Vec<_> = o.mesh.positions.iter().map(|p| model.transform_point3(*p)).collect();
        let caster = Caster { positions: &positions, triangles: &o.mesh.triangles, adjacency: &o.mesh.adjacency };
        let volume = shadow_volume(&caster, &o.mesh.planes.light_facing(&model, light), is_open(&caster));
        sides += screen_fill(&volume, &positions, light, camera.view_proj, false);
        all += screen_fill(&volume, &positions, light, camera.view_proj, true);
    }
    Ok((sides, all))
}

/// What is measured at each K: the technique, its knobs, and whether its fill passes are shown.
const RUNS: [(&str, &[(&str, &str)]); 7] = [
    ("shadow-map", &[]),
    ("shadow-volume", &[("counting", "1")]),
    ("shadow-volume", &[("counting", "2")]),
    ("shadow-volume", &[("counting", "2"), ("gpu_silhouettes", "1")]),
    ("shadow-volume", &[("samples", "4")]),
    ("shadow-volume", &[("samples", "16")]),
    ("shadow-volume", &[("samples", "64")]),
];

/// Per run of [`RUNS`], median GPU ms of the frame and of its `volumes` and `caps` passes. One
/// engine per run, their frames taken in turn, so that the machine's load falls on all alike.
fn measure(
    engines: &mut [Engine],
    scene: &Scene,
    size: u32,
    frames: usize,
) -> Result<Vec<(f64, f64)>, Box<dyn std::error::Error>> {
    let mut settings = Vec::new();
    for (technique, sets) in RUNS {
        let mut s = FrameSettings::from_scene(scene)?;
        (s.width, s.height) = (size, size);
        s.params = Params::defaults(find(technique)?);
        s.params.apply(sets.iter().copied())?;
        settings.push(s);
    }
    for i in 0..WARMUP + frames {
        for (engine, s) in engines.iter_mut().zip(&settings) {
            engine.render(scene, s)?;
            engine.flush()?;
            if i < WARMUP {
                engine.take_timings();
            }
        }
    }
    let mut out = Vec::new();
    for (engine, s) in engines.iter_mut().zip(&settings) {
        let timings = engine.take_timings();
        let report = TimingReport::new(engine.device(), s.params.technique.name, size, size, &timings);
        let pass = |name: &str| report.passes.iter().find(|p| p.name == name).map_or(0.0, |p| p.gpu_ms_median);
        out.push((report.gpu_ms_total_median, pass("volumes") + pass("caps")));
    }
    Ok(out)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let size: u32 = args.next().map_or(Ok(512), |a| a.parse())?;
    let frames: usize = args.next().map_or(Ok(8), |a| a.parse())?;
    let options = ContextOptions::from_env();
    let mut engines = RUNS.iter().map(|_| Engine::headless(&options)).collect::<Result<Vec<_>, _>>()?;
    let device = engines[0].device();
    println!("{} ({}), {size}², median of {frames} frames\n", device.name, device.driver);
    println!(
        "| K | fill z-pass | fill z-fail | shadow-map ms | z-pass ms (fill ms) | ratio | z-fail ms (fill ms) | ratio \
         | GPU silhouettes z-fail ms | ratio | N=4 ms | ratio | N=16 ms | ratio | N=64 ms | ratio |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for k in [1, 2, 4, 8, 16, 32] {
        let scene = posts(k)?;
        let (fill_pass, fill_fail) = fill(&scene, 1.0)?;
        let ms = measure(&mut engines, &scene, size, frames)?;
        let map = ms[0].0;
        let mut row = format!("| {k} | {fill_pass:.2} | {fill_fail:.2} | {map:.2} |");
        for (i, (total, filling)) in ms.iter().enumerate().skip(1) {
            let filled = if i < 3 { format!(" ({filling:.2})") } else { String::new() };
            row += &format!(" {total:.2}{filled} | {:.2} |", total / map);
        }
        println!("{row}");
    }
    for engine in engines {
        let errors = engine.finish();
        if !errors.is_empty() {
            return Err(errors.join("\n").into());
        }
    }
    Ok(())
}
