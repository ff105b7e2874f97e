//! SVG plots for the HTML report, drawn with `plotters` (SVG backend only).
//!
//! Fonts: plotters is built without a font backend (`default-features = false`, no `ttf` or
//! `ab_glyph`), so it uses its "naive" font module: label sizes are estimated from the
//! character count and every text is written as an SVG `<text>` element with the generic
//! family `sans-serif`. No font file and no system font is read at build or run time; the
//! browser chooses its own sans-serif when it displays the report.
//!
//! Output is deterministic: the same [`Figure`] gives the same bytes (plotters works in integer
//! pixels, nothing depends on time or environment). [`Figure::to_svg`] strips the fixed size and
//! the XML namespace URL so the SVG scales to its container and the report holds no URL.
//!
//! Building blocks: a [`Figure`] is one or more stacked [`Panel`]s (e.g. a calibration curve over
//! its residuals); a panel has two [`Axis`]es (linear or logarithmic, with label and unit),
//! [`Series`] (line, markers, dashed line, optional error bars), labelled points
//! ([`Annotation`], for Allan read-offs) and reference lines ([`RefLine`], for smoothing windows,
//! zero lines or limits). The functions at the end build the generic plot kinds.

use plotters::coord::ranged1d::{AsRangedCoord, Ranged, ValueFormatter};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::ops::Range;

/// Colours of the series, by index (colour-blind-safe Okabe-Ito order).
pub const PALETTE: [(u8, u8, u8); 7] =
    [(0, 114, 178), (213, 94, 0), (0, 158, 115), (204, 121, 167), (86, 180, 233), (230, 159, 0), (0, 0, 0)];

/// Why a figure could not be drawn.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("cannot draw the plot '{figure}': {message}")]
pub struct PlotError {
    /// Title of the figure.
    pub figure: String,
    /// What went wrong.
    pub message: String,
}

/// Scale of an axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scale {
    /// Linear.
    Linear,
    /// Base-10 logarithmic (values must be positive; others are left out).
    Log,
}

/// One axis: its label with unit, e.g. `rate (deg/s)`, its scale and an optional fixed range.
#[derive(Debug, Clone, PartialEq)]
pub struct Axis {
    /// Label including the unit in parentheses.
    pub label: String,
    /// Linear or logarithmic.
    pub scale: Scale,
    /// Fixed range; `None` fits the data with a margin.
    pub range: Option<(f64, f64)>,
    /// Label only whole-number ticks (run numbers, counts).
    pub integer: bool,
}

impl Axis {
    /// A linear axis fitted to the data.
    pub fn linear(label: impl Into<String>) -> Axis {
        Axis { label: label.into(), scale: Scale::Linear, range: None, integer: false }
    }

    /// A logarithmic axis fitted to the data.
    pub fn log(label: impl Into<String>) -> Axis {
        Axis { label: label.into(), scale: Scale::Log, range: None, integer: false }
    }
}

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SeriesStyle {
    /// Solid line through the points.
    Line,
    /// Dashed line (fits, asymptotes).
    Dashed,
    /// Circle markers only.
    Markers,
    /// Line and circle markers.
    LineMarkers,
    /// Small cross markers (many points, e.g. every run).
    Crosses,
}

/// A data series with its legend name.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend entry; empty for none.
    pub name: String,
    /// Points (x, y).
    pub points: Vec<(f64, f64)>,
    /// Drawing style.
    pub style: SeriesStyle,
    /// Index into [`PALETTE`] (wraps).
    pub colour: usize,
    /// Error bars (lower, upper y) per point, same length as `points`, or empty.
    pub error_bars: Vec<(f64, f64)>,
}

impl Series {
    /// A series of the given style and colour.
    pub fn new(name: impl Into<String>, points: Vec<(f64, f64)>, style: SeriesStyle, colour: usize) -> Series {
        Series { name: name.into(), points, style, colour, error_bars: Vec::new() }
    }

    /// Adds error bars (lower, upper y per point).
    pub fn with_error_bars(mut self, bars: Vec<(f64, f64)>) -> Series {
        self.error_bars = bars;
        self
    }
}

/// A labelled point (e.g. the N, B, K read-offs of an Allan plot).
#[derive(Debug, Clone, PartialEq)]
pub struct Annotation {
    /// Position x.
    pub x: f64,
    /// Position y.
    pub y: f64,
    /// Label written beside the point.
    pub text: String,
}

/// Orientation of a reference line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Orientation {
    /// Vertical line at an x value.
    Vertical,
    /// Horizontal line at a y value.
    Horizontal,
}

/// A reference line across the plot area with an optional label (zero line, window, limit).
#[derive(Debug, Clone, PartialEq)]
pub struct RefLine {
    /// Vertical or horizontal.
    pub orientation: Orientation,
    /// Position on its axis.
    pub at: f64,
    /// Label; empty for none.
    pub label: String,
}

/// Where a panel's legend sits.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LegendCorner {
    /// Upper left (the default).
    #[default]
    UpperLeft,
    /// Upper right (Allan curves, which fall from the upper left).
    UpperRight,
    /// Lower left.
    LowerLeft,
    /// Lower right.
    LowerRight,
}

/// One plot area with its axes and content.
#[derive(Debug, Clone, PartialEq)]
pub struct Panel {
    /// Panel caption; empty for none.
    pub caption: String,
    /// Horizontal axis.
    pub x: Axis,
    /// Vertical axis.
    pub y: Axis,
    /// Data series, drawn in order.
    pub series: Vec<Series>,
    /// Labelled points.
    pub annotations: Vec<Annotation>,
    /// Reference lines.
    pub ref_lines: Vec<RefLine>,
    /// Relative height among the figure's panels.
    pub weight: f64,
    /// Legend position.
    pub legend: LegendCorner,
}

impl Panel {
    /// An empty panel with the given axes.
    pub fn new(x: Axis, y: Axis) -> Panel {
        Panel {
            caption: String::new(),
            x,
            y,
            series: Vec::new(),
            annotations: Vec::new(),
            ref_lines: Vec::new(),
            weight: 1.0,
            legend: LegendCorner::UpperLeft,
        }
    }

    /// Puts the legend (when any series has a name) in the corner whose box (the outer 40 % of the width and 30 % of the height
    /// of the data's extent) holds the fewest points and line segments, so that it covers no data
    /// where some corner is free; ties keep the order upper left, upper right, lower left, lower
    /// right. When every corner holds data, the vertical range is widened by a third above the
    /// data and the legend goes to the upper left, over the added headroom.
    pub fn place_legend(&mut self) {
        if self.series.iter().all(|s| s.name.is_empty()) {
            return;
        }
        let tf = |s: Scale, v: f64| match s {
            Scale::Linear => Some(v),
            Scale::Log if v > 0.0 => Some(v.log10()),
            Scale::Log => None,
        };
        let mut pts: Vec<(f64, f64)> = Vec::new();
        for s in &self.series {
            let p: Vec<(f64, f64)> =
                s.points.iter().filter_map(|&(x, y)| Some((tf(self.x.scale, x)?, tf(self.y.scale, y)?))).collect();
            // Lines: also their midpoints, so a line through a corner counts there.
            if matches!(s.style, SeriesStyle::Line | SeriesStyle::Dashed | SeriesStyle::LineMarkers) {
                for w in p.windows(2) {
                    for k in 1..8 {
                        let f = k as f64 / 8.0;
                        pts.push((w[0].0 + f * (w[1].0 - w[0].0), w[0].1 + f * (w[1].1 - w[0].1)));
                    }
                }
            }
            pts.extend(p);
        }
        pts.extend(self.annotations.iter().filter_map(|a| Some((tf(self.x.scale, a.x)?, tf(self.y.scale, a.y)?))));
        let finite: Vec<(f64, f64)> = pts.into_iter().filter(|p| p.0.is_finite() && p.1.is_finite()).collect();
        if finite.is_empty() {
            return;
        }
        let ext = |f: fn(&(f64, f64)) -> f64| {
            finite.iter().map(f).fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| (l.min(v), h.max(v)))
        };
        let ((x0, x1), (y0, y1)) = (ext(|p| p.0), ext(|p| p.1));
        let (xs, ys) = ((x1 - x0).max(f64::MIN_POSITIVE), (y1 - y0).max(f64::MIN_POSITIVE));
        let count = |left: bool, upper: bool| {
            finite
                .iter()
                .filter(|p| {
                    let fx = (p.0 - x0) / xs;
                    let fy = (p.1 - y0) / ys;
                    (if left { fx <= 0.4 } else { fx >= 0.6 }) && (if upper { fy >= 0.7 } else { fy <= 0.3 })
                })
                .count()
        };
        let corners = [
            (LegendCorner::UpperLeft, count(true, true)),
            (LegendCorner::UpperRight, count(false, true)),
            (LegendCorner::LowerLeft, count(true, false)),
            (LegendCorner::LowerRight, count(false, false)),
        ];
        let best = corners.iter().min_by_key(|c| c.1).copied().unwrap_or((LegendCorner::UpperLeft, 0));
        if best.1 == 0 || self.y.range.is_some() || self.y.scale != Scale::Linear {
            self.legend = best.0;
        } else {
            self.y.range = Some((y0 - 0.05 * ys, y1 + 0.45 * ys));
            self.legend = LegendCorner::UpperLeft;
        }
    }
}

/// A figure: stacked panels under a title.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// Title (also the SVG's accessible name).
    pub title: String,
    /// Panels from top to bottom.
    pub panels: Vec<Panel>,
    /// Width in SVG pixels.
    pub width: u32,
    /// Height in SVG pixels.
    pub height: u32,
}

impl Figure {
    /// A figure of the default size (760 x 440) with one panel.
    pub fn single(title: impl Into<String>, panel: Panel) -> Figure {
        Figure { title: title.into(), panels: vec![panel], width: 760, height: 440 }
    }

    /// Draws the figure as an inline SVG element (no XML header, no namespace URL, scalable).
    pub fn to_svg(&self) -> Result<String, PlotError> {
        let err = |m: String| PlotError { figure: self.title.clone(), message: m };
        if self.panels.is_empty() {
            return Err(err("the figure has no panel".into()));
        }
        let mut buf = String::new();
        {
            let root = SVGBackend::with_string(&mut buf, (self.width, self.height)).into_drawing_area();
            root.fill(&WHITE).map_err(|e| err(e.to_string()))?;
            let root = root.titled(&self.title, ("sans-serif", px(17.0))).map_err(|e| err(e.to_string()))?;
            let total: f64 = self.panels.iter().map(|p| p.weight.max(0.05)).sum();
            let height = root.dim_in_pixel().1 as f64;
            let mut rest = root;
            for (i, panel) in self.panels.iter().enumerate() {
                let area = if i + 1 == self.panels.len() {
                    rest.clone()
                } else {
                    let h = (height * panel.weight.max(0.05) / total).round() as i32;
                    let (top, bottom) = rest.split_vertically(h);
                    rest = bottom;
                    top
                };
                // Every legend goes where it covers no data (when some corner is free).
                let mut placed = panel.clone();
                placed.place_legend();
                draw_panel(&area, &placed).map_err(err)?;
            }
            root_present(&rest).map_err(err)?;
        }
        Ok(clean_svg(&buf, &self.title))
    }
}

fn root_present(area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>) -> Result<(), String> {
    area.present().map_err(|e| e.to_string())
}

/// Makes plotters' SVG inline-ready: drops the fixed width/height and the namespace URL, adds
/// an accessible name.
fn clean_svg(svg: &str, title: &str) -> String {
    let body = match svg.find('>') {
        Some(end) if svg.starts_with("<svg") => &svg[end + 1..],
        _ => svg,
    };
    let view_box =
        svg.split("viewBox=\"").nth(1).and_then(|s| s.split('"').next()).unwrap_or("0 0 760 440").to_string();
    let body = body.replace(">\n", ">").replace("\n</text>", "</text>").replace("><", ">\n<");
    format!(
        "<svg class=\"plot\" viewBox=\"{view_box}\" role=\"img\" aria-label=\"{}\" preserveAspectRatio=\"xMidYMid meet\">{body}",
        html_attr(title)
    )
}

/// Font size for plotters, which writes `size / 1.24` into the SVG: gives `size` pixels.
fn px(size: f64) -> f64 {
    size * 1.24
}

fn html_attr(s: &str) -> String {
    s.replace('&', "&amp;").replace('"', "&quot;").replace('<', "&lt;").replace('>', "&gt;")
}

fn colour(i: usize) -> RGBColor {
    let (r, g, b) = PALETTE[i % PALETTE.len()];
    RGBColor(r, g, b)
}

/// The data range of a panel along one axis (series, error bars, annotations, ref lines).
fn data_range(panel: &Panel, horizontal: bool, scale: Scale) -> (f64, f64) {
    let mut v: Vec<f64> = Vec::new();
    for s in &panel.series {
        for (i, &(x, y)) in s.points.iter().enumerate() {
            if horizontal {
                v.push(x);
            } else {
                v.push(y);
                if let Some(&(lo, hi)) = s.error_bars.get(i) {
                    v.extend([lo, hi]);
                }
            }
        }
    }
    v.extend(panel.annotations.iter().map(|a| if horizontal { a.x } else { a.y }));
    let want = if horizontal { Orientation::Vertical } else { Orientation::Horizontal };
    v.extend(panel.ref_lines.iter().filter(|r| r.orientation == want).map(|r| r.at));
    let v: Vec<f64> = v.into_iter().filter(|x| x.is_finite() && (scale == Scale::Linear || *x > 0.0)).collect();
    let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if !lo.is_finite() || !hi.is_finite() {
        return if scale == Scale::Log { (0.1, 10.0) } else { (-1.0, 1.0) };
    }
    match scale {
        Scale::Linear => {
            let span = hi - lo;
            let pad = if span > 0.0 { 0.06 * span } else { 0.5 * lo.abs().max(1e-12) };
            (lo - pad, hi + pad)
        }
        Scale::Log => {
            let (l, h) = (lo.log10(), hi.log10());
            let pad = if h > l { 0.08 * (h - l) } else { 0.5 };
            (10f64.powf(l - pad), 10f64.powf(h + pad))
        }
    }
}

fn axis_range(panel: &Panel, horizontal: bool) -> Range<f64> {
    let axis = if horizontal { &panel.x } else { &panel.y };
    let (lo, hi) = axis.range.unwrap_or_else(|| data_range(panel, horizontal, axis.scale));
    lo..hi
}

/// Tick label: short decimal for ordinary magnitudes, 1e-3 style otherwise.
pub fn tick_label(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return if v == 0.0 { "0".into() } else { v.to_string() };
    }
    let a = v.abs();
    if !(1e-3..1e5).contains(&a) {
        let e = a.log10().floor() as i32;
        let m = v / 10f64.powi(e);
        if (m.abs() - 1.0).abs() < 1e-9 {
            return format!("{}1e{e}", if v < 0.0 { "-" } else { "" });
        }
        return format!("{}e{e}", gyrolab::format::short(m, 3));
    }
    gyrolab::format::short(v, 4)
}

/// Tick label of `v` on a linear axis spanning `span`: as many decimals as the tick spacing
/// (about a tenth of the span) needs, so that neighbouring ticks never read the same (a scale
/// factor from 7.4995 to 7.5005 labelled "7.5" three times, issue 53); e-notation outside
/// 1e-3 to 1e5 as [`tick_label`].
pub fn tick_label_in(v: f64, span: f64) -> String {
    if !(span.is_finite() && span > 0.0 && v.is_finite()) {
        return tick_label(v);
    }
    let a = v.abs();
    // Decimals of a step a tenth of the span (plotters places up to about ten ticks), plus one.
    let decimals = |step: f64| ((-step.log10()).ceil() + 1.0).clamp(0.0, 15.0) as usize;
    let trim = |s: String| -> String {
        if !s.contains('.') {
            return s;
        }
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    };
    // Zero, or a tick within a step of it, is 0.
    if a < span * 1e-9 {
        return "0".into();
    }
    if (1e-3..1e5).contains(&a) {
        let s = trim(format!("{:.*}", decimals(span / 10.0), v));
        return if s == "-0" { "0".into() } else { s };
    }
    let e = a.log10().floor() as i32;
    let scale = 10f64.powi(e);
    format!("{}e{e}", trim(format!("{:.*}", decimals(span / 10.0 / scale), v / scale)))
}

fn draw_panel(area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>, panel: &Panel) -> Result<(), String> {
    let xr = axis_range(panel, true);
    let yr = axis_range(panel, false);
    let span = |r: &Range<f64>, scale: Scale| (scale == Scale::Linear).then_some(r.end - r.start);
    // A counted axis (runs, power-ups) gets as many labels as whole numbers in its range, so
    // that its ticks fall on them (no tick at 1.5 runs).
    let labels = |r: &Range<f64>, axis: &Axis, default: usize| {
        if axis.integer && r.end > r.start {
            ((r.end.floor() - r.start.ceil()).max(0.0) as usize + 1).clamp(2, default)
        } else {
            default
        }
    };
    let spans =
        (span(&xr, panel.x.scale), span(&yr, panel.y.scale), labels(&xr, &panel.x, 8), labels(&yr, &panel.y, 6));
    match (panel.x.scale, panel.y.scale) {
        (Scale::Linear, Scale::Linear) => draw_in(area, panel, xr, yr, spans),
        (Scale::Log, Scale::Log) => draw_in(area, panel, xr.log_scale(), yr.log_scale(), spans),
        (Scale::Linear, Scale::Log) => draw_in(area, panel, xr, yr.log_scale(), spans),
        (Scale::Log, Scale::Linear) => draw_in(area, panel, xr.log_scale(), yr, spans),
    }
}

fn draw_in<XS, YS>(
    area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    panel: &Panel,
    xs: XS,
    ys: YS,
    (x_span, y_span, x_labels, y_labels): (Option<f64>, Option<f64>, usize, usize),
) -> Result<(), String>
where
    XS: AsRangedCoord<Value = f64>,
    YS: AsRangedCoord<Value = f64>,
    XS::CoordDescType: ValueFormatter<f64> + Ranged<ValueType = f64>,
    YS::CoordDescType: ValueFormatter<f64> + Ranged<ValueType = f64>,
{
    let e = |x: &dyn std::fmt::Display| x.to_string();
    let mut builder = ChartBuilder::on(area);
    builder.margin(8).margin_right(18).x_label_area_size(44).y_label_area_size(70);
    if !panel.caption.is_empty() {
        builder.caption(&panel.caption, ("sans-serif", px(14.0)));
    }
    let mut chart = builder.build_cartesian_2d(xs, ys).map_err(|x| e(&x))?;
    let label = |v: f64, integer: bool, span: Option<f64>| -> String {
        if integer && v.fract().abs() > 1e-9 {
            return String::new();
        }
        match span {
            Some(s) => tick_label_in(v, s),
            None => tick_label(v),
        }
    };
    let fmt_x = |v: &f64| label(*v, panel.x.integer, x_span);
    let fmt_y = |v: &f64| label(*v, panel.y.integer, y_span);
    chart
        .configure_mesh()
        .x_desc(&panel.x.label)
        .y_desc(&panel.y.label)
        .x_label_formatter(&fmt_x)
        .y_label_formatter(&fmt_y)
        .x_labels(x_labels)
        .y_labels(y_labels)
        .label_style(("sans-serif", px(12.0)))
        .axis_desc_style(("sans-serif", px(13.0)))
        .light_line_style(RGBColor(238, 238, 238))
        .bold_line_style(RGBColor(215, 215, 215))
        .draw()
        .map_err(|x| e(&x))?;
    let (x_lo, x_hi) = (chart.x_range().start, chart.x_range().end);
    let (y_lo, y_hi) = (chart.y_range().start, chart.y_range().end);
    let grey = RGBColor(120, 120, 120);
    for r in &panel.ref_lines {
        let (a, b, label_at, anchor) = match r.orientation {
            Orientation::Vertical => ((r.at, y_lo), (r.at, y_hi), (r.at, y_hi), Pos::new(HPos::Left, VPos::Top)),
            Orientation::Horizontal => ((x_lo, r.at), (x_hi, r.at), (x_hi, r.at), Pos::new(HPos::Right, VPos::Bottom)),
        };
        chart.draw_series(DashedLineSeries::new([a, b], 4, 4, grey.stroke_width(1))).map_err(|x| e(&x))?;
        if !r.label.is_empty() {
            let style = TextStyle::from(("sans-serif", px(11.0)).into_font()).color(&grey).pos(anchor);
            chart.draw_series(std::iter::once(Text::new(r.label.clone(), label_at, style))).map_err(|x| e(&x))?;
        }
    }
    let mut legend = false;
    for s in &panel.series {
        let c = colour(s.colour);
        let pts: Vec<(f64, f64)> = s.points.iter().copied().filter(|(x, y)| x.is_finite() && y.is_finite()).collect();
        for (i, &(x, _)) in s.points.iter().enumerate() {
            if let Some(&(lo, hi)) = s.error_bars.get(i) {
                if lo.is_finite() && hi.is_finite() {
                    chart
                        .draw_series(std::iter::once(PathElement::new(vec![(x, lo), (x, hi)], c.stroke_width(1))))
                        .map_err(|x| e(&x))?;
                    chart
                        .draw_series([lo, hi].into_iter().map(|y| {
                            EmptyElement::at((x, y)) + PathElement::new(vec![(-4, 0), (4, 0)], c.stroke_width(1))
                        }))
                        .map_err(|x| e(&x))?;
                }
            }
        }
        let anno = match s.style {
            SeriesStyle::Line => chart.draw_series(LineSeries::new(pts.clone(), c.stroke_width(2))),
            SeriesStyle::Dashed => chart.draw_series(DashedLineSeries::new(pts.clone(), 7, 4, c.stroke_width(2))),
            SeriesStyle::Markers => chart.draw_series(pts.iter().map(|&p| Circle::new(p, 3, c.filled()))),
            SeriesStyle::LineMarkers => {
                chart.draw_series(LineSeries::new(pts.clone(), c.stroke_width(2))).map_err(|x| e(&x))?;
                chart.draw_series(pts.iter().map(|&p| Circle::new(p, 3, c.filled())))
            }
            SeriesStyle::Crosses => chart.draw_series(pts.iter().map(|&p| Cross::new(p, 4, c.stroke_width(2)))),
        }
        .map_err(|x| e(&x))?;
        if !s.name.is_empty() {
            legend = true;
            let style = s.style;
            let marker = matches!(style, SeriesStyle::Markers | SeriesStyle::Crosses | SeriesStyle::LineMarkers);
            let line = !matches!(style, SeriesStyle::Markers | SeriesStyle::Crosses);
            anno.label(s.name.clone()).legend(move |(x, y)| {
                let line_end = if line { 16 } else { 0 };
                EmptyElement::at((x, y))
                    + PathElement::new(vec![(0, 0), (line_end, 0)], c.stroke_width(2))
                    + Circle::new((8, 0), if marker { 3 } else { 0 }, c.filled())
            });
        }
    }
    for a in &panel.annotations {
        if !(a.x.is_finite() && a.y.is_finite()) {
            continue;
        }
        let black = RGBColor(0, 0, 0);
        chart
            .draw_series(std::iter::once(
                EmptyElement::at((a.x, a.y))
                    + Circle::new((0, 0), 5, black.stroke_width(2))
                    + Text::new(a.text.clone(), (8, -16), ("sans-serif", px(12.0)).into_font()),
            ))
            .map_err(|x| e(&x))?;
    }
    if legend {
        chart
            .configure_series_labels()
            .position(match panel.legend {
                LegendCorner::UpperLeft => SeriesLabelPosition::UpperLeft,
                LegendCorner::UpperRight => SeriesLabelPosition::UpperRight,
                LegendCorner::LowerLeft => SeriesLabelPosition::LowerLeft,
                LegendCorner::LowerRight => SeriesLabelPosition::LowerRight,
            })
            .background_style(WHITE.mix(0.85))
            .border_style(RGBColor(180, 180, 180))
            .label_font(("sans-serif", px(12.0)))
            .draw()
            .map_err(|x| e(&x))?;
    }
    Ok(())
}

/// A time series (e.g. bias in deg/h against time in s) with the smoothing windows marked as
/// vertical reference lines at their boundaries (`windows` = (start, end, label)).
pub fn time_series_plot(
    title: &str,
    y_label: &str,
    series: Vec<Series>,
    windows: &[(f64, f64, String)],
) -> Result<String, PlotError> {
    let mut p = Panel::new(Axis::linear("time (s)"), Axis::linear(y_label));
    p.series = series;
    for (a, b, label) in windows {
        p.ref_lines.push(RefLine { orientation: Orientation::Vertical, at: *a, label: label.clone() });
        p.ref_lines.push(RefLine { orientation: Orientation::Vertical, at: *b, label: String::new() });
    }
    Figure::single(title, p).to_svg()
}

/// A log-log plot (e.g. Allan deviation against tau) with error bars on the measured series,
/// dashed asymptote lines and labelled read-off points.
pub fn log_log_plot(
    title: &str,
    x_label: &str,
    y_label: &str,
    measured: Series,
    asymptotes: Vec<Series>,
    read_offs: Vec<Annotation>,
) -> Result<String, PlotError> {
    let mut p = Panel::new(Axis::log(x_label), Axis::log(y_label));
    p.series.push(measured);
    p.series.extend(asymptotes.into_iter().map(|mut s| {
        s.style = SeriesStyle::Dashed;
        s
    }));
    p.annotations = read_offs;
    p.legend = LegendCorner::UpperRight;
    Figure::single(title, p).to_svg()
}

/// A scatter plot with its least-squares line (e.g. bias against temperature); the line is
/// `intercept + slope * x` drawn over the data's x range.
pub fn scatter_fit_plot(
    title: &str,
    x_label: &str,
    y_label: &str,
    points: Vec<(f64, f64)>,
    fit: Option<(f64, f64, String)>,
) -> Result<String, PlotError> {
    let mut p = Panel::new(Axis::linear(x_label), Axis::linear(y_label));
    let lo = points.iter().map(|p| p.0).fold(f64::INFINITY, f64::min);
    let hi = points.iter().map(|p| p.0).fold(f64::NEG_INFINITY, f64::max);
    p.series.push(Series::new("measured", points, SeriesStyle::Markers, 0));
    if let Some((intercept, slope, name)) = fit {
        if lo.is_finite() && hi.is_finite() {
            let line = vec![(lo, intercept + slope * lo), (hi, intercept + slope * hi)];
            p.series.push(Series::new(name, line, SeriesStyle::Line, 1));
        }
    }
    Figure::single(title, p).to_svg()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn demo_figure() -> Figure {
        let mut p = Panel::new(Axis::linear("rate (deg/s)"), Axis::linear("output (V)"));
        p.series.push(Series::new("points", vec![(-1.0, 1.0), (0.0, 2.0), (1.0, 3.1)], SeriesStyle::Markers, 0));
        p.series.push(Series::new("line", vec![(-1.0, 0.95), (1.0, 3.05)], SeriesStyle::Line, 1));
        Figure::single("test figure", p)
    }

    #[test]
    fn legend_goes_to_a_corner_without_data() {
        let panel = |pts: Vec<(f64, f64)>| {
            let mut p = Panel::new(Axis::linear("x"), Axis::linear("y"));
            p.series.push(Series::new("d", pts, SeriesStyle::Markers, 0));
            p.place_legend();
            p
        };
        // Rising points fill the lower left and upper right: the upper left is free.
        let rising: Vec<(f64, f64)> = (0..11).map(|i| (i as f64, i as f64)).collect();
        assert_eq!(panel(rising).legend, LegendCorner::UpperLeft);
        // Points in every corner but the lower right.
        let p = panel(vec![(0.0, 0.0), (0.0, 10.0), (10.0, 10.0), (5.0, 5.0)]);
        assert_eq!(p.legend, LegendCorner::LowerRight);
        // Data in all four corners: headroom above (range widened by 45 % of the span) and upper left.
        let p = panel(vec![(0.0, 0.0), (0.0, 10.0), (10.0, 10.0), (10.0, 0.0)]);
        assert_eq!((p.legend, p.y.range), (LegendCorner::UpperLeft, Some((-0.5, 14.5))));
    }

    /// Tick labels that always differ, and counted axes on whole numbers (issue 53: the per-run
    /// scale-factor plot labelled two ticks "7.5" and put ticks at fractional runs).
    #[test]
    fn tick_labels_differ_and_counted_axes_carry_whole_numbers() {
        let mut runs = Axis::linear("run");
        runs.integer = true;
        let mut p = Panel::new(runs, Axis::linear("scale factor (mV/(deg/s))"));
        let k = [7.49962, 7.50031, 7.49987, 7.50018];
        p.series.push(Series::new(
            "K of the run",
            k.iter().enumerate().map(|(i, &k)| ((i + 1) as f64, k)).collect(),
            SeriesStyle::LineMarkers,
            0,
        ));
        let svg = Figure::single("scale factor per run", p).to_svg().unwrap();
        // Every text element's content: the tick labels are among them.
        let texts: Vec<&str> =
            svg.split("<text").skip(1).filter_map(|t| t.split('>').nth(1)?.split('<').next()).collect();
        let numbers: Vec<f64> = texts.iter().filter_map(|t| t.trim().parse::<f64>().ok()).collect();
        let y: Vec<&str> = texts.iter().copied().filter(|t| t.starts_with("7.")).collect();
        assert!(y.len() >= 3, "{texts:?}");
        let mut distinct = y.clone();
        distinct.sort();
        distinct.dedup();
        assert_eq!(distinct.len(), y.len(), "every y tick reads differently: {y:?}");
        let x: Vec<f64> = numbers.iter().copied().filter(|v| *v < 7.0).collect();
        assert!(x.len() >= 3 && x.iter().all(|v| v.fract() == 0.0), "{x:?}");
        assert_eq!(tick_label_in(7.5005, 0.001), "7.5005");
        assert_eq!(tick_label_in(7.5, 0.001), "7.5");
        assert_eq!(tick_label_in(-1e-17, 1.0), "0");
        assert_eq!(tick_label_in(2.5e-6, 1e-6), "2.5e-6");
        assert_eq!(tick_label_in(3.0, 4.0), "3");
    }

    #[test]
    fn svg_is_inline_deterministic_and_has_labels() {
        let a = demo_figure().to_svg().unwrap();
        let b = demo_figure().to_svg().unwrap();
        assert_eq!(a, b);
        assert!(a.starts_with("<svg class=\"plot\" viewBox=\"0 0 760 440\""), "{}", &a[..200]);
        assert!(!a.contains("http"), "no namespace URL");
        assert!(a.contains(">rate (deg/s)<") && a.contains(">output (V)<"));
        assert!(a.contains(">points<") && a.contains(">line<"), "legend entries");
        assert!(a.contains("font-family=\"sans-serif\""));
        assert!(a.trim_end().ends_with("</svg>"));
    }

    #[test]
    fn log_log_with_error_bars_and_read_offs() {
        let m = Series::new("ADEV", vec![(1.0, 1.0), (10.0, 0.32), (100.0, 0.2)], SeriesStyle::LineMarkers, 0)
            .with_error_bars(vec![(0.9, 1.1), (0.28, 0.36), (0.15, 0.27)]);
        let n = Series::new("N asymptote", vec![(1.0, 1.0), (100.0, 0.1)], SeriesStyle::Line, 1);
        let r = vec![Annotation { x: 1.0, y: 1.0, text: "N = 1".into() }];
        let s = log_log_plot("Allan", "tau (s)", "ADEV (deg/h)", m, vec![n], r).unwrap();
        assert!(s.contains(">N = 1<") && s.contains(">tau (s)<"));
        assert!(s.contains("stroke-dasharray") || s.contains("<polyline"), "asymptote drawn");
    }

    #[test]
    fn generic_builders_and_ticks() {
        let t = time_series_plot(
            "bias",
            "bias (deg/h)",
            vec![Series::new("raw", vec![(0.0, 1.0), (1.0, 2.0)], SeriesStyle::Line, 0)],
            &[(0.0, 0.5, "T = 0.5 s".into())],
        )
        .unwrap();
        assert!(t.contains(">T = 0.5 s<"));
        let s =
            scatter_fit_plot("t", "temperature (degC)", "bias (deg/h)", vec![(20.0, 1.0), (30.0, 2.0)], None).unwrap();
        assert!(s.contains(">temperature (degC)<"));
        assert_eq!(tick_label(0.001), "0.001");
        assert_eq!(tick_label(1e-4), "1e-4");
        assert_eq!(tick_label(2.5e-5), "2.5e-5");
        assert_eq!(tick_label(250.0), "250");
        let empty = Figure { title: "e".into(), panels: vec![], width: 10, height: 10 };
        assert!(empty.to_svg().is_err());
    }
}
