//! The report's plots, drawn with plotters into PNG files. Text needs a font: plotters'
//! `ab_glyph` route takes the bytes of a TrueType file, read here from Debian's
//! `fonts-dejavu-core` (scripts/setup installs it), so no font is compiled in or shipped.

use hairtrace::{Error, Result};
use plotters::prelude::*;
use plotters::style::FontStyle;
use std::path::Path;
use std::sync::OnceLock;

/// Where the font is looked for, first found wins.
const FONT_PATHS: [&str; 2] = [
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu/DejaVuSans.ttf",
];

/// Plot size in pixels.
const SIZE: (u32, u32) = (900, 620);

/// Registers the system's DejaVu Sans as plotters' "sans-serif", once per process.
pub fn load_font() -> Result<()> {
    static LOADED: OnceLock<std::result::Result<(), String>> = OnceLock::new();
    LOADED
        .get_or_init(|| {
            let (path, bytes) = FONT_PATHS
                .iter()
                .find_map(|p| std::fs::read(p).ok().map(|b| (p, b)))
                .ok_or_else(|| {
                    format!(
                        "no font for the plots: install fonts-dejavu-core (scripts/setup); \
                         looked for {}",
                        FONT_PATHS.join(", ")
                    )
                })?;
            // plotters keeps the font for the life of the process.
            let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
            plotters::style::register_font("sans-serif", FontStyle::Normal, bytes)
                .map_err(|_| format!("{path}: not a font plotters can read"))
        })
        .clone()
        .map_err(Error::Image)
}

/// One named set of (x, y) points, joined by a line if `line`, each point named by the
/// label of the same index if there are labels.
pub struct Series {
    pub name: String,
    pub points: Vec<(f64, f64)>,
    pub line: bool,
    pub labels: Vec<String>,
}

/// Axis labels and the caption under a plot.
pub struct Labels<'a> {
    pub title: &'a str,
    pub x: &'a str,
    pub y: &'a str,
    pub caption: &'a str,
}

fn plot_error(path: &Path, e: impl std::fmt::Display) -> Error {
    Error::Image(format!("{}: {e}", path.display()))
}

/// The (low, high) of positive values, widened by a fraction of a decade each side.
fn log_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((f64::MAX, f64::MIN), |(lo, hi), v| (lo.min(v), hi.max(v)));
    if lo > hi {
        return (0.1, 10.0);
    }
    let pad = ((hi / lo).log10() * 0.08).max(0.05);
    (lo / 10f64.powf(pad), hi * 10f64.powf(pad))
}

/// A log-log plot of `series` (points with a non-positive or non-finite coordinate are
/// left out: they have no place on a log axis).
pub fn log_log(path: &Path, labels: &Labels, series: &[Series]) -> Result<()> {
    let all = || series.iter().flat_map(|s| s.points.iter().copied());
    let (x0, x1) = log_range(all().map(|p| p.0));
    let (y0, y1) = log_range(all().map(|p| p.1));
    let root = BitMapBackend::new(path, SIZE).into_drawing_area();
    root.fill(&WHITE).map_err(|e| plot_error(path, e))?;
    let (plot, foot) = root.split_vertically(SIZE.1 - 30);
    foot.draw_text(
        labels.caption,
        &("sans-serif", 13).into_font().color(&BLACK.mix(0.7)),
        (10, 8),
    )
    .map_err(|e| plot_error(path, e))?;
    let mut chart = ChartBuilder::on(&plot)
        .caption(labels.title, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
        .map_err(|e| plot_error(path, e))?;
    chart
        .configure_mesh()
        .x_desc(labels.x)
        .y_desc(labels.y)
        .x_label_formatter(&|v| format!("{v:.2e}"))
        .y_label_formatter(&|v| format!("{v:.1e}"))
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(|e| plot_error(path, e))?;
    for (i, s) in series.iter().enumerate() {
        let color = Palette99::pick(i).to_rgba();
        let plottable = |&(x, y): &(f64, f64)| x.is_finite() && y.is_finite() && x > 0.0 && y > 0.0;
        let points: Vec<(f64, f64)> = s.points.iter().copied().filter(plottable).collect();
        let labelled = s.points.iter().zip(&s.labels).filter(|(p, _)| plottable(p));
        chart
            .draw_series(labelled.map(|(&p, text)| {
                Text::new(
                    text.clone(),
                    p,
                    ("sans-serif", 12).into_font().color(&color),
                )
            }))
            .map_err(|e| plot_error(path, e))?;
        if s.line {
            chart
                .draw_series(LineSeries::new(points.clone(), color.stroke_width(2)))
                .map_err(|e| plot_error(path, e))?;
        }
        chart
            .draw_series(points.iter().map(|&p| Circle::new(p, 5, color.filled())))
            .map_err(|e| plot_error(path, e))?
            .label(s.name.as_str())
            .legend(move |(x, y)| Circle::new((x + 8, y), 5, color.filled()));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK.mix(0.4))
        .label_font(("sans-serif", 13))
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(|e| plot_error(path, e))?;
    root.present().map_err(|e| plot_error(path, e))
}
