//! Trend plots: figures against the evaluation they come from, one panel per (axis, figure), the
//! limits as horizontal lines (`gyrolab store history --svg`, Python's `history_svg`).

use crate::plot::{Axis, Figure, Orientation, Panel, PlotError, RefLine, Series, SeriesStyle};

/// One panel of a trend plot: a figure of an axis over evaluations.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TrendPanel {
    /// The axis.
    pub axis: String,
    /// The figure's key.
    pub figure: String,
    /// Its unit.
    pub unit: String,
    /// (evaluation id, value), in evaluation order.
    pub points: Vec<(f64, f64)>,
    /// The lower limit of the latest evaluation, if any.
    pub limit_min: Option<f64>,
    /// The upper limit of the latest evaluation, if any.
    pub limit_max: Option<f64>,
}

/// The trend plot as a standalone SVG document (XML declaration, namespace): `title` on top, a
/// panel per entry with points (panels without points are left out; `None` when none is left).
pub fn trend_svg(title: &str, panels: &[TrendPanel]) -> Result<Option<String>, PlotError> {
    let mut drawn = Vec::new();
    for t in panels.iter().filter(|t| !t.points.is_empty()) {
        let (fig, unit) = (&t.figure, &t.unit);
        let mut p = Panel::new(Axis::linear("evaluation id"), Axis::linear(format!("{fig} ({unit})")));
        p.caption = format!("axis {}: {fig}", t.axis);
        p.series.push(Series::new(fig.clone(), t.points.clone(), SeriesStyle::LineMarkers, 0));
        for (at, label) in [(t.limit_min, "limit min"), (t.limit_max, "limit max")] {
            if let Some(at) = at {
                p.ref_lines.push(RefLine { orientation: Orientation::Horizontal, at, label: label.into() });
            }
        }
        drawn.push(p);
    }
    if drawn.is_empty() {
        return Ok(None);
    }
    let height = 60 + 260 * drawn.len() as u32;
    let f = Figure { title: title.to_string(), panels: drawn, width: 760, height };
    let svg = f.to_svg()?;
    let svg =
        if svg.contains("xmlns=") { svg } else { svg.replacen("<svg", "<svg xmlns=\"http://www.w3.org/2000/svg\"", 1) };
    Ok(Some(format!("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n{svg}\n")))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panel_per_figure_with_points_and_its_limits() {
        let p = |figure: &str, points: Vec<(f64, f64)>| TrendPanel {
            axis: "x".into(),
            figure: figure.into(),
            unit: "%".into(),
            points,
            limit_min: None,
            limit_max: Some(0.5),
        };
        let svg = trend_svg(
            "History of serial SN-1",
            &[p("nonlinearity_pct", vec![(1.0, 0.1), (2.0, 0.2)]), p("empty", vec![])],
        )
        .unwrap()
        .unwrap();
        assert!(
            svg.starts_with("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\"")
        );
        assert!(svg.contains("axis x: nonlinearity_pct") && svg.contains("limit max"), "{svg}");
        assert!(!svg.contains("limit min") && !svg.contains("axis x: empty"));
        assert_eq!(trend_svg("t", &[p("empty", vec![])]).unwrap(), None);
    }
}
