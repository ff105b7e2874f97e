//! The `[uncertainty]` plan section: the coverage factor and the type-B inputs of the
//! measurement-uncertainty budgets (docs/PLAN.md, "Measurement uncertainty"). It needs no
//! records: its type-A parts come from the plan's rate-table and static records.

/// The TOML text of an `[uncertainty]` section: coverage factor k, the rate table's rate accuracy
/// (ppm, rectangular half-width) and the data acquisition's output accuracy (axis output unit,
/// rectangular half-width); `None` leaves a key out.
pub fn write_uncertainty_section(
    coverage_factor: f64,
    rate_accuracy_ppm: Option<f64>,
    output_accuracy: Option<f64>,
) -> String {
    let mut s = String::from(
        "# Measurement uncertainty (JCGM 100:2008 = JJF 1059.1-2012): type B inputs; type A comes from the data.\n\
         [uncertainty]\n",
    );
    s.push_str(&format!("coverage_factor = {coverage_factor:?}\n"));
    if let Some(a) = rate_accuracy_ppm {
        s.push_str(&format!(
            "rate_accuracy_ppm = {a:?}                # rate table, relative; u = a/sqrt(3)\n\
             rate_accuracy_distribution = \"rectangular\"\n"
        ));
    }
    if let Some(a) = output_accuracy {
        s.push_str(&format!(
            "output_accuracy = {a:?}                  # data acquisition, in the axis's output unit; u = a/sqrt(3)\n\
             output_accuracy_distribution = \"rectangular\"\n"
        ));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn section_is_valid_toml_with_the_values() {
        let s = write_uncertainty_section(2.0, Some(50.0), Some(0.001));
        let v: toml::Value = toml::from_str(&s).unwrap();
        assert_eq!(v["uncertainty"]["coverage_factor"].as_float(), Some(2.0));
        assert_eq!(v["uncertainty"]["rate_accuracy_ppm"].as_float(), Some(50.0));
        assert_eq!(v["uncertainty"]["output_accuracy"].as_float(), Some(0.001));
        let bare: toml::Value = toml::from_str(&write_uncertainty_section(3.0, None, None)).unwrap();
        assert!(bare["uncertainty"].get("rate_accuracy_ppm").is_none());
    }
}
