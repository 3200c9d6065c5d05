//! `bench --curve`: what each technique's frame costs against the casters' triangle count
//! (issue 18), on a scene whose knots are re-made at each size: the points as CSV, each
//! technique's slope beside the hard shadow map's as Markdown, and a log-log plot.

use std::fmt::Write as _;
use std::path::Path;

use plotters::prelude::*;

use super::plot::{COLORS, legend_and_present, plot_error, register_sans};
use crate::error::{Error, Result};

/// One technique's median frame at one size.
#[derive(Clone, Debug)]
pub struct CurvePoint {
    pub technique: String,
    pub triangles: usize,
    pub gpu_ms: f64,
}

/// How a technique's cost grows: the least-squares line through (triangles, ms), as ms per
/// 100k triangles, and the log-log exponent (1: linear in the triangles; 0: independent).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Slope {
    pub ms_per_100k: f64,
    pub exponent: f64,
}

/// The least-squares slope of `y` on `x`; `None` with fewer than two distinct x.
fn fit(points: &[(f64, f64)]) -> Option<f64> {
    let n = points.len() as f64;
    let (mx, my) = points.iter().fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
    let sxx: f64 = points.iter().map(|(x, _)| (x - mx).powi(2)).sum();
    let sxy: f64 = points.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

/// `technique`'s slope over `points`; `None` without two sizes with a positive cost.
pub fn slope(points: &[CurvePoint], technique: &str) -> Option<Slope> {
    let of: Vec<&CurvePoint> = points.iter().filter(|p| p.technique == technique && p.gpu_ms > 0.0).collect();
    let linear: Vec<(f64, f64)> = of.iter().map(|p| (p.triangles as f64 / 1e5, p.gpu_ms)).collect();
    let logs: Vec<(f64, f64)> = of.iter().map(|p| ((p.triangles as f64).ln(), p.gpu_ms.ln())).collect();
    Some(Slope { ms_per_100k: fit(&linear)?, exponent: fit(&logs)? })
}

/// The techniques of `points`, in their order.
fn techniques(points: &[CurvePoint]) -> Vec<&str> {
    let mut names: Vec<&str> = Vec::new();
    for p in points {
        if !names.contains(&p.technique.as_str()) {
            names.push(&p.technique);
        }
    }
    names
}

/// Writes `dir`/curve.csv, curve.md (the slopes beside `baseline`'s) and cost_curve.png.
pub fn write_curve(points: &[CurvePoint], baseline: &str, dir: &Path) -> Result<()> {
    let io = |path: &Path, error| Error::Io { path: path.into(), error };
    let mut csv = String::from("technique,triangles,gpu_ms_total_median\n");
    for p in points {
        let _ = writeln!(csv, "{},{},{:.4}", p.technique, p.triangles, p.gpu_ms);
    }
    let path = dir.join("curve.csv");
    std::fs::write(&path, csv).map_err(|e| io(&path, e))?;

    let base = slope(points, baseline);
    let mut md = format!(
        "# Cost against triangle count\n\nMedian GPU ms per frame; slope of the least-squares line (ms per 100k \
         triangles) and log-log exponent, beside {baseline}'s.\n\n| technique | ms / 100k triangles | exponent | \
         × {baseline}'s slope |\n|---|---|---|---|\n"
    );
    for t in techniques(points) {
        match slope(points, t) {
            Some(s) => {
                let ratio = match base {
                    Some(b) if b.ms_per_100k > 0.0 => format!("{:.2}", s.ms_per_100k / b.ms_per_100k),
                    _ => String::from("–"),
                };
                let _ = writeln!(md, "| {t} | {:.2} | {:.2} | {ratio} |", s.ms_per_100k, s.exponent);
            }
            None => {
                let _ = writeln!(md, "| {t} | – | – | – |");
            }
        }
    }
    let path = dir.join("curve.md");
    std::fs::write(&path, md).map_err(|e| io(&path, e))?;
    plot(points, &dir.join("cost_curve.png"))
}

/// A triangle count as an axis label: 1k, 25k, 1M.
fn count(n: f64) -> String {
    let tenths = |x: f64| (x * 10.0).round() / 10.0;
    match n {
        n if n >= 1e6 => format!("{}M", tenths(n / 1e6)),
        n if n >= 1e3 => format!("{}k", tenths(n / 1e3)),
        n => format!("{n:.0}"),
    }
}

/// GPU ms against triangles, both logarithmic, a line per technique labelled with its slope.
fn plot(points: &[CurvePoint], path: &Path) -> Result<()> {
    register_sans(path)?;
    let tris = |f: fn(f64, f64) -> f64, init| points.iter().map(|p| p.triangles as f64).fold(init, f);
    let ms = |f: fn(f64, f64) -> f64, init| points.iter().map(|p| p.gpu_ms.max(1e-3)).fold(init, f);
    let (x0, x1) = (tris(f64::min, f64::MAX) / 1.5, tris(f64::max, 1.0) * 1.5);
    let (y0, y1) = (ms(f64::min, f64::MAX) / 1.5, ms(f64::max, 1e-3) * 1.5);
    let root = BitMapBackend::new(path, (900, 600)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| plot_error(path, e))?;
    let mut chart = ChartBuilder::on(&root)
        .caption("cost at scale: GPU ms per frame against triangles", ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
        .map_err(|e| plot_error(path, e))?;
    chart
        .configure_mesh()
        .x_desc("caster triangles")
        .y_desc("GPU ms (median)")
        .x_label_formatter(&|n| count(*n))
        .y_label_formatter(&|ms| if *ms >= 10.0 { format!("{ms:.0}") } else { format!("{ms:.1}") })
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(|e| plot_error(path, e))?;
    for (i, t) in techniques(points).into_iter().enumerate() {
        let color = COLORS[i % COLORS.len()];
        let mut line: Vec<(f64, f64)> =
            points.iter().filter(|p| p.technique == t).map(|p| (p.triangles as f64, p.gpu_ms.max(1e-3))).collect();
        line.sort_by(|a, b| a.0.total_cmp(&b.0));
        let label = match slope(points, t) {
            Some(s) => format!("{t}: {:.2} ms / 100k tris", s.ms_per_100k),
            None => t.to_string(),
        };
        chart.draw_series(line.iter().map(|p| Circle::new(*p, 4, color.filled()))).map_err(|e| plot_error(path, e))?;
        chart
            .draw_series(LineSeries::new(line, color.stroke_width(2)))
            .map_err(|e| plot_error(path, e))?
            .label(label)
            .legend(move |(x, y)| PathElement::new([(x - 8, y), (x + 8, y)], color.stroke_width(2)));
    }
    legend_and_present(&mut chart, &root, path, SeriesLabelPosition::UpperLeft, 13)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(technique: &str, triangles: usize, gpu_ms: f64) -> CurvePoint {
        CurvePoint { technique: technique.into(), triangles, gpu_ms }
    }

    #[test]
    fn triangle_counts_label_in_k_and_m() {
        let labels: Vec<String> = [666.7, 1e3, 2.5e4, 1e5, 1e6, 1.5e6].map(count).into();
        assert_eq!(labels, ["667", "1k", "25k", "100k", "1M", "1.5M"]);
    }

    #[test]
    fn slopes_are_ms_per_100k_triangles_and_the_log_log_exponent() {
        // 3 ms per 100k triangles (in proportion: exponent 1), and a cost that does not grow.
        let points: Vec<_> = [1e3, 1e4, 1e5, 1e6]
            .iter()
            .flat_map(|&n| [at("linear", n as usize, 3.0 * n / 1e5), at("flat", n as usize, 5.0)])
            .collect();
        let s = slope(&points, "linear").unwrap();
        assert!((s.ms_per_100k - 3.0).abs() < 1e-9, "{s:?}");
        assert!((s.exponent - 1.0).abs() < 1e-9, "{s:?}");
        assert_eq!(slope(&points, "flat").unwrap(), Slope { ms_per_100k: 0.0, exponent: 0.0 });
        assert_eq!(slope(&points[..1], "linear"), None);
        let dir = std::env::temp_dir().join(format!("softshadow-curve-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        write_curve(&points, "flat", &dir).unwrap();
        let md = std::fs::read_to_string(dir.join("curve.md")).unwrap();
        assert!(md.lines().any(|l| l.starts_with("| linear | 3.00 |")), "{md}");
        assert!(dir.join("cost_curve.png").metadata().unwrap().len() > 0);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
