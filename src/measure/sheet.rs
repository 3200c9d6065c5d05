//! The contact sheet of the default run: the techniques' images side by side, each under a
//! label with what it cost and how wrong it is.

use std::path::Path;

use plotters::prelude::*;

use super::plot::{plot_error, register_sans};
use crate::error::{Error, Result};
use crate::renderer::Capture;

/// Height of the label band above each image, in pixels.
const LABEL: u32 = 48;

/// One image of the sheet with its two label lines.
pub struct Tile<'a> {
    pub title: String,
    pub detail: String,
    pub capture: &'a Capture,
}

/// Writes the tiles in rows of `columns` (all tiles must have the first tile's size) to `path`.
pub fn contact_sheet(tiles: &[Tile], columns: usize, path: &Path) -> Result<()> {
    let Some(first) = tiles.first() else { return Err(Error::Invalid("a contact sheet needs a tile".into())) };
    let (w, h) = (first.capture.width, first.capture.height);
    if let Some(t) = tiles.iter().find(|t| (t.capture.width, t.capture.height) != (w, h)) {
        return Err(Error::Invalid(format!("tile `{}` is not {w}x{h}", t.title)));
    }
    register_sans(path)?;
    let columns = columns.clamp(1, tiles.len()) as u32;
    let rows = (tiles.len() as u32).div_ceil(columns);
    let (sheet_w, sheet_h) = (columns * w, rows * (h + LABEL));
    let mut rgb = vec![255u8; (sheet_w * sheet_h * 3) as usize];
    for (i, tile) in tiles.iter().enumerate() {
        let (x0, y0) = ((i as u32 % columns) * w, (i as u32 / columns) * (h + LABEL) + LABEL);
        for (y, row) in tile.capture.color.chunks_exact(4 * w as usize).enumerate() {
            let at = (((y0 + y as u32) * sheet_w + x0) * 3) as usize;
            for (dst, src) in rgb[at..at + 3 * w as usize].chunks_exact_mut(3).zip(row.chunks_exact(4)) {
                dst.copy_from_slice(&src[..3]);
            }
        }
    }
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (sheet_w, sheet_h)).into_drawing_area();
        for (i, tile) in tiles.iter().enumerate() {
            let (x, y) = ((i as u32 % columns) * w + 8, (i as u32 / columns) * (h + LABEL) + 4);
            let at = |dy: u32| (x as i32, (y + dy) as i32);
            root.draw(&Text::new(tile.title.as_str(), at(0), ("sans-serif", 20).into_font().color(&BLACK)))
                .map_err(|e| plot_error(path, e))?;
            root.draw(&Text::new(tile.detail.as_str(), at(24), ("sans-serif", 15).into_font().color(&BLACK)))
                .map_err(|e| plot_error(path, e))?;
        }
        root.present().map_err(|e| plot_error(path, e))?;
    }
    image::save_buffer(path, &rgb, sheet_w, sheet_h, image::ExtendedColorType::Rgb8)
        .map_err(|error| Error::Image { path: path.into(), error })
}
