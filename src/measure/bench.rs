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
    /// Each round's median GPU ms ([`ROUNDS`]), in order: how far a cost ratio between two
    /// rows of the scene moved from round to round.
    pub round_ms: Vec<f64>,
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

/// The order a round renders `runs` in: each goal's row beside its baseline's (within three
/// rows for the registry's goals), the rest after. A round of a scene takes 10–20 s on
/// lavapipe; rows swept apart met different phases of a shared machine, and a pair's ratio
/// moved by up to 2× from round to round (smoothie against the 1024² map on `contact`:
/// 0.78–1.81) while an identical prepass moved as much. Rows side by side share more of them.
/// It narrows the spread, not removes it: the machine also changes speed within a second (the
/// same pair, adjacent: 1.16–1.63 in one run). Odd rounds run the order backwards, so a steady
/// drift in speed favours neither side of a pair.
pub fn timing_order(runs: &[(&'static TechniqueInfo, Setting)], goals: &[Goal]) -> Vec<usize> {
    let find = |t: &str, s: &str| (0..runs.len()).find(|&i| runs[i].0.name == t && setting_label(runs[i].1) == s);
    let pairs: Vec<(usize, usize)> = goals
        .iter()
        .filter_map(|g| Some((find(g.technique, &g.setting)?, find(g.baseline, &g.baseline_setting)?)))
        .collect();
    // Depth first through the goals' graph: a row, then each row it is compared with.
    fn visit(i: usize, pairs: &[(usize, usize)], order: &mut Vec<usize>) {
        if order.contains(&i) {
            return;
        }
        order.push(i);
        for &(a, b) in pairs {
            if a == i {
                visit(b, pairs, order);
            } else if b == i {
                visit(a, pairs, order);
            }
        }
    }
    let mut order = Vec::with_capacity(runs.len());
    for i in pairs.iter().map(|p| p.0).chain(0..runs.len()) {
        visit(i, &pairs, &mut order);
    }
    order
}

/// `key=value` pairs separated by spaces, as [`BenchRow::setting`] holds them.
pub fn setting_label(setting: Setting) -> String {
    setting.iter().map(|(k, v)| format!("{k}={v}")).collect::<Vec<_>>().join(" ")
}

/// What a goal compares between a row and its baseline row, scene by scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Measure {
    /// Median GPU ms: the row's at most `max_ratio` times the baseline's.
    Cost { max_ratio: f64 },
    /// Light-leak rate: the row's no higher than the baseline's (issue 20: a centred penumbra
    /// may not leak where the papers' outer-only form does not).
    Leaks,
}

/// A goal as bench rows name it: `technique [setting]` against `baseline [baseline_setting]`,
/// compared per scene within one run.
#[derive(Clone, Debug)]
pub struct Goal {
    pub technique: &'static str,
    pub setting: String,
    pub baseline: &'static str,
    pub baseline_setting: String,
    pub measure: Measure,
}

/// Cost goals between settings beyond each entry's own `cost_goal`: (technique, goal).
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

/// Issue 20's leak rule: each centred default leaks no more than its outer-only form, on every
/// scene. (technique, the outer-only setting.)
pub const LEAK_GOALS: &[(&TechniqueInfo, Setting)] =
    &[(&plateau::INFO, plateau::OUTER_ONLY), (&smoothie::INFO, smoothie::OUTER_ONLY)];

const fn goal(
    setting: Setting,
    baseline: &'static TechniqueInfo,
    baseline_setting: Setting,
    max_ratio: f64,
) -> registry::CostGoal {
    registry::CostGoal { setting, baseline, baseline_setting, max_ratio }
}

/// Every technique's cost goal, in registry order, then [`COST_GOALS`].
pub fn registry_cost_goals() -> Vec<Goal> {
    let entries = TECHNIQUES.iter().filter_map(|t| t.cost_goal.map(|g| (*t, g)));
    entries
        .chain(COST_GOALS.iter().copied())
        .map(|(t, g)| Goal {
            technique: t.name,
            setting: setting_label(g.setting),
            baseline: g.baseline.name,
            baseline_setting: setting_label(g.baseline_setting),
            measure: Measure::Cost { max_ratio: g.max_ratio },
        })
        .collect()
}

/// [`LEAK_GOALS`] as goals.
pub fn leak_goals() -> Vec<Goal> {
    LEAK_GOALS
        .iter()
        .map(|&(t, outer)| Goal {
            technique: t.name,
            setting: String::new(),
            baseline: t.name,
            baseline_setting: setting_label(outer),
            measure: Measure::Leaks,
        })
        .collect()
}

/// A scene's name, its row and its baseline row under one goal.
pub type ScenePair<'a> = (&'a str, &'a BenchRow, &'a BenchRow);

impl Goal {
    /// The goal as a column heading, e.g. `smoothie / shadow-map shadow_map_size=1024 ≤ 1.3`
    /// or `plateau leaks ≤ plateau penumbra=outer falloff=linear`.
    pub fn label(&self) -> String {
        let side = |t: &str, s: &str| if s.is_empty() { t.to_string() } else { format!("{t} {s}") };
        let (of, base) = (side(self.technique, &self.setting), side(self.baseline, &self.baseline_setting));
        match self.measure {
            Measure::Cost { max_ratio } => format!("{of} / {base} ≤ {max_ratio}"),
            Measure::Leaks => format!("{of} leaks ≤ {base}"),
        }
    }

    /// What the goal compares in a row.
    fn value(&self, row: &BenchRow) -> f64 {
        match self.measure {
            Measure::Cost { .. } => row.timings.gpu_ms_total_median,
            Measure::Leaks => row.metrics.leak_rate,
        }
    }

    /// Per scene holding both rows, the row and its baseline, in the rows' scene order.
    pub fn pairs<'a>(&self, rows: &'a [BenchRow]) -> Vec<ScenePair<'a>> {
        let find = |scene: &str, technique: &str, setting: &str| {
            rows.iter().find(|r| r.scene == scene && r.technique == technique && r.setting == setting)
        };
        scenes(rows)
            .into_iter()
            .filter_map(|scene| {
                let of = find(scene, self.technique, &self.setting)?;
                let base = find(scene, self.baseline, &self.baseline_setting)?;
                Some((scene, of, base))
            })
            .collect()
    }

    pub fn met(&self, of: &BenchRow, base: &BenchRow) -> bool {
        let (of, base) = (self.value(of), self.value(base));
        match self.measure {
            Measure::Cost { max_ratio } => of <= max_ratio * base,
            Measure::Leaks => of <= base,
        }
    }

    /// A table cell: the ratio of a cost; a leak rule's leaking pixels, which rates of a few
    /// in 10⁵ would hide, and in brackets the pixels each form darkens by as much: the
    /// outer-only form keeps the whole hard shadow dark, so a hard edge a texel off costs it
    /// darkness where the centred form, V = ½ on the edge, errs either way.
    fn cell(&self, of: &BenchRow, base: &BenchRow) -> String {
        let mark = if self.met(of, base) { "✓" } else { "✗" };
        let pixels = |rate: f64, r: &BenchRow| (rate * r.metrics.pixels as f64).round();
        let leaking = |r: &BenchRow| pixels(r.metrics.leak_rate, r);
        let darkened = |r: &BenchRow| pixels(r.metrics.dark_rate, r);
        match self.measure {
            Measure::Cost { .. } => {
                let ratio = format!("{:.2} {mark}", self.value(of) / self.value(base));
                match round_ratios(of, base) {
                    Some((least, most)) => format!("{ratio} ({least:.2}–{most:.2})"),
                    None => ratio,
                }
            }
            Measure::Leaks => {
                let (leaks, dark) = ([of, base].map(leaking), [of, base].map(darkened));
                format!("{} vs {} px {mark} (darker: {} vs {})", leaks[0], leaks[1], dark[0], dark[1])
            }
        }
    }

    /// One line for the terminal, e.g. `smoothie / shadow-map … ≤ 1.3: met on 9/10 scenes
    /// (0.95–1.35)`; `None` when no scene has both rows.
    pub fn outcome(&self, rows: &[BenchRow]) -> Option<String> {
        let values = self.pairs(rows);
        let met = values.iter().filter(|(_, of, base)| self.met(of, base)).count();
        let range = match self.measure {
            Measure::Cost { .. } => {
                let ratios = values.iter().map(|(_, of, base)| self.value(of) / self.value(base));
                let lo = ratios.clone().reduce(f64::min)?;
                format!(" ({lo:.2}–{:.2})", ratios.reduce(f64::max)?)
            }
            Measure::Leaks if values.is_empty() => return None,
            Measure::Leaks => String::new(),
        };
        Some(format!("{}: met on {met}/{} scenes{range}", self.label(), values.len()))
    }
}

/// Goals as a table under `heading`, scene by scene, with how many scenes meet each; empty when
/// no goal has both of its rows in `rows`.
pub fn goal_table(heading: &str, goals: Vec<Goal>, rows: &[BenchRow]) -> String {
    let goals: Vec<(Goal, Vec<ScenePair<'_>>)> = goals
        .into_iter()
        .map(|g| {
            let v = g.pairs(rows);
            (g, v)
        })
        .filter(|(_, v)| !v.is_empty())
        .collect();
    if goals.is_empty() {
        return String::new();
    }
    let mut out = format!("{heading}\n\n| scene |");
    for (g, _) in &goals {
        let _ = write!(out, " {} |", g.label());
    }
    let _ = write!(out, "\n|---|{}\n", "---|".repeat(goals.len()));
    for scene in scenes(rows) {
        let _ = write!(out, "| {scene} |");
        for (g, values) in &goals {
            match values.iter().find(|(s, ..)| *s == scene) {
                Some((_, of, base)) => {
                    let _ = write!(out, " {} |", g.cell(of, base));
                }
                None => out += " |",
            }
        }
        out += "\n";
    }
    out += "| met |";
    for (g, values) in &goals {
        let met = values.iter().filter(|(_, of, base)| g.met(of, base)).count();
        let _ = write!(out, " {met}/{} |", values.len());
    }
    out + "\n\n"
}

/// The least and the greatest ratio of `of`'s GPU ms to `base`'s within one round, over the
/// rounds both were timed in; none with fewer than two.
fn round_ratios(of: &BenchRow, base: &BenchRow) -> Option<(f64, f64)> {
    let ratios: Vec<f64> = of.round_ms.iter().zip(&base.round_ms).map(|(o, b)| o / b).collect();
    (ratios.len() >= 2).then(|| ratios.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &r| (lo.min(r), hi.max(r))))
}

/// Headings of the report's goal tables.
pub const COST_HEADING: &str = "## Cost goals\n\nRatios of median GPU ms within this run, each goal's two rows timed side \
     by side in every round; ✓ where the goal holds; in brackets the least and the greatest of the same ratio within \
     one round, how far this machine's noise moved it.";
pub const LEAK_HEADING: &str = "## Leak rule\n\nLight-leak rates (V above the reference by more than 0.1), the centred \
     default against the papers' outer-only form; ✓ where it leaks no more. In brackets the pixels below the \
     reference by more than 0.1, which the outer-only form's whole-umbra hard shadow trades its leaks for.";

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
         penumbra_rmse,leak_rate,dark_rate,mean_bias,pixels,excluded,pareto,passes,round_ms\n",
    );
    for r in rows {
        let m = &r.metrics;
        let passes: Vec<String> =
            r.timings.passes.iter().map(|p| format!("{}={:.3}", p.name, p.gpu_ms_median)).collect();
        let rounds: Vec<String> = r.round_ms.iter().map(|ms| format!("{ms:.3}")).collect();
        let _ = writeln!(
            out,
            "{},{},\"{}\",{:.4},{:.4},{:.4},{:.4},{:.5},{:.5},{:.5},{:.5},{:.5},{:.5},{:.5},{:.5},{},{},{},\"{}\",\"{}\"",
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
            passes.join(" "),
            rounds.join(" ")
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
    out += &goal_table(COST_HEADING, registry_cost_goals(), rows);
    out += &goal_table(LEAK_HEADING, leak_goals(), rows);
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
            round_ms: Vec::new(),
            metrics: Metrics::default(),
            pareto: false,
        }
    }

    #[test]
    fn rounds_split_the_frames_evenly_and_never_empty() {
        for frames in 1..50 {
            let rounds = round_frames(frames);
            assert_eq!(rounds.iter().sum::<usize>(), frames);
            assert_eq!(rounds.len(), ROUNDS.min(frames));
            assert!(rounds.iter().all(|&n| n >= 1 && n + 1 >= rounds[0]), "{frames}: {rounds:?}");
        }
    }

    /// Every row is timed once a round, and each goal's two rows are rendered within three
    /// rows of each other: about a second apart, not up to a whole round (10–20 s).
    #[test]
    fn a_round_times_each_goal_s_rows_side_by_side() {
        let runs = sweep(false);
        let goals: Vec<Goal> = registry_cost_goals().into_iter().chain(leak_goals()).collect();
        let order = timing_order(&runs, &goals);
        let mut sorted = order.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..runs.len()).collect::<Vec<_>>(), "every row once");
        let place = |t: &str, s: &str| {
            let i = runs.iter().position(|(r, rs)| r.name == t && setting_label(rs) == s).expect("benched");
            order.iter().position(|&o| o == i).expect("ordered") as isize
        };
        for g in &goals {
            let apart = (place(g.technique, &g.setting) - place(g.baseline, &g.baseline_setting)).abs();
            assert!(apart <= 3, "{}: {apart} rows apart", g.label());
        }
    }

    /// Both sides of every goal are settings the full sweep runs, so bench can check them.
    #[test]
    fn every_goal_compares_benched_settings() {
        let swept: Vec<(&str, String)> = sweep(false).iter().map(|(t, s)| (t.name, setting_label(s))).collect();
        for g in registry_cost_goals().into_iter().chain(leak_goals()) {
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
        let goal = |technique| Goal {
            technique,
            setting: String::new(),
            baseline: "base",
            baseline_setting: "size=1024".into(),
            measure: Measure::Cost { max_ratio: 1.3 },
        };
        let soft = goal("soft");
        // Scene c has no baseline row, so it has no ratio rather than a made-up one.
        let ratios: Vec<_> = soft
            .pairs(&rows)
            .iter()
            .map(|(s, of, base)| (*s, of.timings.gpu_ms_total_median / base.timings.gpu_ms_total_median))
            .collect();
        assert_eq!(ratios, vec![("a", 1.2), ("b", 1.5)]);
        assert_eq!(soft.outcome(&rows).unwrap(), "soft / base size=1024 ≤ 1.3: met on 1/2 scenes (1.20–1.50)");
        // No rows of `other`: that goal is left out of the table, not shown as failed.
        assert_eq!(goal("other").outcome(&rows), None);
        let table = goal_table(COST_HEADING, vec![goal("other"), soft.clone()], &rows);
        assert!(!table.contains("other"), "{table}");
        for line in ["| a | 1.20 ✓ |", "| b | 1.50 ✗ |", "| c | |", "| met | 1/2 |"] {
            assert!(table.lines().any(|l| l == line), "{line} in\n{table}");
        }
        assert_eq!(goal_table(COST_HEADING, vec![soft], &rows[..1]), "");
    }

    /// The cell's ratio is the medians'; the bracket, the least and greatest ratio of one
    /// round's medians, each row's round k against the baseline's round k.
    #[test]
    fn a_cost_cell_shows_how_far_the_rounds_moved_the_ratio() {
        let timed =
            |technique: &str, ms, rounds: &[f64]| BenchRow { round_ms: rounds.to_vec(), ..row("a", technique, "", ms) };
        let rows = [timed("base", 10.0, &[8.0, 10.0, 12.0, 10.0]), timed("soft", 12.0, &[12.0, 11.0, 12.0, 12.5])];
        let goal = Goal {
            technique: "soft",
            setting: String::new(),
            baseline: "base",
            baseline_setting: String::new(),
            measure: Measure::Cost { max_ratio: 1.15 },
        };
        let table = goal_table(COST_HEADING, vec![goal.clone()], &rows);
        assert!(table.lines().any(|l| l == "| a | 1.20 ✗ (1.00–1.50) |"), "{table}");
        // One round: no spread to show.
        let once = [timed("base", 10.0, &[10.0]), timed("soft", 11.0, &[11.0])];
        let table = goal_table(COST_HEADING, vec![goal], &once);
        assert!(table.lines().any(|l| l == "| a | 1.10 ✓ |"), "{table}");
    }

    #[test]
    fn the_leak_rule_holds_where_the_centred_form_leaks_no_more_than_the_outer_only_one() {
        let leaking = |scene: &str, setting: &str, leak_rate| BenchRow {
            metrics: Metrics { leak_rate, dark_rate: 0.5 * leak_rate, pixels: 10_000, ..Default::default() },
            ..row(scene, "plateau", setting, 1.0)
        };
        let outer = "penumbra=outer falloff=linear";
        let rows = [
            leaking("a", "", 0.0),
            leaking("a", outer, 0.0),
            leaking("b", "", 0.002),
            leaking("b", outer, 0.001),
            leaking("c", "", 0.001),
            leaking("c", outer, 0.003),
        ];
        let plateau = leak_goals().into_iter().find(|g| g.technique == "plateau").expect("the plateau's leak rule");
        assert_eq!((plateau.baseline, plateau.baseline_setting.as_str()), ("plateau", outer));
        // Equal rates (none at all, say) meet it; a higher one does not.
        assert_eq!(
            plateau.outcome(&rows).unwrap(),
            "plateau leaks ≤ plateau penumbra=outer falloff=linear: met on 2/3 scenes"
        );
        let table = goal_table(LEAK_HEADING, vec![plateau], &rows);
        for line in ["| a | 0 vs 0 px ✓ (darker: 0 vs 0) |", "| b | 20 vs 10 px ✗ (darker: 10 vs 5) |", "| met | 2/3 |"]
        {
            assert!(table.lines().any(|l| l == line), "{line} in\n{table}");
        }
    }
}
