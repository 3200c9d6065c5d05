//! The registry's entries: each carries what every tool needs to know about a technique (its
//! name, summary, knobs, kind, constructor, and the settings the measurements sweep), so
//! `create`, `softshadow techniques`, bench, showcase, the stability sweep and the tests all
//! iterate [`TECHNIQUES`](super::TECHNIQUES), the only list, and none of them names a technique.

use ash::vk;

use super::knobs::Knob;
use super::{TECHNIQUES, Technique};
use crate::error::{Error, Result};
use crate::gpu::Context;

/// What a technique is, for the tools that choose how to run and judge it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Real time on the GPU: warmed up, timed over many frames, swept by `bench`.
    Realtime,
    /// Converges to V itself: what the others are measured against.
    GroundTruth(Runs),
    /// An approximation computed on the CPU (seconds a frame, one frame is enough).
    CpuApproximation,
}

/// Where a ground truth runs: the GPU one is fast enough for the bench's many scenes, the CPU
/// one is exact and independent of every GPU code path.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Runs {
    Gpu,
    Cpu,
}

impl Kind {
    /// Takes seconds per frame: tools render it once, unwarmed.
    pub fn offline(self) -> bool {
        self != Kind::Realtime
    }
}

/// `KEY=VALUE` knob settings, as the command line's `--set` takes them.
pub type Setting = &'static [(&'static str, &'static str)];

/// Knobs that keep an offline technique quick enough for the stability sweep's grids: the
/// short grid, the long grid, and targets too large to compare with the truth.
#[derive(Clone, Copy, Debug)]
pub struct SweepKnobs {
    pub short: Setting,
    pub long: Setting,
    pub huge: Setting,
}

impl SweepKnobs {
    /// The technique's defaults everywhere.
    pub const DEFAULTS: SweepKnobs = SweepKnobs { short: &[], long: &[], huge: &[] };
}

/// A cost goal an issue set: the technique at `setting` costs at most `max_ratio` times the
/// `baseline` technique at `baseline_setting`, per scene within one bench run.
#[derive(Clone, Copy, Debug)]
pub struct CostGoal {
    pub setting: Setting,
    pub baseline: &'static TechniqueInfo,
    pub baseline_setting: Setting,
    pub max_ratio: f64,
}

/// One technique, as every tool sees it.
#[derive(Debug)]
pub struct TechniqueInfo {
    pub name: &'static str,
    pub summary: &'static str,
    pub kind: Kind,
    pub knobs: &'static [Knob],
    /// Builds the technique (`self` is passed back, for constructors shared by a family)
    /// writing V in the given format.
    pub create: fn(&Context, &'static TechniqueInfo, vk::Format) -> Result<Box<dyn Technique>>,
    /// The settings `softshadow bench` sweeps, the knobs that trade speed for accuracy: the
    /// first alone with `--quick`. Empty: not benched (the offline techniques).
    pub bench: &'static [Setting],
    pub sweep_knobs: SweepKnobs,
    pub cost_goal: Option<CostGoal>,
    pub receivers: Receivers,
    /// The accuracy claimed across every scene the technique accepts: its RMSE against the
    /// exact truth exceeds the hard shadow's by at most this (`tests/truths.rs` holds it).
    /// `None` claims nothing but sound V (the blob: the floor of the curve).
    pub error_bound: Option<f64>,
}

/// The error bound of the approximations: no worse than the hard shadow of a point light at the
/// light's centre plus this RMSE, across lights from a point to 1e6 m (PCF's fixed kernel at a
/// point light measured up to 0.07 at 40 px).
pub const APPROXIMATION_BOUND: f64 = 0.15;

/// Which surfaces a technique can shadow: a stated limit of the method, which the accuracy
/// checks respect (they compare a plane-only technique with a truth in which only the ground
/// receives).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Receivers {
    /// Every receiver in view.
    All,
    /// The ground plane only (the planar family: Blinn's projection onto one plane).
    GroundPlane,
}

impl TechniqueInfo {
    /// Builds the technique, writing V in `visibility`'s format.
    pub fn create(&'static self, ctx: &Context, visibility: vk::Format) -> Result<Box<dyn Technique>> {
        (self.create)(ctx, self, visibility)
    }
}

/// Looks a technique up by name.
pub fn find(name: &str) -> Result<&'static TechniqueInfo> {
    TECHNIQUES.iter().copied().find(|t| t.name == name).ok_or_else(|| {
        let names: Vec<_> = TECHNIQUES.iter().map(|t| t.name).collect();
        Error::Invalid(format!("unknown technique `{name}` (known: {})", names.join(", ")))
    })
}

/// The first ground truth that runs on `runs`.
pub fn ground_truth(runs: Runs) -> &'static TechniqueInfo {
    TECHNIQUES.iter().copied().find(|t| t.kind == Kind::GroundTruth(runs)).expect("the registry lists both truths")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::technique::Params;

    #[test]
    fn names_are_unique_and_defaults_lie_in_their_ranges() {
        for (i, t) in TECHNIQUES.iter().enumerate() {
            assert!(TECHNIQUES[..i].iter().all(|u| u.name != t.name), "{} is listed twice", t.name);
            for k in t.knobs {
                assert!(k.min <= k.default && k.default <= k.max, "{}.{}", t.name, k.name);
                // A name for each whole value, none of them twice or a number.
                let names: Vec<&str> = k.choices.iter().flat_map(|c| c.split('|')).collect();
                let whole = k.integer && k.min == 0.0 && k.max + 1.0 == k.choices.len() as f64;
                assert!(k.choices.is_empty() || whole, "{}.{}: a name for each of 0..={}", t.name, k.name, k.max);
                for (j, n) in names.iter().enumerate() {
                    assert!(!names[..j].contains(n) && n.parse::<f64>().is_err(), "{}.{}: {n}", t.name, k.name);
                }
            }
        }
    }

    /// Every setting an entry names is one its knobs accept, a knob that chooses by name named
    /// (bench's rows and goals read as `softshadow techniques` lists them: `penumbra=outer`, not
    /// `penumbra=0`), and a goal's baseline is listed.
    #[test]
    fn settings_in_the_entries_are_valid() {
        for t in TECHNIQUES {
            let mut settings: Vec<(&TechniqueInfo, Setting)> = t.bench.iter().map(|s| (*t, *s)).collect();
            let k = t.sweep_knobs;
            settings.extend([k.short, k.long, k.huge].map(|s| (*t, s)));
            if let Some(goal) = t.cost_goal {
                assert!(TECHNIQUES.iter().any(|u| std::ptr::eq(*u, goal.baseline)), "{}: baseline unlisted", t.name);
                settings.extend([(*t, goal.setting), (goal.baseline, goal.baseline_setting)]);
            }
            for (of, setting) in settings {
                Params::defaults(of).apply(setting.iter().copied()).unwrap_or_else(|e| panic!("{}: {e}", t.name));
                for (name, value) in setting {
                    let knob = of.knobs.iter().find(|k| k.name == *name).expect("applied above");
                    let named = knob.choices.is_empty() || knob.named(value).is_some();
                    assert!(named, "{}: {name}={value} names none of {:?}", of.name, knob.choices);
                }
            }
        }
    }

    #[test]
    fn both_ground_truths_are_listed() {
        assert_eq!(ground_truth(Runs::Gpu).kind, Kind::GroundTruth(Runs::Gpu));
        assert_eq!(ground_truth(Runs::Cpu).kind, Kind::GroundTruth(Runs::Cpu));
    }
}
