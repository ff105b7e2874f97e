"""Rate tables, static tests, reading, simulation and test plans through the package give the
command line's figures and simulated truth."""
import json
import subprocess

import numpy as np
import pytest

import gyrolab


def paper(root, axis):
    return root / "data" / "paper" / f"paper_rate_table_{axis}.csv"


def test_paper_rate_tables_equal_the_command_line(cli, root):
    files = [paper(root, a) for a in "xyz"]
    py = gyrolab.rate_table(files=files, axis_names=["x", "y", "z"])
    out = subprocess.run([cli, "rate", *map(str, files), "--axis", "x", "--axis", "y", "--axis", "z", "--json"],
                         check=True, capture_output=True, text=True).stdout
    c = json.loads(out)
    assert py["axes"] == c["axes"]


def test_rate_table_from_arrays_matches_the_file(root):
    rows = [l.split(",") for l in paper(root, "x").read_text().splitlines() if l and l[0] in "-0123456789"]
    rates = np.array([float(r[0]) for r in rows])
    runs = [int(r[1]) for r in rows]
    strokes = [r[2] for r in rows]
    outputs = np.array([float(r[3]) for r in rows])
    a = gyrolab.rate_table(rates, outputs, runs, strokes, unit="v")["axes"][0]
    f = gyrolab.rate_table(files=[paper(root, "x")], axis_names=["x"])["axes"][0]
    assert a["scale_factor"] == pytest.approx(f["scale_factor"], rel=1e-15)
    assert a["nonlinearity_pct"] == pytest.approx(f["nonlinearity_pct"], rel=1e-12)
    # Independent least-squares slope through the per-rate means.
    u = np.unique(rates)
    means = np.array([outputs[rates == r].mean() for r in u])
    k = np.polyfit(u, means, 1)[0]
    assert a["scale_factor"] == pytest.approx(k, rel=1e-10)


def test_bias_of_a_simulated_record():
    s = gyrolab.simulate_static(1200.0, 100.0, seed=4, arw_deg_rt_h=0.3, bias_dph=40.0)
    b = gyrolab.bias(s["output"], rate_hz=100.0, unit="dps")
    se = 0.3 / 60.0 / np.sqrt(1200.0) * 3600.0  # deg/h, standard error of the mean of white noise
    assert abs(b["bias_dph"] - 40.0) < 5 * se
    assert b["mean_output"] == pytest.approx(float(np.mean(s["output"])), rel=1e-12)


def test_simulation_equals_the_command_lines_record(cli, tmp_path):
    p = tmp_path / "s.csv"
    subprocess.run([cli, "simulate", "static", "--duration-s", "20", "--sample-rate-hz", "50", "--seed", "9",
                    "--arw-deg-rt-h", "0.5", "--out", str(p)], check=True)
    d = gyrolab.read(p, as_dataframe=False)
    s = gyrolab.simulate_static(20.0, 50.0, seed=9, arw_deg_rt_h=0.5)
    np.testing.assert_allclose(d["rate_dps"], s["output"], rtol=1e-15, atol=0)
    np.testing.assert_allclose(d["time_s"], s["time_s"], rtol=1e-15, atol=1e-15)


def test_evaluate_plan_writes_the_report(root, tmp_path):
    out = tmp_path / "report"
    r = gyrolab.evaluate_plan(root / "examples" / "paper_plan.toml", out)
    assert r["verdict"] == "FAIL" and r["failures"]
    assert (out / "report.html").exists() and (out / "results.json").exists()
    # The checks not evaluated (no static records in the paper's plan) come back with their reason.
    assert any("bias_stability_dph_10s" in u and "not available" in u for u in r["undecided"]), r["undecided"]
    results = json.loads((out / "results.json").read_text())
    assert results["simulated"] is False and len(results["integrity"]["inputs"]) == 3
    assert (out / "plan_copy.toml").read_bytes() == (root / "examples" / "paper_plan.toml").read_bytes()


def test_apply_inverts_the_calibration(cli, root, tmp_path):
    cal = tmp_path / "cal.toml"
    subprocess.run([cli, "rate", str(paper(root, "x")), "--axis", "x", "--cal-out", str(cal)], check=True,
                   capture_output=True)
    f = gyrolab.rate_table(files=[paper(root, "x")], axis_names=["x"])["axes"][0]
    k, f0 = f["scale_factor"], f["zero_offset"]
    rates = np.array([-100.0, 0.0, 50.0, 1000.0])
    out = gyrolab.apply(f0 + k * rates, cal)
    np.testing.assert_allclose(out["rate_dps"][:3], rates[:3], rtol=1e-9, atol=1e-9)
    assert list(out["status"]) == ["inside", "inside", "inside", "above"]
