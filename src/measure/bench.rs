//! The speed/accuracy sweep behind `softshadow bench`: what each setting of each technique
//! costs (GPU ms per pass, CPU ms per frame) and how wrong it is against the reference, per
//! scene, with the Pareto-optimal rows marked; written as CSV and a Markdown report.

use std::fmt::Write as _;
use std::path::Path;

use crate::error::{Error, Result};
use crate::frame::Surfaces;
use crate::measure::{Metrics, TimingReport};
use crate::renderer::Capture;
use crate::technique::registry::{self, Setting};
use crate::technique::{TECHNIQUES, TechniqueInfo, plateau, shadow_map, smoothie};

/// One scene × technique × setting.
#[derive(Clone, Debug)]
pub struct BenchRow {
    pub scene: String,
    pub technique: String,
    /// The knobs set, `key=value` separated by spaces; empty for the defaults.
    pub setting: String,
    pub timings: TimingReport,
    pub metrics: Metrics,
    /// No other row of the scene is both cheaper and more accurate (penumbra RMSE).
    pub pareto: bool,
}

/// The settings swept, from each technique's registry entry: every benched technique's first
/// setting, then (without `quick`) the rest, so the quick sweep is a prefix of the full one.
pub fn sweep(quick: bool) -> Vec<(&'static TechniqueInfo, Setting)> {
    let first = TECHNIQUES.iter().filter_map(|t| t.bench.first().map(|s| (*t, *s)));
    let rest = TECHNIQUES.iter().flat_map(|t| t.bench.iter().skip(1).map(move |s| (*t, *s)));
    if quick { first.collect() } else { first.chain(rest).collect() }
}

/// Rounds a scene's timed frames are split into, each row's share of a round rendered after the
/// other rows' of the round before: a slow minute of a shared machine (measured here: a
/// scene's identical prepass at 5.5–10.4 ms from one row to the next) then lands on every row
/// of the scene alike instead of on whichever ran through it, which is what ratios between
/// rows need.
pub const ROUNDS: usize = 4;

/// Each round's frames: `frames` split as evenly as they go into at most [`ROUNDS`] rounds of
/// at least one frame each.
pub fn round_frames(frames: usize) -> Vec<usize> {
    let rounds = ROUNDS.min(frames);
    (0..rounds).map(|r| frames / rounds + usize::from(r < frames % rounds)).collect()
}

/// `key=value` pairs separated by spaces, as [`BenchRow::setting`] holds them.
pub fn setting_label(setting: Setting) -> String {
    setting.iter().map(|(k, v)| format!("{k}={v}")).collect::<Vec<_>>().join(" ")
}

/// A cost goal from a technique's registry entry, as bench rows name it: `technique
/// [setting]`'s frame costs at most `max_ratio` times the `baseline [baseline_setting]` frame,
/// compared per scene within one run.
#[derive(Clone, Debug)]
pub struct CostGoal {
    pub technique: &'static str,
    pub setting: String,
    pub baseline: &'static str,
    pub baseline_setting: String,
    pub max_ratio: f64,
}

/// Goals between settings beyond each entry's own `cost_goal`: (technique, goal).
pub const COST_GOALS: &[(&TechniqueInfo, registry::CostGoal)] = &[
    // Issue 20: the centred forms (the defaults) cost little more than the papers' outer-only
    // forms, well under PCSS (16 + 16), and a smoothie of either form about what a hard map of
    // the same size costs.
    (&plateau::INFO, goal(&[], &plateau::INFO, plateau::OUTER_ONLY, 1.15)),
    (&plateau::INFO, goal(&[], &shadow_map::PCSS, &[], 0.7)),
    (&smoothie::INFO, goal(&[], &smoothie::INFO, smoothie::OUTER_ONLY, 1.15)),
    (&smoothie::INFO, goal(&[], &shadow_map::PCSS, &[], 0.7)),
    (&smoothie::INFO, goal(&[], &shadow_map::INFO, &[("shadow_map_size", "1024")], 1.15)),
    (&smoothie::INFO, goal(smoothie::OUTER_ONLY, &shadow_map::INFO, &[("shadow_map_size", "1024")], 1.15)),
];

const fn goal(
    setting: Setting,
    baseline: &'static TechniqueInfo,
    baseline_setting: Setting,
    max_ratio: f64,
) -> registry::CostGoal {
    registry::CostGoal { setting, baseline, baseline_setting, max_ratio }
}

/// Every technique's cost goal, in registry order, then [`COST_GOALS`].
pub fn registry_cost_goals() -> Vec<CostGoal> {
    let entries = TECHNIQUES.iter().filter_map(|t| t.cost_goal.map(|g| (*t, g)));
    entries
        .chain(COST_GOALS.iter().copied())
        .map(|(t, g)| CostGoal {
            technique: t.name,
            setting: setting_label(g.setting),
            baseline: g.baseline.name,
            baseline_setting: setting_label(g.baseline_setting),
            max_ratio: g.max_ratio,
        })
        .collect()
}

impl CostGoal {
    /// The goal as a column heading, e.g. `smoothie / shadow-map shadow_map_size=1024 ≤ 1.3`.
    pub fn label(&self) -> String {
        let side = |t: &str, s: &str| if s.is_empty() { t.to_string() } else { format!("{t} {s}") };
        format!(
            "{} / {} ≤ {}",
            side(self.technique, &self.setting),
            side(self.baseline, &self.baseline_setting),
            self.max_ratio
        )
    }

    /// Per scene holding both rows, the ratio of their median GPU ms, in the rows' scene order.
    pub fn ratios<'a>(&self, rows: &'a [BenchRow]) -> Vec<(&'a str, f64)> {
        let ms = |scene: &str, technique: &str, setting: &str| {
            rows.iter()
                .find(|r| r.scene == scene && r.technique == technique && r.setting == setting)
                .map(|r| r.timings.gpu_ms_total_median)
        };
        scenes(rows)
            .into_iter()
            .filter_map(|scene| {
                let of = ms(scene, self.technique, &self.setting)?;
                let base = ms(scene, self.baseline, &self.baseline_setting)?;
                Some((scene, of / base))
            })
            .collect()
    }

    /// One line for the terminal, e.g. `smoothie / shadow-map … ≤ 1.3: met on 9/10 scenes
    /// (0.95–1.35)`; `None` when no scene has both rows.
    pub fn outcome(&self, rows: &[BenchRow]) -> Option<String> {
        let ratios: Vec<f64> = self.ratios(rows).into_iter().map(|(_, r)| r).collect();
        let lo = ratios.iter().copied().reduce(f64::min)?;
        let hi = ratios.iter().copied().reduce(f64::max)?;
        let met = ratios.iter().filter(|r| **r <= self.max_ratio).count();
        Some(format!("{}: met on {met}/{} scenes ({lo:.2}–{hi:.2})", self.label(), ratios.len()))
    }
}

/// The cost goals as a table, scene by scene, with how many scenes meet each; empty when no
/// goal has both of its rows in `rows`.
pub fn cost_goal_table(goals: Vec<CostGoal>, rows: &[BenchRow]) -> String {
    let goals: Vec<(CostGoal, Vec<(&str, f64)>)> = goals
        .into_iter()
        .map(|g| {
            let r = g.ratios(rows);
            (g, r)
        })
        .filter(|(_, r)| !r.is_empty())
        .collect();
    if goals.is_empty() {
        return String::new();
    }
    let mut out =
        String::from("## Cost goals\n\nRatios of median GPU ms within this run; ✓ where the goal holds.\n\n| scene |");
    for (g, _) in &goals {
        let _ = write!(out, " {} |", g.label());
    }
    let _ = write!(out, "\n|---|{}\n", "---|".repeat(goals.len()));
    for scene in scenes(rows) {
        let _ = write!(out, "| {scene} |");
        for (g, ratios) in &goals {
            match ratios.iter().find(|(s, _)| *s == scene) {
                Some((_, r)) => {
                    let _ = write!(out, " {r:.2} {} |", if *r <= g.max_ratio { "✓" } else { "✗" });
                }
                None => out += " |",
            }
        }
        out += "\n";
    }
    out += "| met |";
    for (g, ratios) in &goals {
        let _ = write!(out, " {}/{} |", ratios.iter().filter(|(_, r)| *r <= g.max_ratio).count(), ratios.len());
    }
    out + "\n\n"
}

/// The scenes of `rows`, in their order (the sweep keeps each scene's rows together).
fn scenes(rows: &[BenchRow]) -> Vec<&str> {
    let mut scenes: Vec<&str> = rows.iter().map(|r| r.scene.as_str()).collect();
    scenes.dedup();
    scenes
}

/// Marks the rows no other row of the same scene dominates (cheaper and no less accurate, or
/// more accurate and no dearer).
pub fn mark_pareto(rows: &mut [BenchRow]) {
    let keys: Vec<(String, f64, f64)> =
        rows.iter().map(|r| (r.scene.clone(), r.timings.gpu_ms_total_median, r.metrics.penumbra_rmse)).collect();
    for (i, row) in rows.iter_mut().enumerate() {
        let (scene, ms, err) = &keys[i];
        row.pareto = !keys
            .iter()
            .enumerate()
            .any(|(j, (s, m, e))| j != i && s == scene && m <= ms && e <= err && (m < ms || e < err));
    }
}

pub fn write_csv(rows: &[BenchRow], path: &Path) -> Result<()> {
    let mut out = String::from(
        "scene,technique,setting,gpu_ms_total_median,gpu_ms_total_p95,cpu_ms_median,cpu_ms_technique,rmse,mae,max_abs,p99_abs,\
         penumbra_rmse,leak_rate,dark_rate,mean_bias,pixels,excluded,pareto,passes\n",
    );
    for r in rows {
        let m = &r.metrics;
        let passes: Vec<String> =
            r.timings.passes.iter().map(|p| format!("{}={:.3}", p.name, p.gpu_ms_median)).collect();
        let _ = writeln!(
            out,
            "{},{},\"{}\",{:.4},{:.4},{:.4},{:.4},{:.5},{:.5},{:.5},{:.5},{:.5},{:.5},{:.5},{:.5},{},{},{},\"{}\"",
            r.scene,
            r.technique,
            r.setting,
            r.timings.gpu_ms_total_median,
            r.timings.gpu_ms_total_p95,
            r.timings.cpu_ms.get("record").copied().unwrap_or(0.0),
            r.timings.cpu_ms.get("technique").copied().unwrap_or(0.0),
            m.rmse,
            m.mae,
            m.max_abs,
            m.p99_abs,
            m.penumbra_rmse,
            m.leak_rate,
            m.dark_rate,
            m.mean_bias,
            m.pixels,
            m.excluded,
            r.pareto,
            passes.join(" ")
        );
    }
    std::fs::write(path, out).map_err(|error| Error::Io { path: path.into(), error })
}

/// Per scene, a table sorted by cost with the Pareto-optimal rows marked.
pub fn write_report(rows: &[BenchRow], reference: &str, path: &Path) -> Result<()> {
    let mut out = String::from("# softshadow bench\n\n");
    if let Some(r) = rows.first() {
        let t = &r.timings;
        let _ = writeln!(
            out,
            "{}, {}; {}x{}, GPU ms: median (p95) over {} frames, timed in up to {ROUNDS} rounds interleaved \
             across each scene's rows, each after warm-up. Error against {reference}. \
             ★ marks the Pareto-optimal rows (no other row both cheaper and more accurate in the penumbra).\n",
            t.device, t.driver, t.width, t.height, t.frames
        );
    }
    out += &summary(rows);
    out += &cost_goal_table(registry_cost_goals(), rows);
    for scene in scenes(rows) {
        let mut of_scene: Vec<&BenchRow> = rows.iter().filter(|r| r.scene == scene).collect();
        of_scene.sort_by(|a, b| a.timings.gpu_ms_total_median.total_cmp(&b.timings.gpu_ms_total_median));
        let _ = writeln!(out, "## {scene}\n");
        out += "| | technique | setting | GPU ms | technique CPU ms | RMSE | penumbra RMSE | leak | dark |\n";
        out += "|---|---|---|---|---|---|---|---|---|\n";
        for r in of_scene {
            let (t, m) = (&r.timings, &r.metrics);
            let _ = writeln!(
                out,
                "| {} | {} | {} | {:.2} ({:.2}) | {:.3} | {:.4} | {:.4} | {:.4} | {:.4} |",
                if r.pareto { "★" } else { "" },
                r.technique,
                if r.setting.is_empty() { "defaults" } else { &r.setting },
                t.gpu_ms_total_median,
                t.gpu_ms_total_p95,
                t.cpu_ms.get("technique").copied().unwrap_or(0.0),
                m.rmse,
                m.penumbra_rmse,
                m.leak_rate,
                m.dark_rate
            );
        }
        out += "\n";
    }
    std::fs::write(path, out).map_err(|error| Error::Io { path: path.into(), error })
}

/// Per technique and setting, the medians over the scenes and on how many scenes the row is
/// Pareto-optimal, sorted by median cost.
fn summary(rows: &[BenchRow]) -> String {
    let mut keys: Vec<(&str, &str)> = Vec::new();
    for r in rows {
        if !keys.contains(&(r.technique.as_str(), r.setting.as_str())) {
            keys.push((&r.technique, &r.setting));
        }
    }
    let median = |v: Vec<f64>| super::timings::percentile(&v, 0.5);
    let mut lines: Vec<(f64, String)> = keys
        .iter()
        .map(|&(technique, setting)| {
            let of: Vec<&BenchRow> = rows.iter().filter(|r| r.technique == technique && r.setting == setting).collect();
            let ms = median(of.iter().map(|r| r.timings.gpu_ms_total_median).collect());
            let line = format!(
                "| {technique} | {} | {ms:.2} | {:.4} | {:.4} | {}/{} |\n",
                if setting.is_empty() { "defaults" } else { setting },
                median(of.iter().map(|r| r.metrics.rmse).collect()),
                median(of.iter().map(|r| r.metrics.penumbra_rmse).collect()),
                of.iter().filter(|r| r.pareto).count(),
                of.len()
            );
            (ms, line)
        })
        .collect();
    lines.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut out = String::from(
        "## All scenes\n\nMedians over the scenes; the last column counts the scenes where the row is Pareto-optimal.\n\n\
         | technique | setting | GPU ms | RMSE | penumbra RMSE | Pareto |\n|---|---|---|---|---|---|\n",
    );
    lines.into_iter().for_each(|(_, line)| out += &line);
    out + "\n"
}

/// Stores a reference capture's visibility and surfaces (the colour is not needed).
pub fn save_reference(capture: &Capture, path: &Path) -> Result<()> {
    let s = &capture.surfaces;
    let mut bytes = Vec::new();
    bytes.extend(capture.width.to_le_bytes());
    bytes.extend(capture.height.to_le_bytes());
    for i in 0..capture.visibility.len() {
        bytes.extend(capture.visibility[i].to_le_bytes());
        bytes.extend(s.depth[i].to_le_bytes());
        for c in s.normal[i].to_array() {
            bytes.extend(c.to_le_bytes());
        }
        // Bit 0: receives, bit 1: casts (caches written before casts was kept read as 0).
        bytes.push(u8::from(s.receives[i]) | (u8::from(s.casts[i]) << 1));
    }
    std::fs::write(path, bytes).map_err(|error| Error::Io { path: path.into(), error })
}

/// A capture stored by [`save_reference`], if `path` holds one of `width` × `height`.
pub fn load_reference(path: &Path, width: u32, height: u32) -> Option<Capture> {
    let bytes = std::fs::read(path).ok()?;
    const PIXEL: usize = 2 + 4 + 12 + 1;
    let n = width as usize * height as usize;
    let header = [width.to_le_bytes(), height.to_le_bytes()].concat();
    if bytes.len() != 8 + n * PIXEL || bytes[..8] != header[..] {
        return None;
    }
    let f32_at = |b: &[u8]| f32::from_le_bytes([b[0], b[1], b[2], b[3]]);
    let mut capture = Capture {
        width,
        height,
        color: vec![0; n * 4],
        visibility: Vec::with_capacity(n),
        raw_visibility: None,
        surfaces: Surfaces {
            depth: Vec::with_capacity(n),
            normal: Vec::with_capacity(n),
            receives: Vec::with_capacity(n),
            casts: Vec::with_capacity(n),
        },
    };
    for p in bytes[8..].chunks_exact(PIXEL) {
        capture.visibility.push(u16::from_le_bytes([p[0], p[1]]));
        capture.surfaces.depth.push(f32_at(&p[2..]));
        capture.surfaces.normal.push(glam::Vec3::new(f32_at(&p[6..]), f32_at(&p[10..]), f32_at(&p[14..])));
        capture.surfaces.receives.push(p[18] & 1 != 0);
        capture.surfaces.casts.push(p[18] & 2 != 0);
    }
    Some(capture)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(scene: &str, technique: &str, setting: &str, ms: f64) -> BenchRow {
        BenchRow {
            scene: scene.into(),
            technique: technique.into(),
            setting: setting.into(),
            timings: TimingReport { gpu_ms_total_median: ms, ..Default::default() },
            metrics: Metrics::default(),
            pareto: false,
        }
    }

    /// Both sides of every goal are settings the full sweep runs, so bench can check them.
    #[test]
    fn rounds_split_the_frames_evenly_and_never_empty() {
        for frames in 1..50 {
            let rounds = round_frames(frames);
            assert_eq!(rounds.iter().sum::<usize>(), frames);
            assert_eq!(rounds.len(), ROUNDS.min(frames));
            assert!(rounds.iter().all(|&n| n >= 1 && n + 1 >= rounds[0]), "{frames}: {rounds:?}");
        }
    }

    #[test]
    fn every_cost_goal_compares_benched_settings() {
        let swept: Vec<(&str, String)> = sweep(false).iter().map(|(t, s)| (t.name, setting_label(s))).collect();
        for g in registry_cost_goals() {
            for side in [(g.technique, &g.setting), (g.baseline, &g.baseline_setting)] {
                assert!(
                    swept.iter().any(|(t, s)| *t == side.0 && s == side.1),
                    "{}: {side:?} is not benched",
                    g.label()
                );
            }
        }
    }

    #[test]
    fn cost_goals_compare_each_scene_with_its_own_baseline() {
        let rows = [
            row("a", "base", "", 10.0),
            row("a", "base", "size=1024", 5.0),
            row("a", "soft", "", 6.0),
            row("a", "soft", "bits=16", 1.0),
            row("b", "base", "size=1024", 4.0),
            row("b", "soft", "", 6.0),
            row("c", "soft", "", 1.0),
        ];
        let goal = |technique| CostGoal {
            technique,
            setting: String::new(),
            baseline: "base",
            baseline_setting: "size=1024".into(),
            max_ratio: 1.3,
        };
        let soft = goal("soft");
        // Scene c has no baseline row, so it has no ratio rather than a made-up one.
        assert_eq!(soft.ratios(&rows), vec![("a", 1.2), ("b", 1.5)]);
        assert_eq!(soft.outcome(&rows).unwrap(), "soft / base size=1024 ≤ 1.3: met on 1/2 scenes (1.20–1.50)");
        // No rows of `other`: that goal is left out of the table, not shown as failed.
        assert_eq!(goal("other").outcome(&rows), None);
        let table = cost_goal_table(vec![goal("other"), soft.clone()], &rows);
        assert!(!table.contains("other"), "{table}");
        for line in ["| a | 1.20 ✓ |", "| b | 1.50 ✗ |", "| c | |", "| met | 1/2 |"] {
            assert!(table.lines().any(|l| l == line), "{line} in\n{table}");
        }
        assert_eq!(cost_goal_table(vec![soft], &rows[..1]), "");
    }
}
