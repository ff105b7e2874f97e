//! The rate-table plots of one axis: calibration curve with residuals (the paper's Figures 1 to
//! 3), hysteresis (forward and reverse stroke means minus the line) and scale factor per run.

use crate::plot::{Axis, Figure, Orientation, Panel, PlotError, RefLine, Series, SeriesStyle};
use gyrolab::format::sig;
use gyrolab_eval::outcome::rate::AxisReport;

/// Unit and factor for small output differences (volts shown in mV).
fn display_unit(a: &AxisReport<'_>) -> (String, f64) {
    let (u, f) = a.output_unit.scale_factor_display();
    (u.symbol().to_string(), f)
}

/// Calibration curve: stroke means against rate with the least-squares line, over a panel of
/// residuals (point mean, forward and reverse stroke means minus the line).
pub fn calibration_plot(a: &AxisReport<'_>) -> Result<String, PlotError> {
    let e = a.evaluation;
    let u = a.output_unit.symbol();
    let (du, df) = display_unit(a);
    let pts = &e.points;
    let mut top = Panel::new(Axis::linear("input rate (deg/s)"), Axis::linear(format!("output ({u})")));
    top.series.push(Series::new(
        "forward-stroke mean",
        pts.iter().map(|p| (p.rate_dps, p.forward_mean)).collect(),
        SeriesStyle::Markers,
        0,
    ));
    top.series.push(Series::new(
        "reverse-stroke mean",
        pts.iter().map(|p| (p.rate_dps, p.reverse_mean)).collect(),
        SeriesStyle::Crosses,
        1,
    ));
    let (lo, hi) = (pts.first().map_or(0.0, |p| p.rate_dps), pts.last().map_or(0.0, |p| p.rate_dps));
    top.series.push(Series::new(
        format!("fit: K = {} {du}/(deg/s), F0 = {} {u}", sig(e.scale_factor() * df, 5), sig(e.zero_offset(), 6)),
        vec![(lo, e.line.eval(lo)), (hi, e.line.eval(hi))],
        SeriesStyle::Line,
        2,
    ));
    top.weight = 1.6;
    let mut bottom = Panel::new(Axis::linear("input rate (deg/s)"), Axis::linear(format!("residual ({du})")));
    bottom.series.push(Series::new(
        "mean − line",
        pts.iter().map(|p| (p.rate_dps, p.line_residual * df)).collect(),
        SeriesStyle::LineMarkers,
        2,
    ));
    bottom.series.push(Series::new(
        "",
        pts.iter().map(|p| (p.rate_dps, (p.forward_mean - p.line_output) * df)).collect(),
        SeriesStyle::Markers,
        0,
    ));
    bottom.series.push(Series::new(
        "",
        pts.iter().map(|p| (p.rate_dps, (p.reverse_mean - p.line_output) * df)).collect(),
        SeriesStyle::Crosses,
        1,
    ));
    bottom.ref_lines.push(RefLine { orientation: Orientation::Horizontal, at: 0.0, label: String::new() });
    Figure {
        title: format!("Axis {}: calibration curve and residuals", a.name),
        panels: vec![top, bottom],
        width: 760,
        height: 600,
    }
    .to_svg()
}

/// Hysteresis: forward and reverse stroke means minus the fitted line, per rate.
pub fn hysteresis_plot(a: &AxisReport<'_>) -> Result<String, PlotError> {
    let e = a.evaluation;
    let (du, df) = display_unit(a);
    let mut p = Panel::new(Axis::linear("input rate (deg/s)"), Axis::linear(format!("stroke mean − line ({du})")));
    p.series.push(Series::new(
        "forward stroke",
        e.points.iter().map(|q| (q.rate_dps, (q.forward_mean - q.line_output) * df)).collect(),
        SeriesStyle::LineMarkers,
        0,
    ));
    p.series.push(Series::new(
        "reverse stroke",
        e.points.iter().map(|q| (q.rate_dps, (q.reverse_mean - q.line_output) * df)).collect(),
        SeriesStyle::LineMarkers,
        1,
    ));
    p.ref_lines.push(RefLine { orientation: Orientation::Horizontal, at: 0.0, label: String::new() });
    Figure::single(format!("Axis {}: hysteresis (forward against reverse)", a.name), p).to_svg()
}

/// Scale factor of each run (both strokes) with the all-runs K as a reference line; `None`
/// with fewer than two runs.
pub fn scale_factor_plot(a: &AxisReport<'_>) -> Option<Result<String, PlotError>> {
    let e = a.evaluation;
    let s = e.scale_factor_repeatability.as_ref()?;
    let (du, df) = display_unit(a);
    let mut run_axis = Axis::linear("run");
    run_axis.integer = true;
    let mut p = Panel::new(run_axis, Axis::linear(format!("scale factor ({du}/(deg/s))")));
    p.series.push(Series::new(
        "K of the run",
        s.per_run.iter().map(|&(run, k)| (f64::from(run), k * df)).collect(),
        SeriesStyle::LineMarkers,
        0,
    ));
    p.ref_lines.push(RefLine {
        orientation: Orientation::Horizontal,
        at: e.scale_factor() * df,
        label: format!("K, all runs = {}", sig(e.scale_factor() * df, 5)),
    });
    Some(Figure::single(format!("Axis {}: scale factor per run", a.name), p).to_svg())
}
