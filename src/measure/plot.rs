//! `tradeoff.png`: penumbra RMSE against GPU ms, a series per technique, the Pareto frontier
//! drawn. Text uses Debian's DejaVu Sans through ab_glyph (no system font lookup).

use std::path::Path;

use plotters::prelude::*;
use plotters::style::{FontStyle, register_font};

use super::bench::BenchRow;
use crate::error::{Error, Result};

/// Where Debian's fonts-dejavu-core puts the font (scripts/install-deps.sh installs it).
const FONT: &str = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";

pub(super) const COLORS: [RGBColor; 12] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
    RGBColor(0, 0, 0),
    RGBColor(188, 189, 34),
    RGBColor(0, 0, 128),
    RGBColor(127, 127, 127),
];

pub(super) fn plot_error(path: &Path, e: impl std::fmt::Display) -> Error {
    Error::Invalid(format!("drawing {}: {e}", path.display()))
}

/// Registers DejaVu Sans as plotters' "sans-serif", once per process (plotters keeps
/// registered fonts for the process's life).
/// Draws the series' legend at `position` and writes the image: the last step of every chart.
pub(super) fn legend_and_present<'a, CT: CoordTranslate>(
    chart: &mut ChartContext<'a, BitMapBackend<'a>, CT>,
    root: &DrawingArea<BitMapBackend<'a>, plotters::coord::Shift>,
    path: &Path,
    position: SeriesLabelPosition,
    font_size: u32,
) -> Result<()> {
    chart
        .configure_series_labels()
        .position(position)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .label_font(("sans-serif", font_size))
        .draw()
        .map_err(|e| plot_error(path, e))?;
    root.present().map_err(|e| plot_error(path, e))
}

pub(super) fn register_sans(path: &Path) -> Result<()> {
    static REGISTERED: std::sync::OnceLock<std::result::Result<(), String>> = std::sync::OnceLock::new();
    let registered = REGISTERED.get_or_init(|| {
        let font = std::fs::read(FONT).map_err(|e| format!("reading {FONT}: {e}"))?;
        register_font("sans-serif", FontStyle::Normal, Box::leak(font.into_boxed_slice()))
            .map_err(|_| format!("{FONT} is not a font plotters can read"))
    });
    registered.clone().map_err(|e| plot_error(path, e))
}

/// Draws every row, a colour per technique, and each scene's Pareto frontier as a line.
pub fn tradeoff(rows: &[BenchRow], path: &Path) -> Result<()> {
    register_sans(path)?;
    let max_ms = rows.iter().map(|r| r.timings.gpu_ms_total_median).fold(1.0, f64::max) * 1.1;
    let max_err = rows.iter().map(|r| r.metrics.penumbra_rmse).fold(0.05, f64::max) * 1.1;
    let root = BitMapBackend::new(path, (900, 600)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| plot_error(path, e))?;
    let mut chart = ChartBuilder::on(&root)
        .caption("speed / accuracy: penumbra RMSE against GPU ms per frame", ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..max_ms, 0.0..max_err)
        .map_err(|e| plot_error(path, e))?;
    chart
        .configure_mesh()
        .x_desc("GPU ms (median)")
        .y_desc("penumbra RMSE")
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(|e| plot_error(path, e))?;
    let mut techniques: Vec<&str> = rows.iter().map(|r| r.technique.as_str()).collect();
    techniques.sort();
    techniques.dedup();
    for (i, technique) in techniques.iter().enumerate() {
        let color = COLORS[i % COLORS.len()];
        let points: Vec<(f64, f64)> = rows
            .iter()
            .filter(|r| r.technique == *technique)
            .map(|r| (r.timings.gpu_ms_total_median, r.metrics.penumbra_rmse))
            .collect();
        chart
            .draw_series(points.iter().map(|p| Circle::new(*p, 5, color.filled())))
            .map_err(|e| plot_error(path, e))?
            .label(*technique)
            .legend(move |(x, y)| Circle::new((x, y), 5, color.filled()));
    }
    let mut scenes: Vec<&str> = rows.iter().map(|r| r.scene.as_str()).collect();
    scenes.dedup();
    for (i, scene) in scenes.iter().enumerate() {
        let mut frontier: Vec<(f64, f64)> = rows
            .iter()
            .filter(|r| r.pareto && r.scene == *scene)
            .map(|r| (r.timings.gpu_ms_total_median, r.metrics.penumbra_rmse))
            .collect();
        frontier.sort_by(|a, b| a.0.total_cmp(&b.0));
        let series =
            chart.draw_series(LineSeries::new(frontier, BLACK.stroke_width(2))).map_err(|e| plot_error(path, e))?;
        if i == 0 {
            series
                .label("Pareto frontier (per scene)")
                .legend(|(x, y)| PathElement::new([(x - 8, y), (x + 8, y)], BLACK.stroke_width(2)));
        }
    }
    legend_and_present(&mut chart, &root, path, SeriesLabelPosition::UpperRight, 14)
}

/// A line chart: each series a colour, for profiles and curves a closing note shows.
pub fn lines(path: &Path, caption: &str, axes: (&str, &str), series: &[(&str, Vec<(f64, f64)>)]) -> Result<()> {
    register_sans(path)?;
    let points = || series.iter().flat_map(|(_, s)| s.iter());
    let (x0, x1) = points().fold((f64::MAX, f64::MIN), |(lo, hi), p| (lo.min(p.0), hi.max(p.0)));
    let (y0, y1) = points().fold((0.0f64, f64::MIN), |(lo, hi), p| (lo.min(p.1), hi.max(p.1)));
    if x0 >= x1 {
        return Err(plot_error(path, "no extent to draw"));
    }
    let root = BitMapBackend::new(path, (900, 560)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| plot_error(path, e))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(caption, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(x0..x1, y0..y1 * 1.05 + 1e-9)
        .map_err(|e| plot_error(path, e))?;
    chart
        .configure_mesh()
        .x_desc(axes.0)
        .y_desc(axes.1)
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(|e| plot_error(path, e))?;
    for (i, (name, points)) in series.iter().enumerate() {
        let color = COLORS[i % COLORS.len()];
        chart
            .draw_series(LineSeries::new(points.iter().copied(), color.stroke_width(2)))
            .map_err(|e| plot_error(path, e))?
            .label(*name)
            .legend(move |(x, y)| PathElement::new([(x - 8, y), (x + 8, y)], color.stroke_width(2)));
    }
    legend_and_present(&mut chart, &root, path, SeriesLabelPosition::UpperRight, 14)
}
