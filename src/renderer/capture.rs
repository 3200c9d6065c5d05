//! Readback of the color and visibility images, and their PNG files (DESIGN.md §3).

use std::path::Path;

use ash::vk;

use super::CameraTargets;
use crate::error::{Error, Result};
use crate::gpu::{Buffer, Context};

/// Bytes for one frame: RGBA8 color, then R16 visibility.
pub(super) fn readback_size(w: u32, h: u32) -> u64 {
    w as u64 * h as u64 * (4 + 2)
}

pub(super) fn record_copies(ctx: &Context, cmd: vk::CommandBuffer, t: &CameraTargets, dst: &Buffer) {
    let extent = t.color.extent();
    let region = |offset: u64| vk::BufferImageCopy {
        buffer_offset: offset,
        buffer_row_length: 0,
        buffer_image_height: 0,
        image_subresource: vk::ImageSubresourceLayers {
            aspect_mask: vk::ImageAspectFlags::COLOR,
            mip_level: 0,
            base_array_layer: 0,
            layer_count: 1,
        },
        image_offset: vk::Offset3D::default(),
        image_extent: vk::Extent3D { width: extent.width, height: extent.height, depth: 1 },
    };
    let color_bytes = extent.width as u64 * extent.height as u64 * 4;
    unsafe {
        ctx.device.cmd_copy_image_to_buffer(
            cmd,
            t.color.image,
            vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
            dst.buffer,
            &[region(0)],
        );
        ctx.device.cmd_copy_image_to_buffer(
            cmd,
            t.visibility.image,
            vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
            dst.buffer,
            &[region(color_bytes)],
        );
    }
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
}

impl Capture {
    pub(super) fn read(buffer: &Buffer, width: u32, height: u32) -> Self {
        let bytes = buffer.read();
        let n = width as usize * height as usize;
        let color = bytes[..n * 4].to_vec();
        let visibility = bytes[n * 4..n * 6].chunks_exact(2).map(|b| u16::from_ne_bytes([b[0], b[1]])).collect();
        Capture { width, height, color, visibility }
    }

    /// V at pixel (x, y) in [0, 1].
    pub fn visibility_at(&self, x: u32, y: u32) -> f32 {
        self.visibility[(y * self.width + x) as usize] as f32 / 65535.0
    }

    pub fn save_color(&self, path: &Path) -> Result<()> {
        image::save_buffer(path, &self.color, self.width, self.height, image::ExtendedColorType::Rgba8)
            .map_err(|source| Error::Image { path: path.into(), source })
    }

    /// The 16-bit grayscale PNG of DESIGN.md §3.
    pub fn save_visibility(&self, path: &Path) -> Result<()> {
        let img = image::ImageBuffer::<image::Luma<u16>, _>::from_raw(self.width, self.height, self.visibility.clone())
            .expect("buffer matches its size");
        img.save(path).map_err(|source| Error::Image { path: path.into(), source })
    }
}
