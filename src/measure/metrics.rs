//! Error metrics between two visibility images of the same camera, over the pixels where V
//! means something (surfaces that receive shadows). Pixels where the two renders saw different
//! surfaces (object silhouettes, which a rasterizer and a ray tracer resolve differently) are
//! left out and counted.

use std::path::Path;

use serde::Serialize;

use crate::error::{Error, Result};
use crate::renderer::Capture;

/// |error| above which a pixel counts as a light leak or as over-darkened.
pub const GROSS_ERROR: f64 = 0.1;
/// The reference is in penumbra strictly between these.
pub const PENUMBRA: (f64, f64) = (0.02, 0.98);
/// Relative depth difference above which two renders see different surfaces.
const SAME_DEPTH: f32 = 1e-3;
/// Facet normals further apart than this (cosine; half floats carry about 1e-3) belong to
/// different facets: at a silhouette the depths agree but the surfaces do not.
const SAME_FACET: f32 = 0.99;

/// How wrong `V` is against a reference. Rates are fractions of the compared pixels; with no
/// pixel to compare (or no penumbra) the errors are 0 and the counts say why.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Metrics {
    /// Receiver pixels compared.
    pub pixels: usize,
    /// Receiver pixels left out: the renders saw different surfaces there.
    pub excluded: usize,
    pub rmse: f64,
    pub mae: f64,
    pub max_abs: f64,
    pub p99_abs: f64,
    /// Compared pixels where the reference is in penumbra.
    pub penumbra_pixels: usize,
    pub penumbra_rmse: f64,
    /// V − reference > 0.1: light where there should be shadow.
    pub leak_rate: f64,
    /// reference − V > 0.1: shadow where there should be light.
    pub dark_rate: f64,
    /// Mean of V − reference: positive is too light.
    pub mean_bias: f64,
}

/// Per pixel: `Some(V − reference)` where compared, `Err(())` where the surfaces differ,
/// `None` where neither render sees a receiver.
fn errors(v: &Capture, reference: &Capture) -> Result<Vec<Option<std::result::Result<f64, ()>>>> {
    if (v.width, v.height) != (reference.width, reference.height) {
        return Err(Error::Invalid(format!(
            "cannot compare a {}x{} image with a {}x{} reference",
            v.width, v.height, reference.width, reference.height
        )));
    }
    let (a, b) = (&v.surfaces, &reference.surfaces);
    Ok((0..v.visibility.len())
        .map(|i| {
            if !a.receives[i] && !b.receives[i] {
                return None;
            }
            let (da, db) = (a.depth[i], b.depth[i]);
            let same = a.receives[i] == b.receives[i]
                && (da - db).abs() <= SAME_DEPTH * da.max(db)
                && a.normal[i].dot(b.normal[i]) >= SAME_FACET;
            if !same {
                return Some(Err(()));
            }
            Some(Ok((v.visibility[i] as f64 - reference.visibility[i] as f64) / 65535.0))
        })
        .collect())
}

impl Metrics {
    /// Compares `v` with `reference` (same size, same camera).
    pub fn between(v: &Capture, reference: &Capture) -> Result<Metrics> {
        let per_pixel = errors(v, reference)?;
        let mut m = Metrics::default();
        let mut abs = Vec::new();
        let (mut sq, mut sum, mut penumbra_sq) = (0.0, 0.0, 0.0);
        for (i, e) in per_pixel.iter().enumerate() {
            match e {
                None => {}
                Some(Err(())) => m.excluded += 1,
                Some(Ok(e)) => {
                    let r = reference.visibility[i] as f64 / 65535.0;
                    abs.push(e.abs());
                    sq += e * e;
                    sum += e;
                    if r > PENUMBRA.0 && r < PENUMBRA.1 {
                        m.penumbra_pixels += 1;
                        penumbra_sq += e * e;
                    }
                    m.leak_rate += f64::from(*e > GROSS_ERROR);
                    m.dark_rate += f64::from(-e > GROSS_ERROR);
                }
            }
        }
        m.pixels = abs.len();
        if m.pixels == 0 {
            return Ok(m);
        }
        let n = m.pixels as f64;
        abs.sort_by(f64::total_cmp);
        m.rmse = (sq / n).sqrt();
        m.mae = abs.iter().sum::<f64>() / n;
        m.max_abs = abs[m.pixels - 1];
        m.p99_abs = abs[((0.99 * n).ceil() as usize).clamp(1, m.pixels) - 1];
        m.mean_bias = sum / n;
        m.leak_rate /= n;
        m.dark_rate /= n;
        if m.penumbra_pixels > 0 {
            m.penumbra_rmse = (penumbra_sq / m.penumbra_pixels as f64).sqrt();
        }
        Ok(m)
    }
}

/// Writes the signed error as color: white where exact, red where too light (a leak), blue
/// where too dark, saturating at |error| = 0.25; magenta where the surfaces differ, dark grey
/// where nothing receives shadows.
pub fn save_difference(v: &Capture, reference: &Capture, path: &Path) -> Result<()> {
    let per_pixel = errors(v, reference)?;
    let mut rgb = Vec::with_capacity(per_pixel.len() * 3);
    for e in per_pixel {
        let pixel = match e {
            None => [48, 48, 48],
            Some(Err(())) => [255, 0, 255],
            Some(Ok(e)) => {
                let fade = (255.0 * (1.0 - (e.abs() / 0.25).min(1.0))).round() as u8;
                if e > 0.0 { [255, fade, fade] } else { [fade, fade, 255] }
            }
        };
        rgb.extend(pixel);
    }
    image::save_buffer(path, &rgb, v.width, v.height, image::ExtendedColorType::Rgb8)
        .map_err(|error| Error::Image { path: path.into(), error })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::Surfaces;

    fn capture(v: &[f64], depth: &[f32], receives: &[bool]) -> Capture {
        Capture {
            width: v.len() as u32,
            height: 1,
            color: vec![0; v.len() * 4],
            visibility: v.iter().map(|x| (x * 65535.0).round() as u16).collect(),
            raw_visibility: None,
            surfaces: Surfaces {
                depth: depth.to_vec(),
                normal: vec![glam::Vec3::Y; v.len()],
                receives: receives.to_vec(),
                casts: vec![false; v.len()],
            },
        }
    }

    #[test]
    fn metrics_of_known_errors() {
        let d = [1.0; 5];
        let r = [true, true, true, true, false];
        let reference = capture(&[0.0, 0.5, 1.0, 1.0, 1.0], &d, &r);
        let v = capture(&[0.0, 0.7, 0.8, 1.0, 0.0], &d, &r);
        let m = Metrics::between(&v, &reference).unwrap();
        assert_eq!((m.pixels, m.excluded, m.penumbra_pixels), (4, 0, 1));
        assert!((m.rmse - (0.08f64 / 4.0).sqrt()).abs() < 1e-4, "{m:?}");
        assert!((m.mae - 0.1).abs() < 1e-4 && (m.max_abs - 0.2).abs() < 1e-4 && (m.p99_abs - 0.2).abs() < 1e-4);
        assert!((m.penumbra_rmse - 0.2).abs() < 1e-4);
        assert_eq!((m.leak_rate, m.dark_rate), (0.25, 0.25));
        assert!(m.mean_bias.abs() < 1e-4);
    }

    #[test]
    fn different_surfaces_are_excluded_and_counted() {
        let reference = capture(&[0.0, 0.0, 0.0], &[1.0, 1.0, f32::INFINITY], &[true, true, false]);
        let v = capture(&[1.0, 1.0, 1.0], &[1.0, 2.0, 1.0], &[true, true, true]);
        let m = Metrics::between(&v, &reference).unwrap();
        assert_eq!((m.pixels, m.excluded), (1, 2));
        assert!((m.rmse - 1.0).abs() < 1e-9);
    }

    #[test]
    fn nothing_to_compare_is_zero_not_nan() {
        let c = capture(&[1.0], &[f32::INFINITY], &[false]);
        let m = Metrics::between(&c, &c).unwrap();
        assert_eq!(m, Metrics::default());
        let other = capture(&[1.0, 1.0], &[1.0; 2], &[true; 2]);
        assert!(Metrics::between(&c, &other).unwrap_err().to_string().contains("1x1"));
    }
}
