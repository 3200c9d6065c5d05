//! The 1D falloff texture that turns a linear penumbra parameter into a gradient (Haines §3,
//! Chan & Durand §3.1): one row each for linear, sine (the straight edge under a disk light,
//! Parker et al.) and smoothstep (Parker's Bernstein interpolant). Read by
//! `glsl/common/falloff.glsl`.

use ash::vk;
use bytemuck::cast_slice;
use gpu_allocator::MemoryLocation;

use super::knobs::Knob;
use crate::error::Result;
use crate::gpu::{Buffer, Context, Target, TargetDesc, copy_to_target};

/// The knob choosing the curve. Linear is the default: it measured best against the reference
/// for both plateaus and smoothies (the outer-only penumbrae start at the hard edge, where the
/// true V is already ½, and the sine and smoothstep curves stay darker longer).
pub const FALLOFF: Knob = Knob {
    name: "falloff",
    default: 0.0,
    min: 0.0,
    max: 2.0,
    integer: true,
    help: "gradient: 0 linear, 1 sine (Haines 3), 2 smoothstep (Parker)",
};

const FORMAT: vk::Format = vk::Format::R16_UNORM;
const SIZE: u32 = 256;
/// Rows, in the order of the `falloff` knob's values.
const CURVES: [fn(f64) -> f64; 3] = [
    |t| t,
    |t| (1.0 + (std::f64::consts::PI * t - std::f64::consts::FRAC_PI_2).sin()) / 2.0,
    |t| t * t * (3.0 - 2.0 * t),
];

/// The texture, uploaded on the first frame that needs it.
#[derive(Default)]
pub struct Falloff {
    texture: Option<Target>,
    /// Read by the upload recorded in the first frame; kept until the technique goes.
    staging: Option<Buffer>,
}

impl Falloff {
    /// The texture, recording its one-time upload into `cmd` on first use.
    pub fn texture(&mut self, ctx: &Context, cmd: vk::CommandBuffer) -> Result<&mut Target> {
        if self.texture.is_none() {
            let texels: Vec<u16> = CURVES
                .iter()
                .flat_map(|f| (0..SIZE).map(|i| (f(i as f64 / (SIZE - 1) as f64) * 65535.0).round() as u16))
                .collect();
            let bytes: &[u8] = cast_slice(&texels);
            let usage = vk::BufferUsageFlags::TRANSFER_SRC;
            let mut staging = Buffer::new(ctx, "falloff staging", bytes.len() as u64, usage, MemoryLocation::CpuToGpu)?;
            staging.write(0, bytes);
            let desc = TargetDesc::color("falloff", FORMAT, SIZE, CURVES.len() as u32)
                .usage(vk::ImageUsageFlags::TRANSFER_DST);
            let mut texture = match Target::new(ctx, desc) {
                Ok(t) => t,
                Err(e) => {
                    staging.destroy(ctx);
                    return Err(e);
                }
            };
            let range = vk::DescriptorBufferInfo { buffer: staging.buffer, offset: 0, range: bytes.len() as u64 };
            copy_to_target(ctx, cmd, range, &mut texture);
            self.staging = Some(staging);
            self.texture = Some(texture);
        }
        Ok(self.texture.as_mut().expect("made above"))
    }

    pub fn destroy(self, ctx: &Context) {
        self.texture.into_iter().for_each(|t| t.destroy(ctx));
        self.staging.into_iter().for_each(|b| b.destroy(ctx));
    }
}
