//! The 1D falloff texture that turns a linear penumbra parameter into a gradient (Haines §3,
//! Chan & Durand §3.1): one row each for linear, sine (Parker et al.), smoothstep (Parker's
//! Bernstein interpolant) and the exact visible fraction of a spherical light behind a straight
//! edge (the disk segment; the same half-plane test the ray tracer checks). Read by
//! `glsl/common/falloff.glsl`.

use ash::vk;
use bytemuck::cast_slice;
use gpu_allocator::MemoryLocation;

use super::knobs::Knob;
use crate::error::Result;
use crate::gpu::{Buffer, Context, Target, TargetDesc, Uploads, copy_to_target};

/// The knob choosing the curve. Linear is the default: it measured best against the reference
/// for both plateaus and smoothies (the outer-only penumbrae start at the hard edge, where the
/// true V is already ½, and the sine and smoothstep curves stay darker longer).
pub const FALLOFF: Knob = Knob {
    name: "falloff",
    default: 0.0,
    min: 0.0,
    max: 3.0,
    integer: true,
    help: "gradient: 0 linear, 1 sine (Haines 3), 2 smoothstep (Parker), 3 disk edge (exact for a straight edge)",
};

/// Where the penumbra lies (issue 20): 0, the papers' outer-only form, grown outward from the
/// hard shadow, whose whole area stays umbra (Haines §4, Chan & Durand §3); 1, centred on the
/// hard edge with the physical width, V = ½ on the edge and the umbra shrinking as the light
/// grows. A technique whose measured default differs declares `Knob { default: 1.0, ..PENUMBRA }`.
pub const PENUMBRA: Knob = Knob::switch("penumbra", "penumbra: 0 outer only (the papers), 1 centred on the hard edge");

const FORMAT: vk::Format = vk::Format::R16_UNORM;
const SIZE: u32 = 256;
/// Rows, in the order of the `falloff` knob's values.
const CURVES: [fn(f64) -> f64; 4] = [
    |t| t,
    |t| (1.0 + (std::f64::consts::PI * t - std::f64::consts::FRAC_PI_2).sin()) / 2.0,
    |t| t * t * (3.0 - 2.0 * t),
    disk_edge,
];

/// The visible fraction of a disk light whose centre sits at `t` across a straight edge, the
/// penumbra spanning t = 0 (the edge covers the whole disk) to t = 1 (none of it): the area of
/// the disk segment beyond the chord at u = 2t − 1, V = 1 − (acos u − u·√(1 − u²))/π. V = ½ on
/// the hard edge (t = ½), which is why a penumbra using it must straddle that edge.
pub fn disk_edge(t: f64) -> f64 {
    let u = (2.0 * t - 1.0).clamp(-1.0, 1.0);
    1.0 - (u.acos() - u * (1.0 - u * u).sqrt()) / std::f64::consts::PI
}

/// The texture, uploaded on the first frame that needs it (again after a lost frame: that
/// frame's copy never ran), with the staging buffer its copy reads.
pub struct Falloff {
    uploaded: Uploads<(), (Target, Buffer)>,
}

impl Default for Falloff {
    fn default() -> Self {
        Falloff {
            uploaded: Uploads::new(|(texture, staging), ctx| {
                texture.destroy(ctx);
                staging.destroy(ctx);
            }),
        }
    }
}

impl Falloff {
    /// The texture, recording its upload into `cmd` on first use.
    pub fn texture(&mut self, ctx: &Context, cmd: vk::CommandBuffer) -> Result<&mut Target> {
        let at = self.uploaded.index(ctx, (), || {
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
            Ok((texture, staging))
        })?;
        Ok(&mut self.uploaded.get_mut(at).0)
    }

    pub fn destroy(self, ctx: &Context) {
        self.uploaded.destroy(ctx);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The disk-segment profile against the visible fraction of a unit disk counted on a fine
    /// grid: an independent measure, so a wrong sign or a swapped term fails.
    #[test]
    fn disk_edge_is_the_visible_fraction_of_a_disk() {
        let n = 400;
        for &t in &[0.0, 0.1, 0.25, 0.5, 0.7, 0.9, 1.0] {
            let chord = 2.0 * t - 1.0;
            let (mut inside, mut visible) = (0u32, 0u32);
            for i in 0..n {
                for j in 0..n {
                    let (x, y) = (-1.0 + (i as f64 + 0.5) * 2.0 / n as f64, -1.0 + (j as f64 + 0.5) * 2.0 / n as f64);
                    if x * x + y * y <= 1.0 {
                        inside += 1;
                        // The edge blocks everything beyond the chord on the far side (x > chord).
                        visible += u32::from(x <= chord);
                    }
                }
            }
            let counted = visible as f64 / inside as f64;
            assert!((disk_edge(t) - counted).abs() < 0.005, "t {t}: {} vs counted {counted}", disk_edge(t));
        }
        assert!((disk_edge(0.5) - 0.5).abs() < 1e-12);
    }
}
