//! The stability sweep: every technique over grids of the extremes a game meets (grazing
//! lights, point lights and lights larger than the caster, casters touching the ground or far
//! above it, tiny and huge scene scales, small and large targets), checked for
//!
//! - sound output: V as the technique wrote it (raw, before R16_UNORM would clamp it and turn
//!   NaN into 0) finite and within [0, 1] at every pixel;
//! - continuity: along each axis, a step changes the technique's error against the ray tracer
//!   by at most [`continuity_bound`];
//! - agreement on what is seen: the technique and the tracer see the same surfaces at all but
//!   [`MAX_EXCLUDED`] of the pixels (depth precision at extreme scales shows up here first).
//!
//! The tests run the short grids at 64²; `softshadow bench --extremes` runs the long ones.

use std::fmt::Write as _;
use std::path::Path;
use std::sync::Arc;

use glam::Vec3;

use crate::error::{Error, Result};
use crate::geometry::Projection;
use crate::measure::Metrics;
use crate::renderer::{Capture, Engine, FrameSettings};
use crate::scene::{Camera, Ground, Light, Object, RenderSettings, Scene, primitives};
use crate::technique::registry::{Runs, Setting, ground_truth};
use crate::technique::{Params, TECHNIQUES, TechniqueInfo};

/// One scene of a sweep, in units of the caster: a cube of side `scale` whose bottom is
/// `caster_height` × `scale` above the ground, lit from +x at `elevation_deg` above the horizon
/// (seen from the cube's centre, 5 sides away) by a light of radius `light_radius` × `scale`,
/// rendered at `size`².
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Setup {
    pub elevation_deg: f32,
    pub light_radius: f32,
    pub caster_height: f32,
    pub scale: f32,
    pub size: u32,
}

/// Where every axis's sweep starts from: a plate-like penumbra of moderate width.
pub const BASE: Setup = Setup { elevation_deg: 60.0, light_radius: 0.25, caster_height: 0.5, scale: 1.0, size: 64 };

/// The light's distance from the caster's centre, in caster sides.
const LIGHT_DISTANCE: f32 = 5.0;

/// The largest target the ray-traced truth is rendered at; beyond it only soundness is checked.
pub const TRUTH_MAX_SIZE: u32 = 1024;

/// The most pixels (a fraction) on which a technique and the tracer may see different surfaces.
pub const MAX_EXCLUDED: f64 = 0.02;

/// Along each axis, a step may change a technique's error (RMSE against the tracer) by at most
/// `2 × truth_step + 0.03`, where `truth_step` is the RMSE between the two truths.
///
/// Why: for a technique T and the truth R at neighbouring points a and b, the triangle
/// inequality gives |‖T_a − R_a‖ − ‖T_b − R_b‖| ≤ ‖T_a − T_b‖ + ‖R_a − R_b‖. A technique whose
/// image changes no more than the truth's (‖T_a − T_b‖ ≤ ‖R_a − R_b‖ + ε) stays within
/// `2 · truth_step + ε`. ε allows for what changes while the truth barely does: a hard edge
/// crossing pixel centres or shadow-map texels, the tracer's noise. On lavapipe the largest
/// excess over `2 · truth_step` at the small steps of the long grid was 0.017 (PCSS, caster
/// height 50 → 52.5), and under 0.01 elsewhere; ε = 0.03 keeps almost 2× headroom over that
/// and is still well under the 0.05–0.1 jump that a shadow lost or doubled makes at a small
/// step (a Parker mutant that drops its shadow above a light radius of 1.01 fails here: 0.167
/// → 0.220 against a bound of 0.039).
pub fn continuity_bound(truth_step: f64) -> f64 {
    2.0 * truth_step + 0.03
}

/// A parameter the sweep varies, the others staying at [`BASE`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Axis {
    Elevation,
    LightRadius,
    CasterHeight,
    Scale,
    Size,
}

impl Axis {
    pub const ALL: [Axis; 5] = [Axis::Elevation, Axis::LightRadius, Axis::CasterHeight, Axis::Scale, Axis::Size];

    pub fn name(self) -> &'static str {
        match self {
            Axis::Elevation => "elevation_deg",
            Axis::LightRadius => "light_radius",
            Axis::CasterHeight => "caster_height",
            Axis::Scale => "scale",
            Axis::Size => "size",
        }
    }

    /// This axis's value in `s`.
    pub fn value(self, s: &Setup) -> f32 {
        match self {
            Axis::Elevation => s.elevation_deg,
            Axis::LightRadius => s.light_radius,
            Axis::CasterHeight => s.caster_height,
            Axis::Scale => s.scale,
            Axis::Size => s.size as f32,
        }
    }

    /// The points of the sweep, in order: coarse points across the whole range (the long grid,
    /// for `bench --extremes`, has twice as many), each followed by a twin one small step away
    /// ([`Axis::nudge`]), so that continuity is checked both across the range and at small
    /// steps everywhere in it.
    pub fn grid(self, long: bool) -> Vec<Setup> {
        let coarse: &[f32] = match (self, long) {
            (Axis::Elevation, false) => &[90.0, 60.0, 40.0, 25.0, 15.0, 10.0, 6.0, 4.0, 2.5, 1.5, 1.0],
            (Axis::Elevation, true) => &[
                90.0, 75.0, 60.0, 50.0, 40.0, 30.0, 25.0, 20.0, 15.0, 12.0, 10.0, 8.0, 6.0, 5.0, 4.0, 3.0, 2.5, 2.0,
                1.5, 1.2, 1.0,
            ],
            (Axis::LightRadius, false) => &[0.0, 0.05, 0.15, 0.25, 0.5, 1.0, 1.5, 2.0],
            (Axis::LightRadius, true) => {
                &[0.0, 0.02, 0.05, 0.1, 0.15, 0.2, 0.25, 0.35, 0.5, 0.75, 1.0, 1.25, 1.5, 1.75, 2.0]
            }
            (Axis::CasterHeight, false) => &[0.0, 0.01, 0.05, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0, 30.0, 100.0],
            (Axis::CasterHeight, true) => &[
                0.0, 0.003, 0.01, 0.03, 0.06, 0.1, 0.2, 0.35, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0, 5.0, 7.0, 10.0, 20.0,
                30.0, 50.0, 100.0,
            ],
            (Axis::Scale, false) => &[1e-3, 1e-2, 1e-1, 1.0, 1e1, 1e2, 1e3, 1e4],
            (Axis::Scale, true) => &[1e-3, 3e-3, 1e-2, 3e-2, 1e-1, 3e-1, 1.0, 3.0, 1e1, 3e1, 1e2, 3e2, 1e3, 3e3, 1e4],
            (Axis::Size, false) => &[64.0, 128.0, 256.0, 4096.0],
            (Axis::Size, true) => &[64.0, 128.0, 256.0, 512.0, 1024.0, 2048.0, 4096.0],
        };
        coarse
            .iter()
            .flat_map(|&v| {
                let point = self.with(v);
                // Beyond the truth's size there is no error to be continuous; no twin.
                let twin = (self != Axis::Size || point.size < TRUTH_MAX_SIZE).then(|| self.with(self.nudge(v)));
                std::iter::once(point).chain(twin)
            })
            .collect()
    }

    /// A small step from `v`, inside the axis's range.
    fn nudge(self, v: f32) -> f32 {
        match self {
            Axis::Elevation => v * 0.97,
            Axis::LightRadius => v * 1.05 + 0.005,
            Axis::CasterHeight => v * 1.05 + 0.002,
            Axis::Scale => v * 1.1,
            Axis::Size => v + 8.0,
        }
    }

    /// [`BASE`] with this axis set to `v`.
    fn with(self, v: f32) -> Setup {
        let mut s = BASE;
        match self {
            Axis::Elevation => s.elevation_deg = v,
            Axis::LightRadius => s.light_radius = v,
            Axis::CasterHeight => s.caster_height = v,
            Axis::Scale => s.scale = v,
            Axis::Size => s.size = v as u32,
        }
        s
    }
}

impl Setup {
    /// The scene: the cube, the ground, the light, and a camera looking down at where the
    /// light's centre casts the cube's centre, so that the shadow stays in view however far
    /// the light or the cube moves it.
    pub fn scene(&self) -> Result<Scene> {
        let k = self.scale;
        let centre = Vec3::new(0.0, (self.caster_height + 0.5) * k, 0.0);
        let e = self.elevation_deg.to_radians();
        let towards_light = Vec3::new(e.cos(), e.sin(), 0.0);
        let shadow = centre - towards_light * (centre.y / towards_light.y);
        let mut cube = Object::new("cube", Arc::new(primitives::cuboid(Vec3::splat(k))?));
        cube.transform.position = centre;
        let scene = Scene {
            camera: Camera {
                position: shadow + Vec3::new(0.0, 6.0, 6.0) * k,
                target: shadow,
                up: Vec3::Y,
                projection: Projection::Perspective { fov_y_deg: 40.0 },
            },
            light: Light {
                position: centre + towards_light * LIGHT_DISTANCE * k,
                radius: self.light_radius * k,
                target: None,
            },
            ground: Some(Ground { height: 0.0, half_size: 200.0 * k }),
            objects: vec![cube],
            render: RenderSettings { width: self.size, height: self.size, ..RenderSettings::default() },
        };
        scene.validate()?;
        Ok(scene)
    }
}

/// One technique at one point of a sweep.
#[derive(Clone, Debug)]
pub struct ExtremeRow {
    pub axis: Axis,
    pub setup: Setup,
    pub technique: &'static str,
    /// Pixels whose raw V is NaN or infinite.
    pub non_finite: usize,
    /// The smallest and largest finite raw V.
    pub min_v: f32,
    pub max_v: f32,
    /// Against the ray tracer, where the truth was rendered (targets up to [`TRUTH_MAX_SIZE`]).
    pub metrics: Option<Metrics>,
    /// RMSE between this point's truth and the previous point's (None at the first point, and
    /// where either truth is missing or their sizes differ: then 0 is assumed, as the truth is
    /// the same picture).
    pub truth_step: Option<f64>,
}

/// Knobs for a technique in the sweep: its registry entry's [`SweepKnobs`] for the grid (the
/// offline techniques take fewer samples than their defaults, so that the short grids stay
/// quick on lavapipe; beyond [`TRUTH_MAX_SIZE`], where only soundness is checked, fewer still).
fn sweep_knobs(info: &TechniqueInfo, setup: &Setup, long: bool) -> Setting {
    let k = info.sweep_knobs;
    if setup.size > TRUTH_MAX_SIZE {
        k.huge
    } else if long {
        k.long
    } else {
        k.short
    }
}

/// Samples of the ray-traced truth.
fn truth_samples(long: bool) -> &'static str {
    if long { "1024" } else { "256" }
}

fn settings(setup: &Setup, info: &'static TechniqueInfo, knobs: &[(&str, &str)]) -> Result<FrameSettings> {
    let mut params = Params::defaults(info);
    params.apply(knobs.iter().copied())?;
    Ok(FrameSettings { width: setup.size, height: setup.size, params })
}

/// Runs `techniques` (all when empty) over `axis`'s grid on `engine`, which is switched to raw
/// visibility for the sweep and back afterwards, also when the sweep fails. `progress` hears
/// each render's label.
pub fn sweep(
    engine: &mut Engine,
    axis: Axis,
    long: bool,
    techniques: &[&'static TechniqueInfo],
    progress: &mut dyn FnMut(&str),
) -> Result<Vec<ExtremeRow>> {
    let techniques = if techniques.is_empty() { TECHNIQUES } else { techniques };
    engine.set_raw_visibility(true)?;
    let rows = sweep_raw(engine, axis, long, techniques, progress);
    engine.set_raw_visibility(false)?;
    rows
}

/// [`sweep`] on an engine already keeping raw visibility.
fn sweep_raw(
    engine: &mut Engine,
    axis: Axis,
    long: bool,
    techniques: &[&'static TechniqueInfo],
    progress: &mut dyn FnMut(&str),
) -> Result<Vec<ExtremeRow>> {
    let grid = axis.grid(long);
    let scenes: Vec<Scene> = grid.iter().map(Setup::scene).collect::<Result<_>>()?;
    let mut truths: Vec<Option<Capture>> = Vec::with_capacity(grid.len());
    for (setup, scene) in grid.iter().zip(&scenes) {
        progress(&format!("{} = {}: truth", axis.name(), axis.value(setup)));
        truths.push(if setup.size <= TRUTH_MAX_SIZE {
            let truth = settings(setup, ground_truth(Runs::Cpu), &[("samples", truth_samples(long))])?;
            Some(engine.render_and_capture(scene, &truth)?)
        } else {
            None
        });
    }
    let mut truth_steps = vec![None];
    for pair in truths.windows(2) {
        truth_steps.push(match (&pair[0], &pair[1]) {
            (Some(a), Some(b)) if (a.width, a.height) == (b.width, b.height) => Some(Metrics::between(b, a)?.rmse),
            _ => None,
        });
    }
    let mut rows = Vec::new();
    for &info in techniques {
        for (i, (setup, scene)) in grid.iter().zip(&scenes).enumerate() {
            progress(&format!("{} = {}: {}", axis.name(), axis.value(setup), info.name));
            let knobs = sweep_knobs(info, setup, long);
            let capture = engine.render_and_capture(scene, &settings(setup, info, knobs)?)?;
            let raw = capture.raw_visibility.as_deref().expect("raw visibility is on");
            let finite = raw.iter().copied().filter(|v| v.is_finite());
            let metrics = truths[i].as_ref().map(|t| Metrics::between(&capture, t)).transpose()?;
            rows.push(ExtremeRow {
                axis,
                setup: *setup,
                technique: info.name,
                non_finite: raw.iter().filter(|v| !v.is_finite()).count(),
                min_v: finite.clone().fold(f32::INFINITY, f32::min),
                max_v: finite.fold(f32::NEG_INFINITY, f32::max),
                metrics,
                truth_step: truth_steps[i],
            });
        }
    }
    Ok(rows)
}

/// What is wrong in a sweep's rows (in the order [`sweep`] made them), one line each.
pub fn problems(rows: &[ExtremeRow]) -> Vec<String> {
    let mut out = Vec::new();
    let at = |r: &ExtremeRow| format!("{} at {} = {}", r.technique, r.axis.name(), r.axis.value(&r.setup));
    for r in rows {
        if r.non_finite > 0 {
            out.push(format!("{}: {} pixels of V are NaN or infinite", at(r), r.non_finite));
        }
        if r.min_v < 0.0 || r.max_v > 1.0 {
            out.push(format!("{}: V spans [{}, {}], outside [0, 1]", at(r), r.min_v, r.max_v));
        }
        if let Some(m) = &r.metrics {
            let excluded = m.excluded as f64 / (m.pixels + m.excluded).max(1) as f64;
            if excluded > MAX_EXCLUDED {
                out.push(format!(
                    "{}: sees other surfaces than the tracer at {:.1}% of pixels",
                    at(r),
                    100.0 * excluded
                ));
            }
        }
    }
    for pair in rows.windows(2) {
        let (a, b) = (&pair[0], &pair[1]);
        if a.technique != b.technique || a.axis != b.axis {
            continue;
        }
        if let (Some(ma), Some(mb)) = (&a.metrics, &b.metrics) {
            let bound = continuity_bound(b.truth_step.unwrap_or(0.0));
            let step = (mb.rmse - ma.rmse).abs();
            if step > bound {
                out.push(format!(
                    "{} → {}: RMSE jumps {:.4} → {:.4} (bound {:.4})",
                    at(a),
                    b.axis.value(&b.setup),
                    ma.rmse,
                    mb.rmse,
                    bound
                ));
            }
        }
    }
    out
}

/// The rows as CSV.
pub fn write_csv(rows: &[ExtremeRow], path: &Path) -> Result<()> {
    let mut out = String::from("axis,value,technique,non_finite,min_v,max_v,rmse,penumbra_rmse,excluded,truth_step\n");
    for r in rows {
        let m = r.metrics.as_ref();
        let opt = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v:.5}"));
        let _ = writeln!(
            out,
            "{},{},{},{},{},{},{},{},{},{}",
            r.axis.name(),
            r.axis.value(&r.setup),
            r.technique,
            r.non_finite,
            r.min_v,
            r.max_v,
            opt(m.map(|m| m.rmse)),
            opt(m.map(|m| m.penumbra_rmse)),
            m.map_or(String::new(), |m| m.excluded.to_string()),
            opt(r.truth_step)
        );
    }
    std::fs::write(path, out).map_err(|error| Error::Io { path: path.into(), error })
}
