//! The `softshadow` command line (DESIGN.md §3).

use std::path::{Path, PathBuf};

use anyhow::{Context as _, Result, bail};
use clap::{Parser, Subcommand};
use softshadow::gpu::ContextOptions;
use softshadow::measure::TimingReport;
use softshadow::scene::Scene;
use softshadow::technique::{TECHNIQUES, knobs};
use softshadow::{Engine, FrameSettings};

/// Frames rendered before timing starts (pipelines warm, caches filled).
const WARMUP_FRAMES: usize = 3;

#[derive(Parser)]
#[command(name = "softshadow", version, about = "Real-time fake soft shadows with raw Vulkan")]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene file to images and timings.
    Render(RenderArgs),
    /// List the techniques and their knobs with defaults.
    Techniques,
    /// Show the Vulkan device, driver and limits.
    Info,
}

#[derive(clap::Args)]
struct RenderArgs {
    /// The scene file (TOML).
    scene: PathBuf,
    /// Technique; overrides the scene's `[render] technique`.
    #[arg(long)]
    technique: Option<String>,
    /// A technique knob, KEY=VALUE; repeatable; overrides `[render.params]`.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<String>,
    #[arg(long)]
    width: Option<u32>,
    #[arg(long)]
    height: Option<u32>,
    /// Color image (PNG).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Visibility image V (16-bit grayscale PNG).
    #[arg(long)]
    visibility: Option<PathBuf>,
    /// Timings JSON.
    #[arg(long)]
    timings: Option<PathBuf>,
    /// Frames to time (after warm-up frames).
    #[arg(long, default_value_t = 20)]
    frames: usize,
}

fn main() {
    if let Err(e) = run(Cli::parse()) {
        eprintln!("softshadow: {e:#}");
        std::process::exit(1);
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Some(Command::Render(args)) => render(&args).map(|_| ()),
        Some(Command::Techniques) => {
            for t in TECHNIQUES {
                println!("{}: {}", t.name, t.summary);
                for k in t.knobs {
                    println!("    {:<16} default {:<8} range {}..={}  {}", k.name, k.default, k.min, k.max, k.help);
                }
            }
            Ok(())
        }
        Some(Command::Info) => {
            let engine = Engine::headless(&ContextOptions::from_env())?;
            let d = engine.device();
            println!("device:   {} ({})", d.name, d.device_type);
            println!("driver:   {}", d.driver);
            println!("vulkan:   {}", d.vulkan_version);
            println!("max 2D image side:    {}", d.max_image_dimension_2d);
            println!("max push constants:   {} bytes", d.max_push_constants_size);
            println!("timestamp period:     {} ns, {} valid bits", d.timestamp_period_ns, d.timestamp_valid_bits);
            Ok(())
        }
        None => default_run(),
    }
}

/// `softshadow` alone: the default scene into out/, with a table of GPU ms per pass.
fn default_run() -> Result<()> {
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/default.toml");
    let out = PathBuf::from("out");
    std::fs::create_dir_all(&out).with_context(|| format!("creating {}", out.display()))?;
    let args = RenderArgs {
        scene,
        technique: None,
        set: Vec::new(),
        width: None,
        height: None,
        out: Some(out.join("color.png")),
        visibility: Some(out.join("visibility.png")),
        timings: Some(out.join("timings.json")),
        frames: 20,
    };
    let report = render(&args)?;
    println!(
        "{} on {} ({}), {}x{}, median of {} frames",
        report.technique, report.device, report.driver, report.width, report.height, report.frames
    );
    println!("{:<12} {:>10} {:>10}", "pass", "GPU ms", "p95 ms");
    for p in &report.passes {
        println!("{:<12} {:>10.3} {:>10.3}", p.name, p.gpu_ms_median, p.gpu_ms_p95);
    }
    println!("{:<12} {:>10.3}", "total", report.gpu_ms_total_median);
    println!("wrote out/color.png, out/visibility.png, out/timings.json");
    Ok(())
}

fn render(args: &RenderArgs) -> Result<TimingReport> {
    let mut scene = Scene::load(&args.scene)?;
    if let Some(t) = &args.technique {
        knobs::find(t)?;
        // A different technique starts from its own defaults, not the scene's knobs.
        if *t != scene.render.technique {
            scene.render.params.clear();
        }
        scene.render.technique = t.clone();
    }
    scene.render.width = args.width.unwrap_or(scene.render.width);
    scene.render.height = args.height.unwrap_or(scene.render.height);
    let mut settings = FrameSettings::from_scene(&scene)?;
    for pair in &args.set {
        let Some((k, v)) = pair.split_once('=') else { bail!("--set takes KEY=VALUE, got `{pair}`") };
        settings.params.set(k.trim(), v)?;
    }
    if args.frames == 0 {
        bail!("--frames must be at least 1");
    }

    let mut engine = Engine::headless(&ContextOptions::from_env())?;
    for _ in 0..WARMUP_FRAMES + args.frames - 1 {
        engine.render(&scene, &settings)?;
    }
    let capture = engine.render_and_capture(&scene, &settings)?;
    engine.flush()?;
    let timings = engine.take_timings();
    let measured = &timings[timings.len().saturating_sub(args.frames)..];
    let report = TimingReport::new(engine.device(), &scene.render.technique, settings.width, settings.height, measured);
    if let Some(p) = &args.out {
        capture.save_color(p)?;
    }
    if let Some(p) = &args.visibility {
        capture.save_visibility(p)?;
    }
    if let Some(p) = &args.timings {
        let json = serde_json::to_string_pretty(&report)?;
        std::fs::write(p, json + "\n").with_context(|| format!("writing {}", p.display()))?;
    }
    let errors = engine.finish();
    if !errors.is_empty() {
        bail!("{} Vulkan validation error(s), the first: {}", errors.len(), errors[0]);
    }
    Ok(report)
}
