//! The store on both back ends (SQLite file, real PostgreSQL server): records round-trip
//! verbatim (SQL, quotes, Unicode, 1 MB texts) or are refused (NUL) with nothing written;
//! revisions (correction, approval) supersede without changing; lot statistics equal hand
//! calculations; lot comparison equals scipy; control-chart rules; concurrent writers; newer
//! schema, corrupt and foreign files refused; passwords never shown.

use crate::common;

use approx::assert_relative_eq;
use common::{backends, make_version_1_store, mark_newer_schema, pg_url, record};
use gyrolab_store::record::FigureRecord;
use gyrolab_store::{query, Changes, Revision, RevisionKind, Store, StoreError};

fn count(store: &mut Store) -> usize {
    // Every serial used by the tests is listed by history; count via evaluation ids instead.
    let mut n = 0;
    while store.evaluation(n as i64 + 1).is_ok() {
        n += 1;
    }
    n
}

#[test]
fn hostile_texts_round_trip_verbatim_or_are_refused() {
    let hostile = [
        "'; DROP TABLE evaluation; --",
        "Robert'); DELETE FROM figure; --",
        "\"double\" 'single' `back` \\ backslash",
        "Ünïcödé 温度 🚀 \u{202e}rtl",
        "$1 $2 ? ?1 :name @p",
    ];
    let big = "x".repeat(1 << 20);
    for b in backends("hostile_texts") {
        let mut s = Store::open(&b.location, true).unwrap();
        for h in hostile {
            let mut r = record(h, Some(h), &[("x", h, 10.0)]);
            r.operator = Some(h.into());
            r.plan_text = format!("{h}\n{big}");
            let id = s.add(&r).unwrap();
            let back = s.evaluation(id).unwrap();
            assert_eq!(back.record, r, "{} {h:?}", b.name);
            let hist = query::history(&mut s, h).unwrap();
            assert_eq!(hist.len(), 1);
            assert_eq!(hist[0].figure.figure, h);
        }
        let n = count(&mut s);
        for field in ["serial", "lot", "operator", "plan"] {
            let mut r = record("SN-nul", Some("L"), &[("x", "bias_dph", 10.0)]);
            match field {
                "serial" => r.serial = "a\0b".into(),
                "lot" => r.lot = Some("a\0b".into()),
                "operator" => r.operator = Some("\0".into()),
                _ => r.plan_text = "x\0".into(),
            }
            let e = s.add(&r).unwrap_err();
            assert!(matches!(e, StoreError::Refused { .. }), "{} {field}: {e}", b.name);
            assert!(e.to_string().contains("NUL"), "{e}");
        }
        assert_eq!(count(&mut s), n, "{}: nothing written for refused records", b.name);
    }
}

#[test]
fn revisions_supersede_and_never_change_the_record() {
    for b in backends("revisions") {
        let mut s = Store::open(&b.location, true).unwrap();
        let r = record("SN1", Some("L-wrong"), &[("x", "bias_dph", 10.0)]);
        let first = s.add(&r).unwrap();
        let corr = Revision {
            supersedes: first,
            kind: RevisionKind::Correction,
            by: "QA".into(),
            reason: "lot mistyped".into(),
        };
        let second = s.revise(&corr, &Changes { lot: Some("L1".into()), ..Default::default() }, None).unwrap();
        let appr = Revision {
            supersedes: second,
            kind: RevisionKind::Approval,
            by: "Dr. Approver".into(),
            reason: "reviewed".into(),
        };
        let third = s.revise(&appr, &Changes::default(), None).unwrap();
        let e1 = s.evaluation(first).unwrap();
        assert_eq!(e1.record, r, "{}: the superseded record is unchanged", b.name);
        assert_eq!(e1.superseded_by, Some(second));
        let e2 = s.evaluation(second).unwrap();
        assert_eq!(
            (e2.supersedes, e2.record.lot.as_deref(), e2.revision_kind.as_str()),
            (Some(first), Some("L1"), "correction")
        );
        assert_eq!(e2.revision_by.as_deref(), Some("QA"));
        let e3 = s.evaluation(third).unwrap();
        assert_eq!(
            (e3.record.approver.as_deref(), e3.superseded_by, e3.record.lot.as_deref()),
            (Some("Dr. Approver"), None, Some("L1"))
        );
        assert_eq!(e3.record.figures, r.figures);
        let h = query::history(&mut s, "SN1").unwrap();
        let current: Vec<(i64, bool)> = h.iter().map(|r| (r.evaluation, r.current)).collect();
        assert_eq!(current, vec![(first, false), (second, false), (third, true)]);
        // A superseded revision cannot be revised again (no forks), and a revision needs who and why.
        let again = Revision { supersedes: first, kind: RevisionKind::Correction, by: "X".into(), reason: "y".into() };
        assert!(matches!(s.revise(&again, &Changes::default(), None), Err(StoreError::Refused { .. })));
        let anon = Revision { supersedes: third, kind: RevisionKind::Approval, by: " ".into(), reason: "ok".into() };
        assert!(s.revise(&anon, &Changes::default(), None).unwrap_err().to_string().contains("--by"));
        // Only the current revision counts in the lot: the wrong lot is empty now.
        assert!(matches!(query::lot(&mut s, "L-wrong", 0.95), Err(StoreError::NotFound { .. })));
        assert_eq!(query::lot(&mut s, "L1", 0.95).unwrap()[0].statistics.as_ref().unwrap().n, 1);
    }
}

#[test]
fn records_cannot_be_updated_or_deleted_in_the_database() {
    let b = &backends("immutable")[0];
    Store::open(&b.location, true).unwrap().add(&record("SN1", None, &[("x", "bias_dph", 10.0)])).unwrap();
    let c = rusqlite::Connection::open(&b.location).unwrap();
    let e = c.execute("UPDATE evaluation SET serial = 'forged'", []).unwrap_err();
    assert!(e.to_string().contains("never changed"), "{e}");
    assert!(c.execute("DELETE FROM figure", []).is_err());
    for sql in [
        "UPDATE report_file SET content_zstd = NULL",
        "DELETE FROM report_file",
        "UPDATE input_file SET sha256 = 'forged'",
        "DELETE FROM input_file",
    ] {
        let e = c.execute(sql, []).unwrap_err();
        assert!(e.to_string().contains("gyrolab records are never"), "{sql}: {e}");
    }
    if let Some(url) = pg_url("immutable") {
        let pg = &backends("immutable_pg")[1];
        let mut s = Store::open(&pg.location, true).unwrap();
        s.add(&record("SN1", None, &[("x", "bias_dph", 10.0)])).unwrap();
        drop(s);
        let schema = pg.location.rsplit("search_path%3D").next().unwrap().to_string();
        let mut c = postgres::Client::connect(&url, postgres::NoTls).unwrap();
        for sql in [
            "DELETE FROM {s}.evaluation",
            "UPDATE {s}.report_file SET content_zstd = NULL",
            "DELETE FROM {s}.input_file",
        ] {
            let e = c.batch_execute(&sql.replace("{s}", &schema)).unwrap_err();
            assert!(format!("{e:?}").contains("never changed or deleted"), "{sql}: {e:?}");
        }
    }
}

#[test]
fn lot_statistics_equal_the_hand_calculation() {
    // Values 9.8, 10.1, 10.0, 9.9, 10.2 in test order (limits 9 .. 11): mean 10, s = 0.158113883,
    // MR-bar 0.2 -> sigma within 0.177305, Cp = 2/(6 * 0.177305) = 1.88, Pp = 2.108185107 (the
    // core crate's hand calculation). A superseded revision of SN3 (value 30) must not count.
    for b in backends("lot_statistics") {
        let mut s = Store::open(&b.location, true).unwrap();
        let values = [9.8, 10.1, 10.0, 9.9, 10.2];
        for (i, v) in values.iter().enumerate() {
            let mut r = record(&format!("SN{i}"), Some("L1"), &[("x", "bias_dph", if i == 3 { 30.0 } else { *v })]);
            r.test_date = Some(format!("2026-11-{:02}", i + 1));
            let id = s.add(&r).unwrap();
            if i == 3 {
                let mut fixed = r.clone();
                fixed.figures[0].value = Some(*v);
                let rev =
                    Revision { supersedes: id, kind: RevisionKind::Reevaluation, by: "t".into(), reason: "t".into() };
                s.revise(&rev, &Changes::default(), Some(&fixed)).unwrap();
            }
        }
        s.add(&record("OTHER", Some("L2"), &[("x", "bias_dph", 100.0)])).unwrap();
        let lot = query::lot(&mut s, "L1", 0.95).unwrap();
        assert_eq!(lot.len(), 1, "{}", b.name);
        let st = lot[0].statistics.as_ref().unwrap();
        assert_eq!(st.n, 5);
        assert_eq!((lot[0].n_devices, lot[0].n_bounds, lot[0].n_not_evaluated), (5, 0, 0));
        assert_relative_eq!(st.mean, 10.0, max_relative = 1e-12);
        assert_relative_eq!(st.sd.unwrap(), 0.158113883008419, max_relative = 1e-12);
        assert_relative_eq!(st.cp.unwrap().value, 1.88, max_relative = 1e-12);
        assert_relative_eq!(st.pp.unwrap().value, 2.108185106778919, max_relative = 1e-12);
        assert_eq!(st.yield_fraction, Some(1.0));
        assert_eq!((lot[0].limit_min, lot[0].limit_max), (Some(9.0), Some(11.0)));
        // Bissell interval of Ppk at n = 5: z(0.975) = 1.959963984540054 (scipy norm.ppf).
        let ppk = st.ppk.unwrap();
        let half = 1.959963984540054 * (1.0 / 45.0 + ppk.value * ppk.value / 8.0).sqrt();
        assert_relative_eq!(ppk.interval.unwrap().lower, ppk.value - half, max_relative = 1e-9);
    }
}

/// A figure row as a test sets it: `value` (or the bound), `basis`, limits and verdict.
fn figure_row(
    key: &str,
    unit: &str,
    value: Option<f64>,
    basis: &str,
    limits: (Option<f64>, Option<f64>),
    verdict: Option<&str>,
) -> FigureRecord {
    FigureRecord {
        axis: "x".into(),
        figure: key.into(),
        value,
        unit: unit.into(),
        basis: basis.into(),
        expanded_uncertainty: None,
        coverage_factor: None,
        limit_min: limits.0,
        limit_max: limits.1,
        verdict: verdict.map(str::to_string),
        simulated: false,
    }
}

/// The devices of lot Q (issue 53), in test order D1 .. D7, each with its figure rows:
/// - bias_dph (deg/h, limits 9 .. 11): values 9.8, 10.1, 10.0, 9.9, 10.2 (D1-D5), D6 a value 10.0
///   whose verdict is NOT EVALUATED, D7 10.0;
/// - resolution_dps (deg/s, upper limit 0.0625): upper bounds 0.0125, 0.0125, 0.02 (D1-D3), a
///   value 0.03 (D4), an upper bound 0.1 (D5), no value NOT EVALUATED (D6), no row (D7);
/// - scale_factor (mV/(deg/s), upper limit 0.0625): the issue's degenerate values 0.0125 + 0,
///   0, 6 and 10 units in the last place (2^-59) on D1-D4, no row on D5-D7.
fn lot_q(s: &mut Store) {
    let ulp = 2f64.powi(-59);
    let bias = [Some(9.8), Some(10.1), Some(10.0), Some(9.9), Some(10.2), Some(10.0), Some(10.0)];
    let resolution: [Option<(f64, &str)>; 7] = [
        Some((0.0125, "upper_bound")),
        Some((0.0125, "upper_bound")),
        Some((0.02, "upper_bound")),
        Some((0.03, "value")),
        Some((0.1, "upper_bound")),
        None,
        None,
    ];
    let k = [0.0, 0.0, 6.0, 10.0];
    for i in 0..7 {
        let mut r = common::record(&format!("D{}", i + 1), Some("Q"), &[]);
        r.test_date = Some(format!("2026-11-{:02}", i + 1));
        let nev = i == 5;
        r.figures.push(figure_row(
            "bias_dph",
            "deg/h",
            bias[i],
            "value",
            (Some(9.0), Some(11.0)),
            Some(if nev { "NOT EVALUATED" } else { "PASS" }),
        ));
        let usl = (None, Some(0.0625));
        match (i, resolution[i]) {
            (_, Some((v, basis))) => r.figures.push(figure_row(
                "resolution_dps",
                "deg/s",
                Some(v),
                basis,
                usl,
                Some(if v <= 0.0625 { "PASS" } else { "FAIL" }),
            )),
            (5, None) => {
                r.figures.push(figure_row("resolution_dps", "deg/s", None, "value", usl, Some("NOT EVALUATED")))
            }
            _ => {}
        }
        if i < 4 {
            r.figures.push(figure_row(
                "scale_factor",
                "mV/(deg/s)",
                Some(0.0125 + k[i] * ulp),
                "value",
                usl,
                Some("PASS"),
            ));
        }
        s.add(&r).unwrap();
    }
}

#[test]
fn lot_statistics_keep_bounds_apart_and_count_devices_not_evaluated() {
    for b in backends("lot_honest") {
        let mut s = Store::open(&b.location, true).unwrap();
        lot_q(&mut s);
        let lot = query::lot(&mut s, "Q", 0.95).unwrap();
        let by = |k: &str| lot.iter().find(|f| f.figure == k).unwrap_or_else(|| panic!("{k}: {lot:?}")).clone();
        assert_eq!(lot.len(), 3, "{}", b.name);

        // bias_dph: D6's value is NOT EVALUATED, so the values are 9.8 10.1 10.0 9.9 10.2 10.0
        // (n = 6): mean 60/6 = 10; squares .04 .01 0 .01 .04 0 = .10, s = sqrt(.1/5) = 0.1414213562;
        // moving ranges .3 .1 .1 .3 .2 -> .2, sigma within .2/1.128, Cp = 2/(6 .2/1.128) = 1.88;
        // Pp = Ppk = 2/(6 s) = 2.3570226040. Yield: 6 inside of 7 devices; 6 of 6 values.
        let f = by("bias_dph");
        let st = f.statistics.as_ref().unwrap();
        assert_eq!((f.n_devices, f.n_evaluated, f.n_bounds, f.n_not_evaluated, f.n_missing), (7, 6, 0, 1, 0));
        assert_eq!(st.n, 6);
        assert_eq!(f.not_evaluated_serials, vec!["D6"]);
        assert_relative_eq!(st.mean, 10.0, max_relative = 1e-12);
        assert_relative_eq!(st.sd.unwrap(), 0.1414213562373095, max_relative = 1e-12);
        assert_relative_eq!(st.sigma_within.unwrap(), 0.2 / 1.128, max_relative = 1e-12);
        assert_relative_eq!(st.cp.unwrap().value, 1.88, max_relative = 1e-12);
        assert_relative_eq!(st.pp.unwrap().value, 2.357022603955158, max_relative = 1e-12);
        assert_relative_eq!(st.ppk.unwrap().value, 2.357022603955158, max_relative = 1e-12);
        assert_eq!(f.conforming_devices, Some(6));
        assert_relative_eq!(f.yield_devices.unwrap(), 6.0 / 7.0, max_relative = 1e-15);
        assert_eq!(st.yield_fraction, Some(1.0));
        assert!(f.warnings.iter().any(|w| w.starts_with("1 device NOT EVALUATED") && w.ends_with(": D6")), "{f:?}");
        assert!(
            f.warnings.iter().any(|w| w.starts_with("capability from n = 6 values, fewer than 25")),
            "{}: {:?}",
            b.name,
            f.warnings
        );

        // resolution_dps: four upper bounds (0.0125, 0.0125, 0.02, 0.1) kept out, one value
        // (0.03: n = 1, no sd, no index), D6 NOT EVALUATED and D7 without the figure. Yield over
        // the 7 devices: the value 0.03 and the bounds 0.0125, 0.0125, 0.02 are at most 0.0625;
        // the bound 0.1 decides nothing, D6 and D7 are not evaluated: 4/7.
        let f = by("resolution_dps");
        let st = f.statistics.as_ref().unwrap();
        assert_eq!((f.n_devices, f.n_evaluated, f.n_bounds, f.n_not_evaluated, f.n_missing), (7, 1, 4, 2, 1));
        assert_eq!((f.n_upper_bounds, f.largest_upper_bound, f.n_lower_bounds), (4, Some(0.1), 0));
        assert_eq!((st.n, st.mean, st.sd), (1, 0.03, None), "bounds are never averaged");
        assert!(st.ppk.is_none() && st.indices_refused.as_deref().is_some_and(|r| r.contains("n = 1")));
        assert_eq!(f.bound_serials, vec!["D1", "D2", "D3", "D5"]);
        assert_eq!(f.not_evaluated_serials, vec!["D6", "D7"]);
        assert_eq!(f.conforming_devices, Some(4));
        assert_relative_eq!(f.yield_devices.unwrap(), 4.0 / 7.0, max_relative = 1e-15);
        let notes = f.warnings.join("\n");
        assert!(
            notes.contains("4 devices give only an upper bound (each at most 0.1 deg/s, the largest bound)"),
            "{notes}"
        );
        assert!(
            notes.contains("1 device without this figure in its current evaluation, counted as NOT EVALUATED: D7"),
            "{notes}"
        );
        assert!(notes.contains("n = 1: no standard deviation"), "{notes}");

        // scale_factor: the issue's case, s = 8.498e-18 from values equal to within rounding:
        // (USL - mean)/(3 s) would be 1.96e15; refused, with the reason. D5-D7 lack the figure.
        let f = by("scale_factor");
        let st = f.statistics.as_ref().unwrap();
        assert_eq!((f.n_devices, f.n_evaluated, f.n_not_evaluated, f.n_missing), (7, 4, 3, 3));
        assert_relative_eq!(st.sd.unwrap(), 8.498374721940739e-18, max_relative = 1e-6);
        assert!(st.cp.is_none() && st.cpk.is_none() && st.pp.is_none() && st.ppk.is_none(), "{st:?}");
        assert!(st.indices_refused.as_deref().unwrap().contains("degenerate spread"), "{st:?}");
        assert!(f.warnings.iter().all(|w| !w.contains("fewer than 25")), "no index, no few-values warning");
        assert_relative_eq!(f.yield_devices.unwrap(), 4.0 / 7.0, max_relative = 1e-15);
    }
}

#[test]
fn the_issues_resolution_upper_bounds_give_no_statistics() {
    // Issue 53: every device's resolution an upper bound of 0.0125 deg/s (equal to within
    // rounding) was averaged into s = 8.5e-18 and Ppk = 1.96e15. Now: no statistics, the bounds
    // counted and named, and the yield from the bounds (each at most the limit 0.0625: 4/4).
    for b in backends("lot_resolution") {
        let mut s = Store::open(&b.location, true).unwrap();
        let ulp = 2f64.powi(-59);
        for (i, k) in [0.0, 0.0, 6.0, 10.0].iter().enumerate() {
            let mut r = common::record(&format!("R{i}"), Some("R"), &[]);
            r.figures.push(figure_row(
                "resolution_dps",
                "deg/s",
                Some(0.0125 + k * ulp),
                "upper_bound",
                (None, Some(0.0625)),
                Some("PASS"),
            ));
            s.add(&r).unwrap();
        }
        let lot = query::lot(&mut s, "R", 0.95).unwrap();
        assert_eq!(lot.len(), 1, "{}: the figure is a row, not dropped", b.name);
        let f = &lot[0];
        assert!(f.statistics.is_none(), "{}: {f:?}", b.name);
        assert_eq!((f.n_devices, f.n_evaluated, f.n_bounds, f.n_not_evaluated), (4, 0, 4, 0));
        assert_eq!(f.largest_upper_bound, Some(0.0125 + 10.0 * ulp));
        assert_eq!(f.yield_devices, Some(1.0));
        assert!(f.warnings.iter().any(|w| w == "no device gives a value: no statistics"), "{:?}", f.warnings);
        assert!(
            f.warnings[0].starts_with("4 devices give only an upper bound (each at most 0.0125 deg/s"),
            "{:?}",
            f.warnings
        );
    }
}

#[test]
fn no_few_values_warning_from_25_devices() {
    for b in backends("lot_25") {
        let mut s = Store::open(&b.location, true).unwrap();
        let values: Vec<f64> = (0..25).map(|i| 10.0 + 0.01 * ((i * 7 % 11) as f64 - 5.0)).collect();
        for (i, v) in values.iter().enumerate() {
            let lot = if i < 24 { "BIG" } else { "BIG-late" };
            s.add(&common::record(&format!("B{i:02}"), Some(lot), &[("x", "bias_dph", *v)])).unwrap();
        }
        let f = &query::lot(&mut s, "BIG", 0.95).unwrap()[0];
        assert_eq!(f.n_evaluated, 24);
        assert!(f.warnings.iter().any(|w| w.contains("n = 24 values, fewer than 25")), "{}: {:?}", b.name, f.warnings);
        // The 25th device joins the lot by a correction: 25 values, no warning.
        let id = query::history(&mut s, "B24").unwrap()[0].evaluation;
        let corr = Revision { supersedes: id, kind: RevisionKind::Correction, by: "QA".into(), reason: "lot".into() };
        s.revise(&corr, &Changes { lot: Some("BIG".into()), ..Default::default() }, None).unwrap();
        let f = &query::lot(&mut s, "BIG", 0.95).unwrap()[0];
        assert_eq!((f.n_evaluated, f.n_devices), (25, 25));
        assert!(f.statistics.as_ref().unwrap().ppk.is_some());
        assert!(f.warnings.is_empty(), "{}: {:?}", b.name, f.warnings);
    }
}

#[test]
fn comparison_and_charts_use_values_only_and_count_the_rest() {
    for b in backends("lot_compare_honest") {
        let mut s = Store::open(&b.location, true).unwrap();
        lot_q(&mut s);
        for (i, v) in [10.4, 10.6, 10.5].iter().enumerate() {
            s.add(&common::record(&format!("P{i}"), Some("P"), &[("x", "bias_dph", *v)])).unwrap();
        }
        let c = query::compare(&mut s, "Q", "P").unwrap();
        assert_eq!(c.len(), 1, "{}: only bias_dph is in both lots", b.name);
        let r = &c[0];
        assert_eq!((r.n1, r.n_devices1, r.n_not_evaluated1, r.n2, r.n_devices2), (6, 7, 1, 3, 3));
        assert_eq!((r.mean1, r.mean2), (Some(10.0), Some(10.5)));
        assert!(r.test.is_some());
        assert!(r.notes.iter().any(|n| n.starts_with("lot Q: 1 device NOT EVALUATED")), "{:?}", r.notes);
        // Charts: the individuals chart has the six values of Q (D6 left out).
        let ch = query::control_charts(&mut s, Some("Q"), "x", "bias_dph").unwrap();
        assert_eq!(ch.serials, vec!["D1", "D2", "D3", "D4", "D5", "D7"], "{}", b.name);
        assert_eq!((ch.n_devices, ch.n_not_evaluated), (7, 1));
        assert!(ch.notes.iter().any(|n| n.contains("NOT EVALUATED") && n.ends_with("no point")), "{:?}", ch.notes);
        // X-bar/S: lots Q (6 values) and P (3), D6 left out.
        assert_eq!(ch.lots, vec!["Q", "P"]);
        assert_eq!(ch.n_left_out_of_lots, 1);
        // The resolution chart has one value only: no chart, and the bounds counted.
        let ch = query::control_charts(&mut s, Some("Q"), "x", "resolution_dps").unwrap();
        assert!(ch.individuals.is_none());
        assert_eq!((ch.serials.len(), ch.n_bounds, ch.n_not_evaluated), (1, 4, 2));
        // The degenerate scale factors give no chart of rounding noise.
        let ch = query::control_charts(&mut s, Some("Q"), "x", "scale_factor").unwrap();
        assert!(ch.individuals.is_none(), "{ch:?}");
        assert!(ch.notes.iter().any(|n| n.contains("no spread (zero or degenerate)")), "{:?}", ch.notes);
    }
}

#[test]
fn lot_comparison_equals_scipy() {
    // scipy 1.17.1: ttest_ind(a, b, equal_var=False) -> t -3.2135252690935623, p 0.013332958459766134;
    // F = 0.30892857142857216, two-sided p 0.18509344439172562.
    let a = [1.02, 0.98, 1.05, 0.97, 1.01, 1.03, 0.99];
    let bb = [1.10, 1.04, 1.12, 1.01, 1.08, 1.15];
    for b in backends("compare") {
        let mut s = Store::open(&b.location, true).unwrap();
        for (lot, vals) in [("A", &a[..]), ("B", &bb[..])] {
            for (i, v) in vals.iter().enumerate() {
                s.add(&record(&format!("{lot}{i}"), Some(lot), &[("x", "scale_factor", *v)])).unwrap();
            }
        }
        let c = query::compare(&mut s, "A", "B").unwrap();
        let t = c[0].test.unwrap();
        assert_eq!((c[0].n1, c[0].n2), (7, 6));
        assert_relative_eq!(t.t, -3.2135252690935623, max_relative = 1e-9);
        assert_relative_eq!(t.t_p_value, 0.013332958459766134, max_relative = 1e-7);
        assert_relative_eq!(t.f_p_value, 0.18509344439172562, max_relative = 1e-7);
        assert!(matches!(query::compare(&mut s, "A", "nope"), Err(StoreError::NotFound { .. })));
    }
}

#[test]
fn control_chart_flags_the_hand_made_shift() {
    // Ten devices around 10 with small alternating scatter, then nine high ones: Nelson rule 2
    // (nine on one side) must fire at the 19th point; lots L1 (first ten) and L2 give X-bar/S.
    for b in backends("chart") {
        let mut s = Store::open(&b.location, true).unwrap();
        let mut values: Vec<f64> = (0..10).map(|i| 10.0 + if i % 2 == 0 { 0.1 } else { -0.1 }).collect();
        values.extend((0..9).map(|i| 10.05 + 0.01 * (i % 3) as f64));
        for (i, v) in values.iter().enumerate() {
            let mut r = record(&format!("SN{i:02}"), Some(if i < 10 { "L1" } else { "L2" }), &[("x", "bias_dph", *v)]);
            r.test_date = Some(format!("2026-01-{:02}", i + 1));
            s.add(&r).unwrap();
        }
        let c = query::control_charts(&mut s, None, "x", "bias_dph").unwrap();
        let i = c.individuals.unwrap();
        assert_eq!(i.points, values);
        assert!(i.violations.iter().any(|v| v.rule == 2 && v.index == 18), "{}: {:?}", b.name, i.violations);
        assert_eq!(c.lots, vec!["L1", "L2"]);
        assert_eq!(c.xbar.unwrap().points.len(), 2);
    }
}

#[test]
fn concurrent_writers_all_land() {
    for b in backends("concurrent") {
        Store::open(&b.location, true).unwrap();
        let threads: Vec<_> = (0..2)
            .map(|t| {
                let loc = b.location.clone();
                std::thread::spawn(move || {
                    let mut s = Store::open(&loc, true).unwrap();
                    for i in 0..25 {
                        s.add(&record(
                            &format!("T{t}-{i}"),
                            Some("C"),
                            &[("x", "bias_dph", 10.0), ("y", "bias_dph", 10.0)],
                        ))
                        .unwrap();
                    }
                })
            })
            .collect();
        threads.into_iter().for_each(|t| t.join().unwrap());
        let mut s = Store::open(&b.location, false).unwrap();
        let lot = query::lot(&mut s, "C", 0.95).unwrap();
        assert_eq!(lot.iter().map(|f| f.n_evaluated).collect::<Vec<_>>(), vec![50, 50], "{}", b.name);
    }
}

#[test]
fn first_use_by_two_clients_at_once_migrates_once() {
    for b in backends("migrate_race") {
        let threads: Vec<_> = (0..3)
            .map(|_| {
                let loc = b.location.clone();
                std::thread::spawn(move || Store::open(&loc, true).map(|mut s| s.schema_version().unwrap()))
            })
            .collect();
        for t in threads {
            assert_eq!(t.join().unwrap().unwrap(), gyrolab_store::schema::SCHEMA_VERSION, "{}", b.name);
        }
    }
}

/// Many processes opening one new SQLite file at once: the conversion to WAL is the one step for
/// which SQLite runs no busy handler, so without the retry in `set_wal` some opens failed with
/// "database is locked" (seen in CI through the CLI's two-process test; without the retry this
/// test failed in most runs). Each round starts eight processes (this test binary again, running
/// only this test in child mode) on a fresh file, each opening the store and then storing five
/// evaluations, so that later processes open while earlier ones write. Threads of one process do
/// not show the race (SQLite shares one file lock among them).
#[test]
fn many_processes_opening_a_new_sqlite_store_at_once_all_open() {
    const CHILD: &str = "GYROLAB_TEST_STORE_OPEN_CHILD";
    if let Ok(loc) = std::env::var(CHILD) {
        // Open, then write: later processes open while earlier ones hold write transactions.
        let mut s = Store::open(&loc, true).unwrap_or_else(|e| panic!("child open: {e}"));
        assert_eq!(s.schema_version().unwrap(), gyrolab_store::schema::SCHEMA_VERSION);
        for i in 0..5 {
            let serial = format!("P{}-{i}", std::process::id());
            s.add(&record(&serial, Some("C"), &[("x", "bias_dph", 10.0)])).unwrap_or_else(|e| panic!("child add: {e}"));
        }
        return;
    }
    let exe = std::env::current_exe().unwrap();
    // The test's name in the harness: its module path without the test binary's own name.
    let name = module_path!().split_once("::").map_or(String::new(), |(_, m)| format!("{m}::"))
        + "many_processes_opening_a_new_sqlite_store_at_once_all_open";
    let mut failures = Vec::new();
    for round in 0..12 {
        let dir = tempfile::tempdir().unwrap();
        let loc = dir.path().join("gyrolab.db").display().to_string();
        let children: Vec<_> = (0..8)
            .map(|_| {
                std::process::Command::new(&exe)
                    .args([name.as_str(), "--exact", "--nocapture"])
                    .env(CHILD, &loc)
                    .stdout(std::process::Stdio::null())
                    .stderr(std::process::Stdio::piped())
                    .spawn()
                    .unwrap()
            })
            .collect();
        for c in children {
            let o = c.wait_with_output().unwrap();
            if !o.status.success() {
                failures.push(format!("round {round}: {}", String::from_utf8_lossy(&o.stderr)));
            }
        }
        let mut s = Store::open(&loc, false).unwrap();
        assert_eq!(
            count(&mut s),
            40 - 5 * failures.iter().filter(|f| f.starts_with(&format!("round {round}:"))).count()
        );
    }
    assert!(failures.is_empty(), "{} of 96 opens failed:\n{}", failures.len(), failures.join("\n"));
}

#[test]
fn a_newer_schema_is_refused_naming_both_versions() {
    for b in backends("newer_schema") {
        let mut s = Store::open(&b.location, true).unwrap();
        s.add(&record("SN1", None, &[("x", "bias_dph", 10.0)])).unwrap();
        drop(s);
        mark_newer_schema(&b, 7);
        let e = Store::open(&b.location, true).err().unwrap();
        let m = e.to_string();
        assert!(
            matches!(e, StoreError::NewerSchema { found: 7, known: gyrolab_store::schema::SCHEMA_VERSION, .. }),
            "{m}"
        );
        assert!(
            m.contains("schema version 7")
                && m.contains(&format!("up to {}", gyrolab_store::schema::SCHEMA_VERSION))
                && m.contains(gyrolab_store::SOFTWARE_VERSION),
            "{m}"
        );
    }
}

#[test]
fn corrupt_and_foreign_sqlite_files_are_refused_untouched() {
    let dir = tempfile::tempdir().unwrap();
    let cases: Vec<(&str, Vec<u8>)> = vec![
        ("text.db", b"this is not a database at all, just text\n".to_vec()),
        ("short.db", b"SQLite".to_vec()),
        ("header_only.db", {
            let mut v = b"SQLite format 3\0".to_vec();
            v.extend(std::iter::repeat_n(0xAB, 4096));
            v
        }),
    ];
    for (name, bytes) in &cases {
        let p = dir.path().join(name);
        std::fs::write(&p, bytes).unwrap();
        let e = Store::open(p.to_str().unwrap(), true).err().unwrap();
        assert!(matches!(e, StoreError::Open { .. }), "{name}: {e}");
        assert!(e.to_string().contains(name), "{e}");
        assert_eq!(&std::fs::read(&p).unwrap(), bytes, "{name} untouched");
        assert!(!dir.path().join(format!("{name}-wal")).exists());
    }
    let foreign = dir.path().join("other.db");
    rusqlite::Connection::open(&foreign).unwrap().execute_batch("CREATE TABLE customers (name TEXT)").unwrap();
    let before = std::fs::read(&foreign).unwrap();
    let e = Store::open(foreign.to_str().unwrap(), true).err().unwrap();
    assert!(e.to_string().contains("not a gyrolab store") && e.to_string().contains("customers"), "{e}");
    assert_eq!(std::fs::read(&foreign).unwrap(), before);
    let missing = dir.path().join("missing.db");
    assert!(matches!(Store::open(missing.to_str().unwrap(), false), Err(StoreError::NotFound { .. })));
    assert!(!missing.exists(), "a query does not create a store");
}

#[test]
fn postgres_down_or_wrong_password_is_a_clear_error_without_the_password() {
    // A closed port: nothing listens on port 1 of the loopback.
    let e = Store::open("postgres://lab:s3cret-pw@127.0.0.1:1/gyrolab", true).err().unwrap();
    let m = e.to_string();
    assert!(matches!(e, StoreError::Open { .. }), "{m}");
    assert!(m.contains("postgres://***@127.0.0.1:1/gyrolab") && !m.contains("s3cret-pw"), "{m}");
    if let Some(url) = pg_url("wrong_password") {
        let config: postgres::Config = url.parse().unwrap();
        let real = String::from_utf8(config.get_password().unwrap().to_vec()).unwrap();
        let wrong = url.replace(&real, "not-the-password-42");
        let e = Store::open(&wrong, true).err().unwrap();
        let m = e.to_string();
        assert!(m.contains("password authentication failed"), "{m}");
        assert!(!m.contains("not-the-password-42") && !m.contains(&real), "{m}");
        // A good connection's name is masked too.
        let s = Store::open(&url, true).unwrap();
        assert!(!s.name().contains(&real) && s.name().contains("***"));
    }
}

#[test]
fn masking_covers_urls_and_keywords() {
    use gyrolab_store::mask_location;
    // The whole user information (user and password) and any query are masked (issue 53).
    assert_eq!(mask_location("postgres://u:p@h:5432/db"), "postgres://***@h:5432/db");
    assert_eq!(mask_location("postgresql://u:p%40ss@h/db?sslmode=disable"), "postgresql://***@h/db?***");
    assert_eq!(mask_location("postgres://u@h/db?password=secret&x=1"), "postgres://***@h/db?***");
    assert_eq!(mask_location("postgres://h/db"), "postgres://h/db");
    assert_eq!(mask_location("/tmp/gyrolab.db"), "/tmp/gyrolab.db");
}

#[test]
fn a_version_1_store_is_migrated_on_first_use_and_keeps_its_records() {
    for b in backends("migrate_v1") {
        make_version_1_store(&b);
        // A record as version 1 stored it: its report files hashed only (no bytes).
        let mut old = record("OLD1", Some("L"), &[("x", "bias_dph", 10.0)]);
        {
            let mut s = Store::open(&b.location, false).unwrap();
            assert_eq!(s.schema_version().unwrap(), gyrolab_store::schema::SCHEMA_VERSION, "{}", b.name);
            for f in &mut old.report_files {
                f.content = None;
            }
            s.add(&old).unwrap();
        }
        let mut s = Store::open(&b.location, false).unwrap();
        let e = s.evaluation(1).unwrap();
        assert_eq!(e.record.serial, "OLD1");
        let m = query::report_files(&mut s, 1).unwrap_err().to_string();
        assert!(m.contains("stored as a hash only") && m.contains("results.json"), "{}: {m}", b.name);
        // A record stored now keeps its report files: written back equal.
        let new = record("NEW1", Some("L"), &[("x", "bias_dph", 10.5)]);
        let id = s.add(&new).unwrap();
        let files = query::report_files(&mut s, id).unwrap();
        assert_eq!(files, vec![("results.json".to_string(), b"{}".to_vec())], "{}", b.name);
        let lot = query::lot(&mut s, "L", 0.95).unwrap();
        assert_eq!(lot[0].n_evaluated, 2, "{}", b.name);
    }
}
