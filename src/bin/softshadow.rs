//! The `softshadow` command line (DESIGN.md §3).

/// `println!` that ends the program quietly when standard output is a closed pipe
/// (`softshadow techniques | head`), as a Unix filter does, where `println!` panics.
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::write_line(format_args!($($arg)*))
    };
}

#[path = "softshadow/view.rs"]
mod view;

use std::path::{Path, PathBuf};

use anyhow::{Context as _, Result, bail};
use clap::{Parser, Subcommand};
use softshadow::gpu::ContextOptions;
use softshadow::measure::{FileTrace, Metrics, TimingReport, save_difference, total_median};
use softshadow::scene::Scene;
use softshadow::technique::registry::{Runs, ground_truth};
use softshadow::technique::{Kind, Params, TECHNIQUES, TechniqueInfo, find};
use softshadow::{Capture, Engine, FrameSettings, FrameTimings};

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
    /// Render a technique and a reference, and print how wrong the technique is.
    Compare(CompareArgs),
    /// The speed/accuracy sweep: every technique and setting on every scene, against the
    /// reference; writes results.csv, report.md and tradeoff.png.
    Bench(BenchArgs),
    /// Every technique on one scene, side by side: a contact sheet labelled with GPU ms and
    /// the error against the CPU ray tracer, and the same table printed. `softshadow` with no
    /// arguments runs it on the default scene into out/.
    Showcase(ShowcaseArgs),
    /// Open a window on a scene: orbit, pan and zoom with the mouse, drag the light, switch
    /// techniques and knobs, take screenshots, measure the error against the reference.
    View(view::ViewArgs),
    /// List the techniques and their knobs with defaults.
    Techniques,
    /// Show the Vulkan device, driver and limits.
    Info,
}

/// What to render: a scene, a technique and its knobs, a size.
#[derive(clap::Args)]
struct SceneArgs {
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
    /// Frames to time after warm-up [default: 20; 1 without warm-up for offline techniques].
    #[arg(long)]
    frames: Option<usize>,
}

#[derive(clap::Args)]
struct RenderArgs {
    #[command(flatten)]
    what: SceneArgs,
    /// Color image (PNG).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Visibility image V (16-bit grayscale PNG).
    #[arg(long)]
    visibility: Option<PathBuf>,
    /// Timings JSON.
    #[arg(long)]
    timings: Option<PathBuf>,
    /// Chrome trace of every frame (GPU passes and CPU work; opens in Perfetto).
    #[arg(long)]
    trace: Option<PathBuf>,
}

#[derive(clap::Args)]
struct CompareArgs {
    #[command(flatten)]
    what: SceneArgs,
    /// A ground truth (`softshadow techniques` lists them) [default: the one on the GPU].
    #[arg(long)]
    against: Option<String>,
    /// A knob of the ground truth, KEY=VALUE; repeatable.
    #[arg(long = "against-set", value_name = "KEY=VALUE")]
    against_set: Vec<String>,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
    /// Signed error image (PNG): red too light, blue too dark, magenta different surfaces.
    #[arg(long)]
    diff: Option<PathBuf>,
}

#[derive(clap::Args)]
struct BenchArgs {
    /// Scene files [default: every scene in scenes/].
    scenes: Vec<PathBuf>,
    /// Only these techniques (comma-separated).
    #[arg(long, value_delimiter = ',')]
    techniques: Vec<String>,
    /// Output folder.
    #[arg(long, default_value = "bench-out")]
    out: PathBuf,
    /// A small subset (two scenes, default settings, 128²) for CI.
    #[arg(long)]
    quick: bool,
    /// Also the scale scenes of scenes/scale/ (60k–100k triangles; minutes more on lavapipe).
    #[arg(long, conflicts_with_all = ["scenes", "quick"])]
    scale: bool,
    /// Frames timed per setting, after warm-up.
    #[arg(long, default_value_t = 20)]
    frames: usize,
    /// Light samples of the reference: its own error must stay far below the techniques'.
    #[arg(long, default_value_t = 256)]
    reference_samples: u32,
    /// Chrome trace of every timed frame (GPU passes and CPU work; opens in Perfetto).
    #[arg(long)]
    trace: Option<PathBuf>,
    /// Instead of the trade: the stability sweep's long grids (every axis, up to 4096²),
    /// written to DIR/extremes.csv; fails if any check fails.
    #[arg(long, conflicts_with_all = ["scenes", "quick", "trace"])]
    extremes: bool,
    /// Instead of the trade: each technique's cost against triangle count, at these sizes of
    /// the scene's knots (the scene given, else scenes/scale/knot.toml), written to
    /// DIR/curve.csv, curve.md (slopes) and cost_curve.png.
    #[arg(long, value_delimiter = ',', conflicts_with_all = ["quick", "extremes", "trace"])]
    curve: Vec<u32>,
}

#[derive(clap::Parser)]
struct ShowcaseArgs {
    /// The scene file (TOML).
    #[arg(default_value = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/default.toml"))]
    scene: PathBuf,
    /// Output folder: contact_sheet.png and a folder per technique.
    #[arg(long, default_value = "out")]
    out: PathBuf,
    #[arg(long)]
    width: Option<u32>,
    #[arg(long)]
    height: Option<u32>,
}

fn write_line(line: std::fmt::Arguments) {
    use std::io::Write as _;
    if let Err(e) = writeln!(std::io::stdout().lock(), "{line}") {
        if e.kind() != std::io::ErrorKind::BrokenPipe {
            eprintln!("softshadow: writing to standard output: {e}");
            std::process::exit(1);
        }
        std::process::exit(0);
    }
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
        Some(Command::Compare(args)) => compare(&args),
        Some(Command::Bench(args)) => bench(&args),
        Some(Command::Showcase(args)) => showcase(&args),
        Some(Command::View(args)) => view::view(&args),
        Some(Command::Techniques) => {
            for t in TECHNIQUES {
                out!("{}: {}", t.name, t.summary);
                for k in t.knobs {
                    let range = match k.choices {
                        [] => format!("range {}..={}", k.min, k.max),
                        _ => format!("values {}", k.choice_list()),
                    };
                    out!("    {:<16} default {:<8} {range}  {}", k.name, k.default, k.help);
                }
            }
            Ok(())
        }
        Some(Command::Info) => {
            let engine = Engine::headless(&ContextOptions::from_env())?;
            let d = engine.device();
            out!("device:   {} ({})", d.name, d.device_type);
            out!("driver:   {}", d.driver);
            out!("vulkan:   {}", d.vulkan_version);
            out!("max 2D image side:    {}", d.max_image_dimension_2d);
            out!("max push constants:   {} bytes", d.max_push_constants_size);
            out!("subpixel precision:   {} bits", d.sub_pixel_precision_bits);
            out!("timestamp period:     {} ns, {} valid bits", d.timestamp_period_ns, d.timestamp_valid_bits);
            Ok(())
        }
        None => showcase(&ShowcaseArgs::parse_from(["softshadow showcase"])),
    }
}

/// `showcase`: every technique on one scene, against the CPU ray tracer.
fn showcase(args: &ShowcaseArgs) -> Result<()> {
    use softshadow::measure::{Tile, contact_sheet};
    let what = SceneArgs {
        scene: args.scene.clone(),
        technique: None,
        set: Vec::new(),
        width: args.width,
        height: args.height,
        frames: None,
    };
    let (scene, base) = load(&what)?;
    std::fs::create_dir_all(&args.out).with_context(|| format!("creating {}", args.out.display()))?;
    let mut engine = Engine::headless(&ContextOptions::from_env())?;
    let bar = indicatif::ProgressBar::new(TECHNIQUES.len() as u64);
    let truth_info = ground_truth(Runs::Cpu);
    bar.set_message(truth_info.name);
    let truth_settings = FrameSettings { params: Params::defaults(truth_info), ..base.clone() };
    let truth = render_frames(&mut engine, &scene, &truth_settings, None, None)?;
    let mut rows: Vec<(&TechniqueInfo, Capture, TimingReport, Option<Metrics>)> = Vec::new();
    for &info in TECHNIQUES {
        bar.set_message(info.name);
        let (capture, report, metrics) = if info.name == truth_info.name {
            (truth.0.clone(), truth.1.clone(), None)
        } else {
            let settings = FrameSettings { params: Params::defaults(info), ..base.clone() };
            let (capture, report) = render_frames(&mut engine, &scene, &settings, None, None)?;
            let metrics = Metrics::between(&capture, &truth.0)?;
            (capture, report, Some(metrics))
        };
        let dir = args.out.join(info.name);
        std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
        capture.save_color(&dir.join("color.png"))?;
        capture.save_visibility(&dir.join("visibility.png"))?;
        write_json(&report, &dir.join("timings.json"))?;
        rows.push((info, capture, report, metrics));
        bar.inc(1);
    }
    bar.finish_and_clear();
    finish(engine)?;

    let cpu = |r: &TimingReport| r.cpu_ms.get("technique").copied().unwrap_or(0.0);
    let tiles: Vec<Tile> = rows
        .iter()
        .map(|(info, capture, report, metrics)| Tile {
            title: info.name.to_string(),
            // Short enough for 256-pixel tiles; the CPU tracers' cost is their CPU time.
            detail: match (metrics, info.kind.offline() && cpu(report) > report.gpu_ms_total_median) {
                (Some(m), true) => format!("CPU {:.0} ms  RMSE {:.4}", cpu(report), m.rmse),
                (Some(m), false) => format!("GPU {:.1} ms  RMSE {:.4}", report.gpu_ms_total_median, m.rmse),
                (None, _) => format!("truth, CPU {:.0} ms", cpu(report)),
            },
            capture,
        })
        .collect();
    let sheet = args.out.join("contact_sheet.png");
    contact_sheet(&tiles, 4, &sheet)?;

    let first = &rows[0].2;
    out!(
        "{}, {}x{}, {} ({}); GPU and CPU ms: medians of 20 frames after 3 warm-up (offline techniques: 1 frame); \
         error against {} [{}]",
        args.scene.display(),
        first.width,
        first.height,
        first.device,
        first.driver,
        truth_info.name,
        truth_settings.params
    );
    out!(
        "{:<12} {:>10} {:>10} {:>9} {:>10} {:>9} {:>9}",
        "technique",
        "GPU ms",
        "CPU ms",
        "RMSE",
        "penumbra",
        "leak",
        "dark"
    );
    for (info, _, report, metrics) in &rows {
        let errors = match metrics {
            Some(m) => format!("{:>9.4} {:>10.4} {:>9.4} {:>9.4}", m.rmse, m.penumbra_rmse, m.leak_rate, m.dark_rate),
            None => format!("{:>9}", "(truth)"),
        };
        out!("{:<12} {:>10.2} {:>10.2} {errors}", info.name, report.gpu_ms_total_median, cpu(report));
    }
    out!(
        "wrote {} and per technique {}/<technique>/{{color,visibility}}.png, timings.json",
        sheet.display(),
        args.out.display()
    );
    Ok(())
}

fn write_json(value: &impl serde::Serialize, path: &Path) -> Result<()> {
    let json = serde_json::to_string_pretty(value)?;
    std::fs::write(path, json + "\n").with_context(|| format!("writing {}", path.display()))
}

/// Applies `KEY=VALUE` pairs to `params`.
fn apply_sets(params: &mut Params, pairs: &[String]) -> Result<()> {
    for pair in pairs {
        let Some((k, v)) = pair.split_once('=') else { bail!("--set takes KEY=VALUE, got `{pair}`") };
        params.set(k.trim(), v)?;
    }
    Ok(())
}

/// The scene with the command line's technique, size and knobs applied.
fn load(args: &SceneArgs) -> Result<(Scene, FrameSettings)> {
    let mut scene = Scene::load(&args.scene)?;
    if let Some(t) = &args.technique {
        find(t)?;
        // A different technique starts from its own defaults, not the scene's knobs.
        if *t != scene.render.technique {
            scene.render.params.clear();
        }
        scene.render.technique = t.clone();
    }
    scene.render.width = args.width.unwrap_or(scene.render.width);
    scene.render.height = args.height.unwrap_or(scene.render.height);
    let mut settings = FrameSettings::from_scene(&scene)?;
    apply_sets(&mut settings.params, &args.set)?;
    Ok((scene, settings))
}

/// Renders warm-up frames and `frames` timed frames, the last one captured. Offline techniques
/// default to one frame without warm-up. With a trace, every frame goes into it, labelled
/// with `label` and whether it was timed.
fn render_frames(
    engine: &mut Engine,
    scene: &Scene,
    settings: &FrameSettings,
    frames: Option<usize>,
    trace: Option<(&mut FileTrace, &serde_json::Value)>,
) -> Result<(Capture, TimingReport)> {
    let offline = settings.params.technique.kind.offline();
    let frames = frames.unwrap_or(if offline { 1 } else { 20 });
    let (capture, measured) = timed_frames(engine, scene, settings, frames, true, trace)?;
    let name = settings.params.technique.name;
    let report = TimingReport::new(engine.device(), name, settings.width, settings.height, &measured);
    Ok((capture.expect("captured"), report))
}

/// Warm-up frames (none for offline techniques), then `frames` timed ones, the last captured
/// when `capture`; their timings.
fn timed_frames(
    engine: &mut Engine,
    scene: &Scene,
    settings: &FrameSettings,
    frames: usize,
    capture: bool,
    trace: Option<(&mut FileTrace, &serde_json::Value)>,
) -> Result<(Option<Capture>, Vec<FrameTimings>)> {
    if frames == 0 {
        bail!("--frames must be at least 1");
    }
    let warmup = if settings.params.technique.kind.offline() { 0 } else { WARMUP_FRAMES };
    // Every frame rendered here is reported (or traced): keep all their timings.
    engine.set_timing_history(warmup + frames);
    for _ in 0..warmup + frames - usize::from(capture) {
        engine.render(scene, settings)?;
    }
    let captured = capture.then(|| engine.render_and_capture(scene, settings)).transpose()?;
    engine.flush()?;
    let mut timings = engine.take_timings();
    let measured = timings.split_off(timings.len().saturating_sub(frames));
    if let Some((trace, label)) = trace {
        let mut label = label.clone();
        label["timed"] = false.into();
        trace.add_frames(&timings, &label);
        label["timed"] = true.into();
        trace.add_frames(&measured, &label);
    }
    Ok((captured, measured))
}

fn finish(engine: Engine) -> Result<()> {
    let errors = engine.finish();
    if !errors.is_empty() {
        bail!("{} Vulkan validation error(s), the first: {}", errors.len(), errors[0]);
    }
    Ok(())
}

fn render(args: &RenderArgs) -> Result<TimingReport> {
    let (scene, settings) = load(&args.what)?;
    writable(&[&args.out, &args.visibility, &args.timings, &args.trace])?;
    let mut engine = Engine::headless(&ContextOptions::from_env())?;
    let mut trace = args.trace.as_ref().map(|p| FileTrace::create(&engine.device().name, p)).transpose()?;
    let label = serde_json::json!({
        "scene": args.what.scene,
        "technique": settings.params.technique.name,
        "params": settings.params.to_string(),
    });
    let (capture, report) =
        render_frames(&mut engine, &scene, &settings, args.what.frames, trace.as_mut().map(|t| (t, &label)))?;
    if let Some(trace) = trace {
        trace.finish()?;
    }
    if let Some(p) = &args.out {
        capture.save_color(p)?;
    }
    if let Some(p) = &args.visibility {
        capture.save_visibility(p)?;
    }
    if let Some(p) = &args.timings {
        write_json(&report, p)?;
    }
    finish(engine)?;
    Ok(report)
}

/// Fails now, before a long render, when an output file's folder does not exist.
fn writable(paths: &[&Option<PathBuf>]) -> Result<()> {
    for path in paths.iter().copied().flatten() {
        let folder = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
        if !folder.is_dir() {
            bail!("{}: the folder {} does not exist", path.display(), folder.display());
        }
    }
    Ok(())
}

/// `compare`: the technique's metrics against a ground truth on the same camera pixels.
fn compare(args: &CompareArgs) -> Result<()> {
    let (scene, settings) = load(&args.what)?;
    writable(&[&args.diff])?;
    let against = args.against.as_deref().map_or(Ok(ground_truth(Runs::Gpu)), find)?;
    if !matches!(against.kind, Kind::GroundTruth(_)) {
        let truths: Vec<_> =
            TECHNIQUES.iter().filter(|t| matches!(t.kind, Kind::GroundTruth(_))).map(|t| t.name).collect();
        bail!("--against takes a ground truth ({}), not `{}`", truths.join(" or "), against.name);
    }
    let mut truth = FrameSettings { params: Params::defaults(against), ..settings.clone() };
    apply_sets(&mut truth.params, &args.against_set)?;

    let mut engine = Engine::headless(&ContextOptions::from_env())?;
    let (capture, report) = render_frames(&mut engine, &scene, &settings, args.what.frames, None)?;
    let (reference, reference_report) = render_frames(&mut engine, &scene, &truth, None, None)?;
    let metrics = Metrics::between(&capture, &reference)?;
    if let Some(p) = &args.diff {
        save_difference(&capture, &reference, p)?;
    }
    finish(engine)?;

    if args.json {
        let json = serde_json::json!({
            "scene": args.what.scene,
            "technique": settings.params.technique.name,
            "params": settings.params.to_string(),
            "against": against.name,
            "against_params": truth.params.to_string(),
            "timings": report,
            "against_timings": reference_report,
            "metrics": metrics,
        });
        out!("{}", serde_json::to_string_pretty(&json)?);
        return Ok(());
    }
    out!("{} [{}] against {} [{}]", report.technique, settings.params, against.name, truth.params);
    out!("{}, {}x{}, {} ({})", args.what.scene.display(), report.width, report.height, report.device, report.driver);
    out!("{:<28} {:>12}", "GPU ms (median)", format!("{:.3}", report.gpu_ms_total_median));
    out!("{:<28} {:>12}", "reference GPU ms", format!("{:.3}", reference_report.gpu_ms_total_median));
    let m = &metrics;
    let rows: [(&str, String); 10] = [
        ("receiver pixels compared", m.pixels.to_string()),
        ("excluded (other surface)", m.excluded.to_string()),
        ("RMSE", format!("{:.5}", m.rmse)),
        ("MAE", format!("{:.5}", m.mae)),
        ("max |error|", format!("{:.5}", m.max_abs)),
        ("99th percentile |error|", format!("{:.5}", m.p99_abs)),
        ("penumbra RMSE", format!("{:.5} ({} px)", m.penumbra_rmse, m.penumbra_pixels)),
        ("light-leak rate (> +0.1)", format!("{:.5}", m.leak_rate)),
        ("over-darkening rate (< -0.1)", format!("{:.5}", m.dark_rate)),
        ("mean bias", format!("{:+.5}", m.mean_bias)),
    ];
    for (name, value) in rows {
        out!("{name:<28} {value:>12}");
    }
    Ok(())
}

/// `bench --extremes`: the long grids of measure::extremes.
fn extremes(args: &BenchArgs) -> Result<()> {
    use softshadow::measure::extremes::{Axis, problems, sweep, write_csv};
    let techniques = args.techniques.iter().map(|t| find(t)).collect::<Result<Vec<_>, _>>()?;
    std::fs::create_dir_all(&args.out).with_context(|| format!("creating {}", args.out.display()))?;
    let mut engine = Engine::headless(&ContextOptions::from_env())?;
    let bar = indicatif::ProgressBar::new_spinner();
    let mut rows = Vec::new();
    for axis in Axis::ALL {
        rows.extend(sweep(&mut engine, axis, true, &techniques, &mut |label| bar.set_message(label.to_string()))?);
    }
    bar.finish_and_clear();
    finish(engine)?;
    let csv = args.out.join("extremes.csv");
    write_csv(&rows, &csv)?;
    out!("wrote {} ({} renders)", csv.display(), rows.len());
    let problems = problems(&rows);
    if !problems.is_empty() {
        bail!("{} stability problem(s):\n{}", problems.len(), problems.join("\n"));
    }
    out!("no NaN, V within [0, 1], continuous along every axis");
    Ok(())
}

/// `bench --curve`: every benched technique's defaults on the scene's knots re-made at each size.
fn curve(args: &BenchArgs) -> Result<()> {
    use softshadow::measure::bench::sweep;
    use softshadow::measure::curve::{CurvePoint, write_curve};
    let path = match args.scenes.as_slice() {
        [] => Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/scale/knot.toml"),
        [one] => one.clone(),
        _ => bail!("--curve takes one scene"),
    };
    let what = SceneArgs { scene: path, technique: None, set: Vec::new(), width: None, height: None, frames: None };
    let (base, _) = load(&what)?;
    if !base.objects.iter().any(|o| o.mesh.name == "knot") {
        bail!("--curve needs a scene with a `shape = \"knot\"` object to re-make at each size");
    }
    for t in &args.techniques {
        find(t)?;
    }
    std::fs::create_dir_all(&args.out).with_context(|| format!("creating {}", args.out.display()))?;
    let mut engine = Engine::headless(&ContextOptions::from_env())?;
    let mut points = Vec::new();
    for &n in &args.curve {
        let mut scene = base.clone();
        let knot = std::sync::Arc::new(softshadow::scene::primitives::knot(n)?);
        scene.objects.iter_mut().filter(|o| o.mesh.name == "knot").for_each(|o| o.mesh = knot.clone());
        let triangles = scene.objects.iter().filter(|o| o.casts).map(|o| o.mesh.triangles.len()).sum();
        for (info, sets) in sweep(true) {
            if !(args.techniques.is_empty() || args.techniques.iter().any(|t| t == info.name)) {
                continue;
            }
            let mut settings = FrameSettings::from_scene(&scene)?;
            settings.params = Params::defaults(info);
            settings.params.apply(sets.iter().copied())?;
            let (_, timings) = render_frames(&mut engine, &scene, &settings, Some(args.frames), None)?;
            out!("{triangles} triangles, {}: {:.2} ms", info.name, timings.gpu_ms_total_median);
            points.push(CurvePoint { technique: info.name.into(), triangles, gpu_ms: timings.gpu_ms_total_median });
        }
    }
    finish(engine)?;
    write_curve(&points, softshadow::technique::shadow_map::INFO.name, &args.out)?;
    out!("wrote {0}/curve.csv, {0}/curve.md, {0}/cost_curve.png", args.out.display());
    Ok(())
}

/// `bench`: the sweep of measure::bench over the scene suite.
fn bench(args: &BenchArgs) -> Result<()> {
    if args.extremes {
        return extremes(args);
    }
    if !args.curve.is_empty() {
        return curve(args);
    }
    use softshadow::measure::bench::{
        BenchRow, leak_goals, load_reference, mark_pareto, registry_cost_goals, round_frames, save_reference,
        setting_label, sweep, timing_order, write_csv, write_report,
    };
    let suite = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let scenes: Vec<PathBuf> = if !args.scenes.is_empty() {
        args.scenes.clone()
    } else if args.quick {
        vec![suite.join("plate.toml"), suite.join("sphere.toml")]
    } else {
        let folders = if args.scale { vec![suite.clone(), suite.join("scale")] } else { vec![suite.clone()] };
        let mut all = Vec::new();
        for folder in folders {
            let mut of: Vec<PathBuf> = std::fs::read_dir(&folder)
                .with_context(|| format!("listing {}", folder.display()))?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.extension().is_some_and(|x| x == "toml"))
                .collect();
            of.sort();
            all.extend(of);
        }
        all
    };
    for t in &args.techniques {
        find(t)?;
    }
    if args.frames == 0 {
        bail!("--frames must be at least 1");
    }
    let runs: Vec<_> = sweep(args.quick)
        .into_iter()
        .filter(|(t, _)| args.techniques.is_empty() || args.techniques.iter().any(|n| n == t.name))
        .collect();
    let goals: Vec<_> = registry_cost_goals().into_iter().chain(leak_goals()).collect();
    let order = timing_order(&runs, &goals);
    let size = if args.quick { 128 } else { 512 };
    let cache = args.out.join("cache");
    std::fs::create_dir_all(&cache).with_context(|| format!("creating {}", cache.display()))?;
    let mut engine = Engine::headless(&ContextOptions::from_env())?;
    let mut trace = args.trace.as_ref().map(|p| FileTrace::create(&engine.device().name, p)).transpose()?;
    let bar = indicatif::ProgressBar::new((scenes.len() * (runs.len() + 1)) as u64);
    let mut rows = Vec::new();
    for path in &scenes {
        let name = path.file_stem().map_or_else(|| path.display().to_string(), |s| s.to_string_lossy().into_owned());
        let what = SceneArgs {
            scene: path.clone(),
            technique: Some(ground_truth(Runs::Gpu).name.into()),
            set: vec![format!("samples={}", args.reference_samples)],
            width: Some(size),
            height: Some(size),
            frames: None,
        };
        let (scene, truth_settings) = load(&what)?;
        // Reference images are cached by a hash of the scene file, the reference's settings and
        // the build's shaders, so that a ground truth whose shaders changed is rendered anew.
        let text = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
        let key = {
            use std::hash::{Hash, Hasher};
            let mut h = std::collections::hash_map::DefaultHasher::new();
            (text, size, truth_settings.params.to_string(), env!("CARGO_PKG_VERSION")).hash(&mut h);
            softshadow::gpu::shaders::ALL.iter().for_each(|s| s.words.hash(&mut h));
            h.finish()
        };
        let cached = cache.join(format!("{name}-{key:016x}.ref"));
        bar.set_message(format!("{name}: reference"));
        let truth = match load_reference(&cached, size, size) {
            Some(c) => c,
            None => {
                let (c, _) = render_frames(&mut engine, &scene, &truth_settings, None, None)?;
                save_reference(&c, &cached)?;
                c
            }
        };
        bar.inc(1);
        let settings: Vec<FrameSettings> = runs
            .iter()
            .map(|&(info, sets)| {
                let mut settings = FrameSettings { params: Params::defaults(info), ..truth_settings.clone() };
                settings.params.apply(sets.iter().copied()).map(|_| settings)
            })
            .collect::<std::result::Result<_, _>>()?;
        // Real-time rows in interleaved rounds (measure::bench::ROUNDS), the last captured, each
        // goal's rows side by side (timing_order); offline ones once, with the first.
        let mut measured = vec![Vec::new(); runs.len()];
        let mut round_ms = vec![Vec::new(); runs.len()];
        let mut captures = vec![None; runs.len()];
        let rounds = round_frames(args.frames);
        for (round, &frames) in rounds.iter().enumerate() {
            let last = round + 1 == rounds.len();
            // Odd rounds backwards (timing_order).
            let n = order.len();
            for i in (0..n).map(|k| order[if round % 2 == 0 { k } else { n - 1 - k }]) {
                let (info, sets) = runs[i];
                let offline = info.kind.offline();
                if offline && round > 0 {
                    continue;
                }
                let technique = info.name;
                bar.set_message(format!("{name}: {technique}"));
                let setting = setting_label(sets);
                let label = serde_json::json!({"scene": name, "technique": technique, "setting": setting});
                let started = std::time::Instant::now();
                let frames = if offline { 1 } else { frames };
                let (capture, timings) = timed_frames(
                    &mut engine,
                    &scene,
                    &settings[i],
                    frames,
                    offline || last,
                    trace.as_mut().map(|t| (t, &label)),
                )?;
                if let Some(trace) = &mut trace {
                    let title = format!("{name}: {technique} {setting}");
                    trace.cpu_slice(title.trim_end(), started, std::time::Instant::now(), label);
                }
                round_ms[i].push(total_median(&timings));
                measured[i].extend(timings);
                if capture.is_some() {
                    captures[i] = capture;
                }
            }
        }
        for (i, &(info, sets)) in runs.iter().enumerate() {
            let capture = captures[i].take().expect("every row's last round captures");
            let timings = TimingReport::new(engine.device(), info.name, size, size, &measured[i]);
            rows.push(BenchRow {
                scene: name.clone(),
                technique: info.name.to_string(),
                setting: setting_label(sets),
                timings,
                round_ms: std::mem::take(&mut round_ms[i]),
                metrics: Metrics::between(&capture, &truth)?,
                pareto: false,
            });
            bar.inc(1);
        }
    }
    bar.finish_and_clear();
    finish(engine)?;
    mark_pareto(&mut rows);
    let reference = format!("{} (samples={})", ground_truth(Runs::Gpu).name, args.reference_samples);
    write_csv(&rows, &args.out.join("results.csv"))?;
    write_report(&rows, &reference, &args.out.join("report.md"))?;
    softshadow::measure::tradeoff(&rows, &args.out.join("tradeoff.png"))?;
    goals.iter().filter_map(|g| g.outcome(&rows)).for_each(|line| out!("{line}"));
    if let (Some(trace), Some(p)) = (trace, &args.trace) {
        trace.finish()?;
        out!("wrote {}", p.display());
    }
    out!("wrote {0}/results.csv, {0}/report.md, {0}/tradeoff.png", args.out.display());
    Ok(())
}
