//! The CPU ray-traced techniques, `raytrace` (ground truth) and `parker` (Parker, Shirley &
//! Smits' single-sample soft shadows): [`TraceScene`] computes V for the frame's camera pixels,
//! then one copy uploads it into the visibility image, so the composite, the readback and the
//! metrics treat them like any GPU technique.

use std::sync::atomic::{AtomicUsize, Ordering};

use ash::vk;

use super::knobs::{Knob, Params};
use super::registry::{APPROXIMATION_BOUND, Kind, Receivers, Runs, SweepKnobs, TechniqueInfo};
use super::{Technique, refuse_wide_lights};
use crate::error::Result;
use crate::frame::{FrameInputs, RAW_VISIBILITY_FORMAT, Surfaces, quantize};
use crate::gpu::{Context, PerFrame, Target, copy_to_target};
use crate::reference::TraceScene;

pub const RAYTRACE: TechniqueInfo = TechniqueInfo {
    name: "raytrace",
    summary: "ground truth on the CPU: stratified shadow rays uniform in the light's solid angle",
    kind: Kind::GroundTruth(Runs::Cpu),
    knobs: &[SAMPLES],
    create: |_, _, _| Ok(Box::new(Traced::new(Method::Exact))),
    bench: &[],
    sweep_knobs: SweepKnobs { short: &[("samples", "64")], long: &[("samples", "64")], huge: &[("samples", "4")] },
    cost_goal: None,
    receivers: Receivers::All,
    error_bound: Some(APPROXIMATION_BOUND),
};

pub const PARKER: TechniqueInfo = TechniqueInfo {
    name: "parker",
    summary: "Parker, Shirley & Smits: one shadow ray per pixel past soft-edged occluders (CPU)",
    kind: Kind::CpuApproximation,
    knobs: &[],
    create: |_, _, _| Ok(Box::new(Traced::new(Method::Parker))),
    bench: &[],
    sweep_knobs: SweepKnobs::DEFAULTS,
    cost_goal: None,
    receivers: Receivers::All,
    // No accuracy claimed: the inner object is the caster itself and the whole penumbra lies
    // outside the hard shadow, so "the umbra region will be larger than in a physically-based
    // computation" (§3), and the paper expects it unnoticed only for occluders large next to
    // the light. Its RMSE against the tracer came out 1.8 to 2.3 times the hard shadow's
    // wherever the light spans 5° to 42° from a 1 m cube (tests/truths.rs's framing), over
    // the hard shadow's plus 0.15 from about 5°.
    error_bound: None,
};

const SAMPLES: Knob = Knob {
    name: "samples",
    default: 1024.0,
    min: 1.0,
    max: 65536.0,
    integer: true,
    choices: &[],
    help: "shadow rays per pixel",
};

/// The widest half-angle a light may span from a caster for `parker`: at 84° it measured RMSE
/// 0.45 against the tracer (tests/truths.rs), three times the hard shadow's error.
const PARKER_MAX_LIGHT_ANGLE_DEG: f64 = 60.0;

/// Shadow rays in a frame above which a progress bar is worth showing.
const LONG_FRAME_RAYS: usize = 20_000_000;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    Exact,
    Parker,
}

pub struct Traced {
    method: Method,
    staging: Option<PerFrame>,
    surfaces: Option<Surfaces>,
}

impl Traced {
    pub fn new(method: Method) -> Self {
        Traced { method, staging: None, surfaces: None }
    }
}

impl Technique for Traced {
    fn record(&mut self, frame: &mut FrameInputs<'_>, params: &Params, visibility: &mut Target) -> Result<()> {
        let ctx = frame.ctx;
        let extent = visibility.extent();
        let (w, h) = (extent.width, extent.height);
        if self.method == Method::Parker {
            refuse_wide_lights(
                frame.scene,
                "parker",
                PARKER_MAX_LIGHT_ANGLE_DEG,
                "for which one ray from the light's centre past occluders grown by similar triangles stands for the \
                 light (Parker et al. §3 assume a light small next to its distance); use a ground truth",
            )?;
        }
        let scene = TraceScene::new(frame.scene)?;
        let light = &frame.scene.light;
        let samples = if self.method == Method::Exact { params.get(&SAMPLES) as usize } else { 1 };

        // Indicatif hides the bar when stderr is not a terminal.
        let bar = (w as usize * h as usize * samples > LONG_FRAME_RAYS)
            .then(|| indicatif::ProgressBar::new(h as u64).with_message(format!("{} rows", params.technique.name)));
        let rows = AtomicUsize::new(0);
        let progress = || {
            let done = rows.fetch_add(1, Ordering::Relaxed) + 1;
            if let Some(bar) = &bar {
                bar.set_position(done as u64);
            }
        };
        let image = match self.method {
            Method::Exact => {
                scene.render(frame.camera, w, h, |p, i| scene.visibility(p, light, samples, i as u64), &progress)
            }
            Method::Parker => scene.render(frame.camera, w, h, |p, _| scene.parker(p, light), &progress),
        };
        if let Some(bar) = bar {
            bar.finish_and_clear();
        }

        // Raw visibility keeps the tracer's floats as they are, for the stability checks.
        let texels: Vec<u16>;
        let bytes: &[u8] = if visibility.desc.format == RAW_VISIBILITY_FORMAT {
            bytemuck::cast_slice(&image.visibility)
        } else {
            texels = image.visibility.iter().map(|&v| quantize(v)).collect();
            bytemuck::cast_slice(&texels)
        };
        let usage = vk::BufferUsageFlags::TRANSFER_SRC;
        let staging = PerFrame::ensure(ctx, &mut self.staging, "traced visibility", bytes.len() as u64, usage)?;
        staging.write(frame.slot, bytes);
        frame.timer.begin(ctx, frame.cmd, "upload");
        copy_to_target(ctx, frame.cmd, staging.range(frame.slot), visibility);
        frame.timer.end(ctx, frame.cmd);
        self.surfaces = Some(image.surfaces);
        Ok(())
    }

    fn traced_surfaces(&self) -> Option<&Surfaces> {
        self.surfaces.as_ref()
    }

    fn destroy(self: Box<Self>, ctx: &Context) {
        self.staging.into_iter().for_each(|s| s.destroy(ctx));
    }
}
