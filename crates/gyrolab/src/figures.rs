//! The catalogue of reportable figures: the names a plan's `[limits]` may use (the JSON keys,
//! each with its unit suffix), with unit, formula and source for the summary table and the
//! methods appendix (taken from docs/METHODS.md; static and Allan entries from
//! methods-notes sections 3 and 4).

use crate::conformity::{Known, Support};

/// Which part of a test a figure comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum FigureGroup {
    /// Rate-table (scale-factor) test.
    RateTable,
    /// Static (bias) test.
    Static,
    /// Allan variance noise terms.
    Allan,
    /// Temperature tests at soaked points.
    Temperature,
    /// Measurement uncertainty (GUM expanded uncertainties).
    Uncertainty,
    /// Threshold and resolution tests.
    ThresholdResolution,
    /// g-sensitivity (static records in several orientations).
    GSensitivity,
}

impl FigureGroup {
    /// Display name of the group.
    pub fn title(self) -> &'static str {
        match self {
            FigureGroup::RateTable => "Rate-table test",
            FigureGroup::Static => "Static (bias) test",
            FigureGroup::Allan => "Allan variance",
            FigureGroup::Temperature => "Temperature tests",
            FigureGroup::Uncertainty => "Measurement uncertainty",
            FigureGroup::ThresholdResolution => "Threshold and resolution",
            FigureGroup::GSensitivity => "g-sensitivity",
        }
    }
}

/// A figure's definition: key (the JSON key and limit name), unit, formula and source.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FigureDef {
    /// JSON key and `[limits]` name; `<T>` stands for a smoothing time in seconds.
    pub key: &'static str,
    /// Human name.
    pub label: &'static str,
    /// Unit as printed (`output` = the axis's output unit).
    pub unit: &'static str,
    /// Group.
    pub group: FigureGroup,
    /// Formula in plain text.
    pub formula: &'static str,
    /// Source label (`[P]`, `[GJB]`, `[IEEE]`, `[GB/T 18459]`, `[SP1065]`).
    pub source: &'static str,
}

const fn def(
    key: &'static str,
    label: &'static str,
    unit: &'static str,
    group: FigureGroup,
    formula: &'static str,
    source: &'static str,
) -> FigureDef {
    FigureDef { key, label, unit, group, formula, source }
}

use FigureGroup::{Allan, GSensitivity, RateTable, Static, Temperature, ThresholdResolution, Uncertainty};

/// Every figure gyrolab reports, in report order.
#[rustfmt::skip]
pub const FIGURES: &[FigureDef] = &[
    def("scale_factor", "scale factor K", "output/(deg/s)", RateTable, "least-squares slope of the point means ȳ_j on the rates Ω_j", "[P] eq. 1-2"),
    def("zero_offset", "zero offset F0", "output", RateTable, "F0 = mean(ȳ) − K mean(Ω)", "[P] eq. 3"),
    def("nonlinearity_pct", "nonlinearity K_a", "%", RateTable, "K_a = max_j |a_j|, a_j = (K Ω_j + F0 − F_r − (ȳ_j − F_r)) / F_m, F_m = max_j |ȳ_j − F_r|", "[P] eq. 7-9, [GJB]"),
    def("nonlinearity_ppm", "nonlinearity K_a", "ppm", RateTable, "as nonlinearity_pct, in parts per million", "[P] eq. 9"),
    def("linearity_pct", "linearity δ_L", "% FS", RateTable, "max_j |ȳ_j − (K Ω_j + F0)| / Y_FS, Y_FS = |K| (Ω_max − Ω_min)", "[GB/T 18459]"),
    def("hysteresis_pct", "hysteresis δ_H", "% FS", RateTable, "max_j |ȳ_j,fwd − ȳ_j,rev| / Y_FS (half of it with half_hysteresis)", "[GB/T 18459]"),
    def("repeatability_pct", "repeatability δ_R", "% FS", RateTable, "k σ_max / Y_FS, σ_max the largest std (n − 1) across runs at any point and stroke", "[GB/T 18459]"),
    def("accuracy_pct", "accuracy (sum)", "% FS", RateTable, "δ_L + δ_H + δ_R (the paper's rule)", "[P], [GB/T 18459]"),
    def("accuracy_rss_pct", "accuracy (RSS)", "% FS", RateTable, "√(δ_L² + δ_H² + δ_R²)", "[GB/T 18459]"),
    def("asymmetry_pct", "scale-factor asymmetry K_as", "%", RateTable, "|K+ − K−| / |(K+ + K−)/2|, K± fitted on Ω ≥ 0 and Ω ≤ 0", "[GJB], [IEEE 528]"),
    def("scale_factor_repeatability_ppm", "scale-factor repeatability K_r", "ppm", RateTable, "std(K_i, n − 1) / |mean(K_i)|, K_i fitted per run on both strokes (runs within one record: within-run)", "[GJB]"),
    def("scale_factor_repeatability_pct", "scale-factor repeatability K_r", "%", RateTable, "as scale_factor_repeatability_ppm, in percent", "[GJB]"),
    def("scale_factor_repeatability_power_up_ppm", "scale-factor repeatability across power-ups", "ppm", RateTable, "std(K_i, n − 1) / |mean(K_i)|, K_i of one rate-table record per power-up", "[GJB], [IEEE 952]"),
    def("bias_dph", "bias B_0 (shift against the rest output)", "deg/h", Static, "(mean output − F_null) / K per test: with the plan's nominal null (options.nominal_null) F_null is that null and B_0 the absolute bias; without one F_null is the rate test's rest output, which holds the gyro's bias then: a bias shift (the tables name which); the summary quotes the mean over the Q tests", "[P] eq. 10"),
    def("bias_stability_dph_<T>s", "bias stability B_s(T)", "deg/h", Static, "std(means of consecutive T-second windows, n − 1) / K; the summary quotes the worst test", "[P] eq. 11, [GJB]"),
    def("bias_repeatability_dph", "bias repeatability B_r", "deg/h", Static, "std(B_0i, n − 1) over the Q tests", "[P] eq. 12, [GJB]"),
    def("drift_dph_per_h", "drift", "deg/h per h", Static, "least-squares slope of bias against time; the summary quotes the test of largest magnitude", "[GJB]"),
    def("bias_repeatability_power_up_dph", "bias repeatability across power-ups", "deg/h", Static, "std(B0_i, n − 1), B0_i = (mean output − null) / K of one static record per power-up", "[GJB], [IEEE 952]"),
    def("turn_on_bias_dph", "turn-on bias", "deg/h", Static, "mean bias of the first warm-up window after power-on", "[IEEE 952]"),
    def("warmup_settling_time_s", "warm-up settling time", "s", Static, "start of the first window from which every window mean stays within the band about the final bias", "[IEEE 952], [GJB]"),
    def("temp_sensitivity_dph_per_c", "bias temperature sensitivity (within-record; confounded with drift, no limit)", "(deg/h)/degC", Static, "least-squares slope of 10-s window-mean bias against window-mean temperature; the test of largest magnitude; confounded with the record's drift when temperature changes with time, so it cannot carry a limit", "[GJB], [GB/T 18459]"),
    def("arw_deg_rt_h", "angle random walk N", "deg/√h", Allan, "ADEV supported slope −1/2 region nearest τ = 1 s, line read at 1 s, × 60", "[IEEE 952], [SP1065]"),
    def("bias_instability_dph", "bias instability B", "deg/h", Allan, "IEEE 952 B = ADEV minimum of a supported flat region / 0.6643 (only when resolved)", "[IEEE 952]"),
    def("allan_minimum_dph", "Allan minimum", "deg/h", Allan, "ADEV minimum of a supported flat region (the ADI / Sensonor datasheet figure; 0.6643 B)", "[IEEE 952]"),
    def("allan_minimum_tau_s", "τ of the Allan minimum", "s", Allan, "averaging time of allan_minimum_dph", "[IEEE 952]"),
    def("rrw_deg_h_rt_h", "rate random walk K", "deg/h/√h", Allan, "K = √(3 (σ² − other terms) / τ) on the rising side where σ exceeds them beyond its bounds, × 216000", "[IEEE 952]"),
    def("quantization_deg", "quantization noise Q", "deg", Allan, "ADEV slope −1 line: Q = σ(τ) τ / √3", "[IEEE 952]"),
    def("rate_ramp_dph_per_h", "rate ramp R", "deg/h per h", Allan, "ADEV slope +1 line: R = √2 σ(τ) / τ, × 3600²", "[IEEE 952]"),
    def("scale_factor_temp_sensitivity_ppm_per_c", "scale-factor temperature sensitivity", "ppm/degC", Temperature, "least-squares slope of K_i on T_i over the soaked points / K(T_ref) × 10⁶", "[IEEE 952] annex B, [GJB]"),
    def("bias_temp_sensitivity_dph_per_c", "bias temperature sensitivity (soaked points)", "(deg/h)/degC", Temperature, "least-squares slope of B_i on T_i over the soaked points, B_i = (static mean − null) / K", "[IEEE 952] annex B, [GJB]"),
    def("scale_factor_thermal_hysteresis_ppm", "scale-factor thermal hysteresis", "ppm", Temperature, "max |K_heating − K_cooling| / K(T_ref) × 10⁶ at temperatures visited both ways (within 1 degC)", "[GJB]"),
    def("bias_thermal_hysteresis_dph", "bias thermal hysteresis", "deg/h", Temperature, "max |B_heating − B_cooling| at temperatures visited both ways (within 1 degC)", "[GJB]"),
    def("threshold_dps", "threshold", "deg/s", ThresholdResolution, "smallest tried |Ω| such that it and every larger tried |Ω| give (ȳ_Ω − ȳ_0) / (K Ω) ≥ 0.5 for +Ω and −Ω; at most the smallest tried when it passes; none (above the largest tried) when that fails", "[GJB], [IEEE 528]"),
    def("resolution_dps", "resolution", "deg/s", ThresholdResolution, "at base rate Ω_b: smallest tried |δ| such that it and every larger tried |δ| give (ȳ_{Ω_b+δ} − ȳ_{Ω_b}) / (K δ) ≥ 0.5 for +δ and −δ; bounds as for threshold_dps", "[GJB], [IEEE 528]"),
    def("g_sensitivity_dph_per_g", "g-sensitivity |G|", "(deg/h)/g", GSensitivity, "|G| of the resolved components of B_i = B_0 + G · f_i, least squares over static records in several orientations (one resolved component: its absolute value)", "IEEE Std 1431-2004, [IEEE 952], [GJB]"),
    def("scale_factor_expanded_uncertainty_ppm", "expanded uncertainty of K", "ppm", Uncertainty, "U(K)/|K|, U = k √(u_A² + u_B² + u_PU² + u_T²): u_A the slope's standard error; u_B = |K| u_rel(rate) and the data acquisition's part; u_PU = |K| s_K (the scale-factor repeatability across power-ups, type A, ν = n − 1, when the plan has them: K is stated for the device); u_T = |K| TC_K a/√3 (K's temperature coefficient times the test temperature's standard uncertainty, when measured); k the plan's coverage factor", "[GUM] 4.2, 4.3, 5.1, 6"),
    def("zero_offset_expanded_uncertainty", "expanded uncertainty of F0", "output", Uncertainty, "U = k √(u_A² + u_B²): u_A intercept standard error, u_B output accuracy", "[GUM] 4.2, 4.3, 5.1, 6"),
    def("bias_expanded_uncertainty_dph", "expanded uncertainty of B_0", "deg/h", Uncertainty, "U = k u_c: record mean (OADEV σ(τ)√(τ/T)), null, output accuracy and K propagated", "[GUM] 5.1, 6"),
    def("bias_stability_expanded_uncertainty_dph", "expanded uncertainty of B_s", "deg/h", Uncertainty, "U = k u_c: s/√(2(n − 1)) and K propagated", "[GUM] E.4.3, 6"),
    def("arw_expanded_uncertainty_deg_rt_h", "expanded uncertainty of N", "deg/√h", Uncertainty, "U = k u_c: the wider side of the 68.3 % Allan interval at the reading τ, and K", "[GUM] 6, [SP1065]"),
    def("bias_instability_expanded_uncertainty_dph", "expanded uncertainty of B", "deg/h", Uncertainty, "U = k u_c: the wider side of the 68.3 % Allan interval at the reading τ, and K", "[GUM] 6, [SP1065]"),
    def("rrw_expanded_uncertainty_deg_h_rt_h", "expanded uncertainty of K (RRW)", "deg/h/√h", Uncertainty, "U = k u_c: the wider side of the 68.3 % Allan interval at the reading τ, and K", "[GUM] 6, [SP1065]"),
];

/// The names a `[limits]` table may use (`<T>` stands for a smoothing time in seconds).
pub fn figure_names() -> Vec<&'static str> {
    FIGURES.iter().map(|f| f.key).collect()
}

/// Whether `name` matches a catalogue key, `<T>` matching a positive decimal number.
pub fn name_matches(pattern: &str, name: &str) -> bool {
    match pattern.split_once("<T>") {
        None => pattern == name,
        Some((pre, post)) => name
            .strip_prefix(pre)
            .and_then(|r| r.strip_suffix(post))
            .is_some_and(|t| !t.is_empty() && t.parse::<f64>().is_ok_and(|v| v > 0.0 && v.is_finite())),
    }
}

/// Why a figure cannot carry a spec limit, for the figures that cannot (issue 33): the
/// within-record temperature slope of a static test is confounded with the record's drift when
/// the temperature changes with time, so a limit on it would decide on drift as much as on
/// temperature. It is reported with that caveat; the soaked-point figure carries limits.
pub fn limit_refusal(name: &str) -> Option<&'static str> {
    match name {
        "temp_sensitivity_dph_per_c" => Some(
            "a within-record temperature slope is confounded with the drift of the record (its temperature \
             changes with time), so it is reported with that caveat but cannot carry a limit: limit \
             bias_temp_sensitivity_dph_per_c, measured at soaked temperature points ([temperature.<axis>]), instead",
        ),
        _ => None,
    }
}

/// The definition of a figure name, if it is known.
pub fn known_figure(name: &str) -> Option<&'static FigureDef> {
    FIGURES.iter().find(|f| name_matches(f.key, name))
}

/// The values of one axis's figures, by key (figures that could not be computed are absent).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct AxisFigures {
    /// Axis name.
    pub axis: String,
    /// Output unit of the axis (replaces `output` in units).
    pub output_unit: String,
    /// (key, value) in catalogue order; static and Allan sections append theirs.
    pub values: Vec<(String, f64)>,
    /// Keys whose values come from simulated data (marked SIMULATED in the summary).
    pub simulated: Vec<String>,
    /// Keys whose entry in `values` is a bound, not an estimate (an Allan term the curve does not
    /// resolve: at most; a threshold above the largest rate tried: above), with its kind.
    pub bounds: Vec<(String, Support)>,
    /// Expanded uncertainties U (same unit as the figure) given for a figure directly; figures
    /// with a catalogue uncertainty key ([`uncertainty_key`]) take theirs from `values`.
    pub uncertainties: Vec<(String, f64)>,
    /// Labels that replace the catalogue's for this axis (the bias is absolute against a nominal
    /// null on some axes and a bias shift on others).
    pub labels: Vec<(String, String)>,
}

/// The catalogue key of a figure's expanded uncertainty (that of K is relative, in ppm:
/// [`AxisFigures::known`] multiplies it by |K| × 1e-6).
pub fn uncertainty_key(figure: &str) -> Option<&'static str> {
    match figure {
        "scale_factor" => Some("scale_factor_expanded_uncertainty_ppm"),
        "zero_offset" => Some("zero_offset_expanded_uncertainty"),
        "bias_dph" => Some("bias_expanded_uncertainty_dph"),
        "arw_deg_rt_h" => Some("arw_expanded_uncertainty_deg_rt_h"),
        "bias_instability_dph" => Some("bias_instability_expanded_uncertainty_dph"),
        "rrw_deg_h_rt_h" => Some("rrw_expanded_uncertainty_deg_h_rt_h"),
        _ => None,
    }
}

impl AxisFigures {
    /// The value of a figure.
    pub fn get(&self, key: &str) -> Option<f64> {
        self.values.iter().find(|(k, _)| k == key).map(|(_, v)| *v)
    }

    /// Adds or replaces a figure value, an estimate (non-finite values are left out).
    pub fn set(&mut self, key: impl Into<String>, value: f64) {
        let key = key.into();
        self.values.retain(|(k, _)| *k != key);
        self.bounds.retain(|(k, _)| *k != key);
        if value.is_finite() {
            self.values.push((key, value));
        }
    }

    /// Adds or replaces a figure known only as a bound: `support` says which side
    /// ([`Support::Value`] is the same as [`AxisFigures::set`]).
    pub fn set_bound(&mut self, key: impl Into<String>, bound: f64, support: Support) {
        let key = key.into();
        self.set(key.clone(), bound);
        if support != Support::Value && bound.is_finite() {
            self.bounds.push((key, support));
        }
    }

    /// Takes every figure of `other` (same axis), with its bound and uncertainty, replacing
    /// figures of the same key.
    pub fn merge(&mut self, other: AxisFigures) {
        for (k, v) in other.values {
            let support = other.bounds.iter().find(|(b, _)| *b == k).map_or(Support::Value, |(_, s)| *s);
            self.set_bound(k, v, support);
        }
        for (k, u) in other.uncertainties {
            self.set_uncertainty(k, u);
        }
        for (k, l) in other.labels {
            self.set_label(k, l);
        }
        self.simulated.extend(other.simulated);
    }

    /// Replaces the catalogue's label of a figure on this axis.
    pub fn set_label(&mut self, key: impl Into<String>, label: impl Into<String>) {
        let key = key.into();
        self.labels.retain(|(k, _)| *k != key);
        self.labels.push((key, label.into()));
    }

    /// The label of a figure on this axis: its own, else the catalogue's, else the key.
    pub fn label_of(&self, key: &str) -> String {
        self.labels
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, l)| l.clone())
            .or_else(|| known_figure(key).map(|d| d.label.to_string()))
            .unwrap_or_else(|| key.to_string())
    }

    /// Gives a figure's expanded uncertainty U (same unit as the figure).
    pub fn set_uncertainty(&mut self, key: impl Into<String>, u: f64) {
        let key = key.into();
        self.uncertainties.retain(|(k, _)| *k != key);
        if u.is_finite() && u >= 0.0 {
            self.uncertainties.push((key, u));
        }
    }

    /// The figure as the conformity decision sees it: value or bound, and its expanded
    /// uncertainty (given directly, or from the catalogue's uncertainty figure of this axis).
    pub fn known(&self, key: &str) -> Option<Known> {
        let value = self.get(key)?;
        let support = self.bounds.iter().find(|(k, _)| k == key).map_or(Support::Value, |(_, s)| *s);
        let direct = self.uncertainties.iter().find(|(k, _)| k == key).map(|(_, u)| *u);
        let catalogue = || {
            let u = self.get(uncertainty_key(key)?)?;
            Some(if key == "scale_factor" { u * value.abs() * 1e-6 } else { u })
        };
        let expanded_uncertainty = if support == Support::Value { direct.or_else(catalogue) } else { None };
        Some(Known { value, support, expanded_uncertainty })
    }

    /// The unit of a figure for this axis.
    pub fn unit_of(&self, key: &str) -> String {
        known_figure(key).map_or_else(String::new, |d| d.unit.replace("output", &self.output_unit))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_and_patterns() {
        assert!(known_figure("nonlinearity_pct").is_some());
        assert!(known_figure("bias_stability_dph_10s").is_some());
        assert!(known_figure("bias_stability_dph_0.5s").is_some());
        assert!(known_figure("bias_stability_dph_s").is_none());
        assert!(known_figure("bias_stability_dph_-1s").is_none());
        assert!(known_figure("nonlinearity").is_none());
        assert!(figure_names().contains(&"arw_deg_rt_h"));
        let mut keys = figure_names();
        keys.sort();
        keys.dedup();
        assert_eq!(keys.len(), FIGURES.len(), "keys are unique");
    }
}
