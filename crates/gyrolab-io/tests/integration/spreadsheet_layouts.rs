//! The wide rate-table layout as spreadsheets export it (issue 16): `Run 1 (V)` run labels
//! over stroke labels, Chinese labels with bracketed units, a title row above the header,
//! semicolon-separated files with decimal commas. Each variant is written from the same numbers
//! as a plain `run1_fwd_v` file and must give the same table.

use gyrolab::rate_test::RateTable;
use gyrolab::units::OutputUnit;
use gyrolab_io::rate_table::{parse_rate_table, RateColumns};
use std::path::Path;

/// Three rates, two runs, both strokes: output = 2.5 + 0.0075 rate + small run/stroke terms.
fn values() -> Vec<(f64, [f64; 4])> {
    [-100.0, 0.0, 100.0].iter().map(|&r| (r, [0, 1, 2, 3].map(|k| 2.5 + 0.0075 * r + 1e-4 * f64::from(k)))).collect()
}

fn table(text: &str) -> (RateTable, OutputUnit) {
    let f = parse_rate_table(Path::new("sheet.csv"), text, &RateColumns::default())
        .unwrap_or_else(|e| panic!("{e}\n{text}"));
    (f.table, f.output_unit)
}

fn plain() -> String {
    let mut s = String::from("rate_dps,run1_fwd_v,run1_rev_v,run2_fwd_v,run2_rev_v\n");
    for (r, v) in values() {
        s.push_str(&format!("{r},{},{},{},{}\n", v[0], v[1], v[2], v[3]));
    }
    s
}

#[test]
fn spreadsheet_variants_give_the_plain_table() {
    let (expected, unit) = table(&plain());
    assert_eq!(unit, OutputUnit::Volt);
    let mut two_rows = String::from("Rate (deg/s),Run 1 (V),,Run 2 (V),\n,fwd,rev,fwd,rev\n");
    let mut chinese =
        String::from("转台速率 (°/s),第一次 正行程 (V),第一次 反行程 (V),第二次 正行程 (V),第二次 反行程 (V)\n");
    let mut titled = String::from("Gyro X rate test 2026-11-20\n");
    titled.push_str(&plain());
    let mut semicolon = String::from("rate_dps;run1_fwd_v;run1_rev_v;run2_fwd_v;run2_rev_v\n");
    for (r, v) in values() {
        two_rows.push_str(&format!("{r},{},{},{},{}\n", v[0], v[1], v[2], v[3]));
        chinese.push_str(&format!("{r},{},{},{},{}\n", v[0], v[1], v[2], v[3]));
        let dc = |x: f64| format!("{x}").replace('.', ",");
        semicolon.push_str(&format!("{};{};{};{};{}\n", dc(r), dc(v[0]), dc(v[1]), dc(v[2]), dc(v[3])));
    }
    for (name, text) in [("two rows", two_rows), ("chinese", chinese), ("title", titled), ("decimal commas", semicolon)]
    {
        let (t, u) = table(&text);
        assert_eq!(u, OutputUnit::Volt, "{name}");
        assert_eq!(t.rates_dps, expected.rates_dps, "{name}");
        assert_eq!(t.forward, expected.forward, "{name}");
        assert_eq!(t.reverse, expected.reverse, "{name}");
    }
}

#[test]
fn decimal_commas_are_not_taken_in_comma_separated_files() {
    // In a comma-separated file "2,5" is two fields: the row has too many fields.
    let text = "rate_dps,run1_fwd_v,run1_rev_v\n-100,1,75,1.76\n100,3.25,3.26\n";
    let e = parse_rate_table(Path::new("c.csv"), text, &RateColumns::default()).unwrap_err();
    assert_eq!(e.line, Some(2), "{e}");
}
