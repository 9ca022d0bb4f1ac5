//! Charts drawn with plotters as PNG (bitmap backend) or SVG, the same drawing code for
//! both; the bundled DejaVu font measures the text, so no system fonts are needed.
//!
//! Files are rendered to a temporary name and renamed, so a chart on disk is always whole.
//! Palette, ticks and number format are [`style`]'s.

pub mod style;
use style::Ticks;
pub use style::PALETTE;

use anyhow::{Context, Result};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::FontStyle;
use std::path::Path;
use std::sync::Once;

/// The file format of every chart a command writes (`--figure-format`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum FigureFormat {
    #[default]
    Png,
    /// Vector graphics, for papers: the same content as the PNG.
    Svg,
}

impl FigureFormat {
    pub fn extension(self) -> &'static str {
        match self {
            FigureFormat::Png => "png",
            FigureFormat::Svg => "svg",
        }
    }

    /// The format a file name asks for: SVG for `.svg`, else PNG.
    pub fn of_path(path: &Path) -> Self {
        match path.extension() {
            Some(e) if e.eq_ignore_ascii_case("svg") => FigureFormat::Svg,
            _ => FigureFormat::Png,
        }
    }
}

/// Renders through a `draw` function generic over the backend into a temporary file beside
/// `path` (its extension replaced by the format's), then renames it into place.
fn render(
    path: &Path,
    format: FigureFormat,
    size: (u32, u32),
    draw: impl Fn(DrawingArea<BitMapBackend, Shift>) -> Result<()>,
    draw_svg: impl Fn(DrawingArea<SVGBackend, Shift>) -> Result<()>,
) -> Result<()> {
    register_fonts();
    let path = path.with_extension(format.extension());
    let file_name = path
        .file_name()
        .context("chart path has no file name")?
        .to_string_lossy();
    let tmp = path.with_file_name(format!(".{file_name}.tmp.{}", format.extension()));
    match format {
        FigureFormat::Png => draw(BitMapBackend::new(&tmp, size).into_drawing_area())?,
        FigureFormat::Svg => draw_svg(SVGBackend::new(&tmp, size).into_drawing_area())?,
    }
    std::fs::rename(&tmp, &path).with_context(|| format!("renaming {}", tmp.display()))
}

/// How a curve is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CurveStyle {
    Line,
    Dashed,
    /// Filled circles.
    Markers,
    /// Crosses (a second kind of point that tells apart without colour).
    Crosses,
    /// Open triangles (a third).
    Triangles,
}

/// One data series of a chart.
#[derive(Clone, Debug)]
pub struct Curve {
    pub label: String,
    pub points: Vec<(f64, f64)>,
    pub style: CurveStyle,
    pub color: RGBColor,
}

/// Axes and title of a chart.
#[derive(Clone, Debug, Default)]
pub struct Chart {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    /// Logarithmic y axis (data must be positive; others are dropped).
    pub log_y: bool,
    /// Logarithmic x axis.
    pub log_x: bool,
    /// Optional note drawn in the top-left corner (e.g. a fitted order).
    pub note: Option<String>,
    /// Fixed y range (after the log transform), e.g. to leave room for the legend.
    pub y_range: Option<(f64, f64)>,
    /// A categorical y axis: row k (y = k) is named `y_categories[k]` (empty: numeric).
    pub y_categories: Vec<String>,
}

fn register_fonts() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The bundled font is known-good; a failure here would only lose the labels.
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            dejavu::sans::regular(),
        );
    });
}

fn transform(v: f64, log: bool) -> Option<f64> {
    if log {
        (v > 0.0 && v.is_finite()).then(|| v.log10())
    } else {
        v.is_finite().then_some(v)
    }
}

/// Draws `curves` to `path` (800×560) in `format`; the extension of `path` is replaced by
/// the format's.
pub fn draw(path: &Path, format: FigureFormat, chart: &Chart, curves: &[Curve]) -> Result<()> {
    let data: Vec<Vec<(f64, f64)>> = curves
        .iter()
        .map(|c| {
            c.points
                .iter()
                .filter_map(|&(x, y)| {
                    Some((transform(x, chart.log_x)?, transform(y, chart.log_y)?))
                })
                .collect()
        })
        .collect();
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for &(x, y) in data.iter().flatten() {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    if !x0.is_finite() {
        (x0, x1, y0, y1) = (0.0, 1.0, 0.0, 1.0);
    }
    if x1 - x0 < 1e-12 {
        x1 = x0 + 1.0;
    }
    if chart.log_x {
        // Points of a sweep (Wi, resolution) sit at the ends of the axis: keep them whole.
        let pad = 0.04 * (x1 - x0);
        (x0, x1) = (x0 - pad, x1 + pad);
    }
    let pad = if y1 - y0 < 1e-12 {
        0.5
    } else {
        0.05 * (y1 - y0)
    };
    let (y0, y1) = chart.y_range.unwrap_or((y0 - pad, y1 + pad));

    let axes = Axes {
        x: (x0..x1, ticks(x0, x1, chart.log_x)),
        y: (y0..y1, y_ticks(chart, y0..y1)),
    };
    let longest = chart.y_categories.iter().map(|n| n.chars().count()).max();
    let width = longest.map_or(800, |n| 800 + 7 * n as u32);
    render(
        path,
        format,
        (width, 560),
        |root| draw_curves(root, chart, curves, &data, &axes),
        |root| draw_curves(root, chart, curves, &data, &axes),
    )
}

/// The two axes of a chart: range and ticks, in the drawn coordinate.
struct Axes {
    x: (std::ops::Range<f64>, Ticks),
    y: (std::ops::Range<f64>, Ticks),
}

fn ticks(lo: f64, hi: f64, log: bool) -> Ticks {
    if log {
        style::log_ticks(lo, hi)
    } else {
        style::linear_ticks(lo, hi)
    }
}

/// A linear coordinate whose grid and labels are at the given ticks.
struct Ticked {
    inner: plotters::coord::types::RangedCoordf64,
    major: Vec<f64>,
    minor: Vec<f64>,
}

impl Ticked {
    fn new(range: &std::ops::Range<f64>, ticks: &Ticks) -> Self {
        Self {
            inner: range.clone().into(),
            major: ticks.major.clone(),
            minor: ticks.minor.clone(),
        }
    }
}

impl Ranged for Ticked {
    type FormatOption = plotters::coord::ranged1d::DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        self.inner.map(value, limit)
    }

    fn key_points<H: plotters::coord::ranged1d::KeyPointHint>(&self, hint: H) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            self.minor.clone()
        } else {
            self.major.clone()
        }
    }

    fn range(&self) -> std::ops::Range<f64> {
        self.inner.range()
    }
}

/// The y ticks: one per category, or numeric.
fn y_ticks(chart: &Chart, range: std::ops::Range<f64>) -> Ticks {
    if chart.y_categories.is_empty() {
        return ticks(range.start, range.end, chart.log_y);
    }
    Ticks {
        major: (0..chart.y_categories.len()).map(|k| k as f64).collect(),
        minor: Vec::new(),
        step: 1.0,
    }
}

fn draw_curves<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    chart: &Chart,
    curves: &[Curve],
    data: &[Vec<(f64, f64)>],
    axes: &Axes,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let ((xs, xt), (ys, yt)) = (&axes.x, &axes.y);
    let longest = chart.y_categories.iter().map(|n| n.chars().count()).max();
    let mut cc = ChartBuilder::on(&root)
        .caption(&chart.title, ("sans-serif", 22))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(longest.map_or(70, |n| 20 + 8 * n as u32))
        .build_cartesian_2d(Ticked::new(xs, xt), Ticked::new(ys, yt))?;
    let x_label = |v: &f64| style::label(*v, chart.log_x, xt.step);
    let y_label = |v: &f64| match chart.y_categories.get(v.round().max(0.0) as usize) {
        Some(name) if !chart.y_categories.is_empty() => name.clone(),
        _ => style::label(*v, chart.log_y, yt.step),
    };
    cc.configure_mesh()
        .x_desc(&chart.x_label)
        .y_desc(&chart.y_label)
        .x_label_formatter(&x_label)
        .y_label_formatter(&y_label)
        .label_style(("sans-serif", 14))
        .light_line_style(RGBColor(235, 235, 235))
        .draw()?;
    for (curve, pts) in curves.iter().zip(data) {
        let color = curve.color;
        let series = match curve.style {
            CurveStyle::Line => {
                cc.draw_series(LineSeries::new(pts.iter().copied(), color.stroke_width(2)))?
            }
            CurveStyle::Dashed => cc.draw_series(DashedLineSeries::new(
                pts.iter().copied(),
                8,
                5,
                color.stroke_width(2),
            ))?,
            CurveStyle::Markers => {
                cc.draw_series(pts.iter().map(|&p| Circle::new(p, 4, color.filled())))?
            }
            CurveStyle::Crosses => {
                cc.draw_series(pts.iter().map(|&p| Cross::new(p, 5, color.stroke_width(2))))?
            }
            CurveStyle::Triangles => cc.draw_series(
                pts.iter()
                    .map(|&p| TriangleMarker::new(p, 6, color.stroke_width(2))),
            )?,
        };
        if !curve.label.is_empty() {
            let kind = curve.style;
            series.label(curve.label.clone()).legend(move |(x, y)| {
                let mark = (x + 10, y);
                match kind {
                    CurveStyle::Markers => Circle::new(mark, 4, color.filled()).into_dyn(),
                    CurveStyle::Crosses => Cross::new(mark, 5, color.stroke_width(2)).into_dyn(),
                    CurveStyle::Triangles => {
                        TriangleMarker::new(mark, 6, color.stroke_width(2)).into_dyn()
                    }
                    _ => PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
                        .into_dyn(),
                }
            });
        }
    }
    if curves.iter().any(|c| !c.label.is_empty()) {
        cc.configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 14))
            .position(SeriesLabelPosition::UpperRight)
            .draw()?;
    }
    if let Some(note) = &chart.note {
        root.draw_text(note, &("sans-serif", 16).into_text_style(&root), (90, 45))?;
    }
    root.present()?;
    Ok(())
}

/// A scalar field on the particles, drawn as squares of side δr coloured by value.
#[derive(Clone, Debug)]
pub struct Field<'a> {
    pub title: String,
    /// (x, y) of each particle.
    pub points: &'a [(f64, f64)],
    pub values: &'a [f64],
    /// The box [x0, x1] × [y0, y1].
    pub extent: ((f64, f64), (f64, f64)),
    pub spacing: f64,
    /// Diverging blue–white–red map symmetric about zero (vorticity), else a sequential map.
    pub diverging: bool,
    /// A solid disc drawn in grey (centre, radius).
    pub disc: Option<((f64, f64), f64)>,
}

fn lerp_colour(stops: &[(f64, [f64; 3])], t: f64) -> RGBColor {
    let t = t.clamp(0.0, 1.0);
    let k = stops
        .windows(2)
        .position(|w| t <= w[1].0)
        .unwrap_or(stops.len() - 2);
    let (a, b) = (stops[k], stops[k + 1]);
    let f = if b.0 > a.0 {
        (t - a.0) / (b.0 - a.0)
    } else {
        0.0
    };
    let c = |i: usize| (255.0 * (a.1[i] + f * (b.1[i] - a.1[i]))).round() as u8;
    RGBColor(c(0), c(1), c(2))
}

/// The colour of `t` ∈ [0, 1] on the map.
pub fn colour_map(t: f64, diverging: bool) -> RGBColor {
    if diverging {
        lerp_colour(
            &[
                (0.0, [0.02, 0.19, 0.55]),
                (0.5, [0.97, 0.97, 0.97]),
                (1.0, [0.60, 0.03, 0.05]),
            ],
            t,
        )
    } else {
        // Close to viridis.
        lerp_colour(
            &[
                (0.0, [0.267, 0.005, 0.329]),
                (0.25, [0.230, 0.322, 0.546]),
                (0.5, [0.128, 0.567, 0.551]),
                (0.75, [0.369, 0.789, 0.383]),
                (1.0, [0.993, 0.906, 0.144]),
            ],
            t,
        )
    }
}

/// Draws a particle field with a colour bar to `path` in `format` (extension replaced).
pub fn draw_field(path: &Path, format: FigureFormat, field: &Field) -> Result<()> {
    let finite = field.values.iter().copied().filter(|v| v.is_finite());
    let (mut lo, mut hi) = finite.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
        (a.min(v), b.max(v))
    });
    if !lo.is_finite() {
        (lo, hi) = (0.0, 1.0);
    }
    if field.diverging {
        let m = lo.abs().max(hi.abs()).max(1e-300);
        (lo, hi) = (-m, m);
    }
    if hi - lo < 1e-300 {
        hi = lo + 1.0;
    }
    let ((x0, x1), (y0, y1)) = field.extent;
    let (w, h) = (x1 - x0, y1 - y0);
    let plot_w = 900u32;
    let plot_h = ((plot_w as f64 - 110.0) * h / w + 90.0)
        .round()
        .clamp(200.0, 1400.0) as u32;
    let size = (plot_w + 110, plot_h);
    render(
        path,
        format,
        size,
        |root| draw_particles(root, field, plot_w, lo..hi),
        |root| draw_particles(root, field, plot_w, lo..hi),
    )
}

fn draw_particles<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    field: &Field,
    plot_w: u32,
    colour_range: std::ops::Range<f64>,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let (lo, hi) = (colour_range.start, colour_range.end);
    let ((x0, x1), (y0, y1)) = field.extent;
    root.fill(&WHITE)?;
    let (left, right) = root.split_horizontally(plot_w);
    let mut cc = ChartBuilder::on(&left)
        .caption(&field.title, ("sans-serif", 20))
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(45)
        .build_cartesian_2d(x0..x1, y0..y1)?;
    cc.configure_mesh()
        .disable_mesh()
        .label_style(("sans-serif", 13))
        .draw()?;
    let half = 0.5 * field.spacing;
    cc.draw_series(field.points.iter().zip(field.values).map(|(&(x, y), &v)| {
        let c = colour_map((v - lo) / (hi - lo), field.diverging);
        Rectangle::new([(x - half, y - half), (x + half, y + half)], c.filled())
    }))?;
    if let Some(((cx, cy), r)) = field.disc {
        let ring: Vec<(f64, f64)> = (0..=180)
            .map(|k| {
                let a = 2.0 * std::f64::consts::PI * k as f64 / 180.0;
                (cx + r * a.cos(), cy + r * a.sin())
            })
            .collect();
        cc.draw_series(std::iter::once(Polygon::new(
            ring,
            RGBColor(160, 160, 160).filled(),
        )))?;
    }
    // Colour bar.
    let bar = ChartBuilder::on(&right)
        .margin_top(45)
        .margin_bottom(45)
        .margin_right(10)
        .y_label_area_size(70)
        .build_cartesian_2d(0.0..1.0, lo..hi);
    let mut bar = bar?;
    bar.configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_label_formatter(&|v| style::label(*v, false, style::linear_ticks(lo, hi).step))
        .label_style(("sans-serif", 12))
        .draw()?;
    let steps = 100;
    bar.draw_series((0..steps).map(|k| {
        let a = lo + (hi - lo) * k as f64 / steps as f64;
        let b = lo + (hi - lo) * (k + 1) as f64 / steps as f64;
        let c = colour_map((k as f64 + 0.5) / steps as f64, field.diverging);
        Rectangle::new([(0.0, a), (1.0, b)], c.filled())
    }))?;
    root.present()?;
    Ok(())
}
