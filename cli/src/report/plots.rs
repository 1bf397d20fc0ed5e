//! The report's plots, drawn with plotters and written as PNG files. Text needs a font:
//! plotters' `ab_glyph` route takes the bytes of a TrueType file, read here from Debian's
//! `fonts-dejavu-core` (scripts/setup installs it), so no font is compiled in or shipped.

use super::markdown::num;
use hairtrace::{Error, Result};
use plotters::coord::combinators::BindKeyPoints;
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
const SIZE: (u32, u32) = (1000, 640);

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

/// One named set of (x, y) points, joined by a line if `line`.
pub struct Series {
    pub name: String,
    pub points: Vec<(f64, f64)>,
    pub line: bool,
}

/// Axis labels and the caption under a plot.
pub struct Labels<'a> {
    pub title: &'a str,
    pub x: &'a str,
    pub y: &'a str,
    pub caption: &'a str,
}

fn plottable(&(x, y): &(f64, f64)) -> bool {
    x.is_finite() && y.is_finite() && x > 0.0 && y > 0.0
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

/// Tick positions for a log axis over (lo, hi): the powers of ten, or 1-2-5 steps, or
/// every digit, whichever gives between 3 and 12 ticks.
fn log_ticks((lo, hi): (f64, f64)) -> Vec<f64> {
    let mantissas: [&[f64]; 3] = [
        &[1.0],
        &[1.0, 2.0, 5.0],
        &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0],
    ];
    let mut best = Vec::new();
    for m in mantissas {
        let ticks: Vec<f64> = (lo.log10().floor() as i32..=hi.log10().ceil() as i32)
            .flat_map(|e| m.iter().map(move |d| d * 10f64.powi(e)))
            .filter(|t| (lo..=hi).contains(t))
            .collect();
        if ticks.len() >= 3 {
            return ticks.into_iter().take(12).collect();
        }
        best = ticks;
    }
    if best.len() < 2 {
        vec![lo, (lo * hi).sqrt(), hi]
    } else {
        best
    }
}

/// `text` in lines of at most about `width` characters, broken after commas.
fn wrap(text: &str, width: usize) -> Vec<String> {
    let mut lines = vec![String::new()];
    for piece in text.split_inclusive(", ") {
        let last = lines.last_mut().expect("one line at least");
        if !last.is_empty() && last.len() + piece.len() > width {
            lines.push(piece.to_owned());
        } else {
            last.push_str(piece);
        }
    }
    lines
}

/// Series colours: Tableau's ten, then darker shades, so that neighbours in a legend
/// differ.
const COLORS: [RGBColor; 14] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
    RGBColor(0, 0, 0),
    RGBColor(120, 60, 0),
    RGBColor(0, 80, 40),
    RGBColor(90, 0, 120),
];

/// Legend width, right of the plot.
const LEGEND_WIDTH: u32 = 330;

/// A log-log plot of `series` (points with a non-positive or non-finite coordinate are
/// left out: they have no place on a log axis), with the legend to its right.
pub fn log_log(path: &Path, labels: &Labels, series: &[Series]) -> Result<()> {
    let all = || {
        series
            .iter()
            .flat_map(|s| s.points.iter().copied())
            .filter(plottable)
    };
    let x_range = log_range(all().map(|p| p.0));
    let y_range = log_range(all().map(|p| p.1));
    let mut rgb = vec![0u8; (SIZE.0 * SIZE.1 * 3) as usize];
    draw(path, labels, series, &mut rgb, x_range, y_range)?;
    crate::files::write_png(path, &rgb, SIZE)
}

/// Draws the plot of [`log_log`] into `rgb`, over `x_range` x `y_range`.
fn draw(
    path: &Path,
    labels: &Labels,
    series: &[Series],
    rgb: &mut [u8],
    x_range: (f64, f64),
    y_range: (f64, f64),
) -> Result<()> {
    let root = BitMapBackend::with_buffer(rgb, SIZE).into_drawing_area();
    root.fill(&WHITE).map_err(|e| Error::image(path, e))?;
    let (upper, foot) = root.split_vertically(SIZE.1 - 44);
    let (plot, legend) = upper.split_horizontally(SIZE.0 - LEGEND_WIDTH);
    for (i, line) in wrap(labels.caption, 130).iter().enumerate() {
        foot.draw_text(
            line,
            &("sans-serif", 13).into_font().color(&BLACK.mix(0.7)),
            (10, 6 + 17 * i as i32),
        )
        .map_err(|e| Error::image(path, e))?;
    }
    let mut chart = ChartBuilder::on(&plot)
        .caption(labels.title, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(
            (x_range.0..x_range.1)
                .log_scale()
                .with_key_points(log_ticks(x_range)),
            (y_range.0..y_range.1)
                .log_scale()
                .with_key_points(log_ticks(y_range)),
        )
        .map_err(|e| Error::image(path, e))?;
    chart
        .configure_mesh()
        .x_desc(labels.x)
        .y_desc(labels.y)
        .x_label_formatter(&|v| num(*v, 1))
        .y_label_formatter(&|v| num(*v, 1))
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(|e| Error::image(path, e))?;
    let shown = series.iter().filter(|s| s.points.iter().any(plottable));
    for (i, s) in shown.enumerate() {
        let color = COLORS[i % COLORS.len()].to_rgba();
        let points: Vec<(f64, f64)> = s.points.iter().copied().filter(plottable).collect();
        if s.line {
            chart
                .draw_series(LineSeries::new(points.clone(), color.stroke_width(2)))
                .map_err(|e| Error::image(path, e))?;
        }
        chart
            .draw_series(points.iter().map(|&p| Circle::new(p, 4, color.filled())))
            .map_err(|e| Error::image(path, e))?;
        let y = 50 + 20 * i as i32;
        legend
            .draw(&Circle::new((12, y), 5, color.filled()))
            .map_err(|e| Error::image(path, e))?;
        legend
            .draw_text(
                &s.name,
                &("sans-serif", 13).into_font().color(&BLACK),
                (24, y - 7),
            )
            .map_err(|e| Error::image(path, e))?;
    }
    root.present().map_err(|e| Error::image(path, e))
}
