//! Readback of the color and visibility images, and their PNG files (DESIGN.md §3), with the
//! surfaces V was estimated at, so that two renders can be compared pixel by pixel.

use std::path::Path;

use ash::vk;
use glam::{Vec2, Vec3};

use super::CameraTargets;
use crate::error::{Error, Result};
use crate::frame::{RAW_VISIBILITY_FORMAT, ShadowRole, Surfaces, quantize};
use crate::geometry::CameraProjection;
use crate::gpu::{Buffer, Context, Target, copy_to_buffer};

/// Bytes per pixel read back: RGBA8 color, D32 depth, RGBA16F normal + receives, then V: R16,
/// or R32F for raw visibility.
fn pixel_bytes(visibility: vk::Format) -> [u64; 4] {
    [4, 4, 8, if visibility == RAW_VISIBILITY_FORMAT { 4 } else { 2 }]
}

pub(super) fn readback_size(w: u32, h: u32, visibility: vk::Format) -> u64 {
    w as u64 * h as u64 * pixel_bytes(visibility).iter().sum::<u64>()
}

/// Copies color (`color`, or the engine's color target), depth, normal and V into `dst`.
pub(super) fn record_copies(
    ctx: &Context,
    cmd: vk::CommandBuffer,
    t: &CameraTargets,
    color: Option<&Target>,
    dst: &Buffer,
) {
    let extent = t.extent();
    let pixels = extent.width as u64 * extent.height as u64;
    let mut offset = 0;
    let bytes = pixel_bytes(t.visibility.desc.format);
    let own = &t.shaded.as_ref().expect("a captured frame is the engine's own").color;
    for (target, bytes) in [color.unwrap_or(own), &t.depth, &t.normal, &t.visibility].into_iter().zip(bytes) {
        copy_to_buffer(ctx, cmd, target, dst, &[target.whole_copy(offset)]);
        offset += pixels * bytes;
    }
}

/// An IEEE half float's value.
fn half_to_f32(h: u16) -> f32 {
    let sign = if h & 0x8000 != 0 { -1.0 } else { 1.0 };
    let (exponent, mantissa) = ((h >> 10) & 0x1F, (h & 0x3FF) as f32);
    sign * match exponent {
        0 => mantissa * 2f32.powi(-24),
        31 => {
            if mantissa == 0.0 {
                f32::INFINITY
            } else {
                f32::NAN
            }
        }
        e => (1.0 + mantissa / 1024.0) * 2f32.powi(e as i32 - 15),
    }
}

/// The image point (0..1, row 0 at the top) at the centre of pixel `index` of a row-major image.
pub fn pixel_uv(index: usize, width: u32, height: u32) -> Vec2 {
    let (x, y) = (index % width as usize, index / width as usize);
    Vec2::new((x as f32 + 0.5) / width as f32, (y as f32 + 0.5) / height as f32)
}

/// One frame's images on the CPU. Row 0 is the top of the image.
#[derive(Clone, Debug)]
pub struct Capture {
    pub width: u32,
    pub height: u32,
    /// sRGB-encoded RGBA8.
    pub color: Vec<u8>,
    /// V as round(V · 65535); 1 (65535) where no surface is seen.
    pub visibility: Vec<u16>,
    /// V as the technique wrote it, before quantisation (NaN and values outside [0, 1]
    /// included), when the engine keeps raw visibility ([`Engine::set_raw_visibility`](super::Engine::set_raw_visibility)).
    pub raw_visibility: Option<Vec<f32>>,
    /// Where V was estimated: the prepass's surfaces, or the ones a ray tracer found.
    pub surfaces: Surfaces,
}

impl Capture {
    pub(super) fn read(
        buffer: &Buffer,
        width: u32,
        height: u32,
        camera: &CameraProjection,
        visibility_format: vk::Format,
    ) -> Self {
        let n = width as usize * height as usize;
        let mut parts = Vec::new();
        let mut rest = buffer.read();
        for bytes in pixel_bytes(visibility_format) {
            let (part, tail) = rest.split_at(n * bytes as usize);
            parts.push(part);
            rest = tail;
        }
        let color = parts[0].to_vec();
        let depth = parts[1]
            .chunks_exact(4)
            .enumerate()
            .map(|(i, b)| {
                let d = f32::from_ne_bytes([b[0], b[1], b[2], b[3]]);
                // Reverse Z: the prepass clears to 0, "no surface".
                if d > 0.0 { camera.view_depth(pixel_uv(i, width, height), d) } else { f32::INFINITY }
            })
            .collect();
        let halfs = |b: &[u8]| -> [u16; 4] { std::array::from_fn(|i| u16::from_ne_bytes([b[2 * i], b[2 * i + 1]])) };
        let normal = parts[2]
            .chunks_exact(8)
            .map(|b| {
                let [x, y, z, _] = halfs(b).map(half_to_f32);
                Vec3::new(x, y, z)
            })
            .collect();
        // The normal target's alpha (a half float) is the shadow role.
        let role: Vec<f32> = parts[2].chunks_exact(8).map(|b| half_to_f32(halfs(b)[3])).collect();
        let receives = role.iter().map(|&r| ShadowRole::receives(r)).collect();
        let casts = role.iter().map(|&r| ShadowRole::casts(r)).collect();
        let (visibility, raw_visibility) = if visibility_format == RAW_VISIBILITY_FORMAT {
            let raw: Vec<f32> =
                parts[3].chunks_exact(4).map(|b| f32::from_ne_bytes([b[0], b[1], b[2], b[3]])).collect();
            (raw.iter().map(|&v| quantize(v)).collect(), Some(raw))
        } else {
            (parts[3].chunks_exact(2).map(|b| u16::from_ne_bytes([b[0], b[1]])).collect(), None)
        };
        Capture {
            width,
            height,
            color,
            visibility,
            raw_visibility,
            surfaces: Surfaces { depth, normal, receives, casts },
        }
    }

    /// V at pixel (x, y) in [0, 1].
    pub fn visibility_at(&self, x: u32, y: u32) -> f32 {
        self.visibility[(y * self.width + x) as usize] as f32 / 65535.0
    }

    pub fn save_color(&self, path: &Path) -> Result<()> {
        image::save_buffer(path, &self.color, self.width, self.height, image::ExtendedColorType::Rgba8)
            .map_err(|error| Error::Image { path: path.into(), error })
    }

    /// The 16-bit grayscale PNG of DESIGN.md §3.
    pub fn save_visibility(&self, path: &Path) -> Result<()> {
        let img = image::ImageBuffer::<image::Luma<u16>, _>::from_raw(self.width, self.height, self.visibility.clone())
            .expect("buffer matches its size");
        img.save(path).map_err(|error| Error::Image { path: path.into(), error })
    }
}

#[cfg(test)]
mod tests {
    use super::half_to_f32;

    #[test]
    fn half_floats_decode() {
        for (bits, value) in [(0x3C00, 1.0), (0x3800, 0.5), (0xC000, -2.0), (0x0000, 0.0), (0x0001, 2f32.powi(-24))] {
            assert_eq!(half_to_f32(bits), value);
        }
        assert_eq!(half_to_f32(0x7BFF), 65504.0);
    }
}
