"""gyrolab.store with accounts (issue 53: "accounts and issue from Python"): the same workflow as
the README's command-line walk-through, from Python, on an SQLite file and on the real PostgreSQL
server (GYROLAB_TEST_PG_URL; SKIPPED without it, a failure under CI=true): accounts added by an
admin, an operator stores, an approver issues with the lab key, the issued folder verifies with
the lab's public key (`gyrolab verify`, the command line, is the independent check), an operator
cannot issue, no one issues their own work, a correction is amended, the store checks whole, and
the raw records come back byte for byte."""
import os
import subprocess

import pytest

import gyrolab
from gyrolab.store import Store

from test_store import _postgres_url, _write_device


@pytest.fixture(params=["sqlite", "postgres"])
def location(request, tmp_path):
    return str(tmp_path / "lab.db") if request.param == "sqlite" else _postgres_url()


def test_accounts_issue_amend_and_check_from_python(location, root, cli, tmp_path, monkeypatch):
    monkeypatch.delenv("GYROLAB_USER", raising=False)
    monkeypatch.delenv("GYROLAB_PASSWORD", raising=False)
    s = Store(location)
    s.add_user("admin", "admin", "admin-passw0rd", display_name="Lab Admin")
    s.add_user("olga", "operator", "operator-passw0rd", user="admin", password="admin-passw0rd")
    s.add_user("arun", "approver", "approver-passw0rd", user="admin", password="admin-passw0rd")
    assert [(a["name"], a["role"]) for a in s.accounts()] == [
        ("admin", "admin"), ("olga", "operator"), ("arun", "approver")
    ]
    with pytest.raises(gyrolab.Error, match="admin"):
        s.add_user("mallory", "admin", "mallory-passw0rd", user="olga", password="operator-passw0rd")
    # The lab key, made by the admin with the command line.
    key = tmp_path / "lab.key"
    env = dict(os.environ, GYROLAB_USER="admin", GYROLAB_PASSWORD="admin-passw0rd")
    subprocess.run([cli, "store", "key", "init", "--out", str(key), "--store", location], check=True, env=env,
                   capture_output=True)
    plan = _write_device(root, tmp_path, "PY-TRUST", 1.0)
    out = tmp_path / "draft"
    gyrolab.evaluate_plan(plan, out)
    with pytest.raises(gyrolab.Error, match="account"):
        s.add(out)  # a store with accounts: no anonymous write
    with pytest.raises(gyrolab.Error):
        s.add(out, user="olga", password="wrong-password")
    eid = s.add(out, user="olga", password="operator-passw0rd")
    audit = s.evaluation(eid)["audit"]
    assert audit[-1]["actor"] == "olga" and audit[-1]["action"] == "store", audit
    with pytest.raises(gyrolab.Error, match="approver"):
        s.issue(eid, key, user="olga", password="operator-passw0rd")
    issued = s.issue(eid, key, user="arun", password="approver-passw0rd")
    assert issued["report_number"].startswith("GL-") and issued["signer"] == "arun", issued
    folder = tmp_path / "issued"
    s.report(eid, folder)
    v = subprocess.run([cli, "verify", str(folder), "--public-key", str(tmp_path / "lab.pub")], capture_output=True, text=True)
    assert v.returncode == 0, v.stdout + v.stderr
    # A correction, amended by the approver.
    subprocess.run(
        [cli, "store", "revise", str(eid), "--kind", "correction", "--lot", "LOT-7", "--reason", "lot misrecorded",
         "--store", location],
        check=True, capture_output=True, env=dict(os.environ, GYROLAB_USER="olga", GYROLAB_PASSWORD="operator-passw0rd"),
    )
    amended = s.amend(eid + 1, "lot corrected", key, user="arun", password="approver-passw0rd")
    assert amended["amendment_no"] == 1 and amended["amends_report"] == issued["report_number"], amended
    check = s.check()
    assert check["problems"] == [] and check["head"], check
    # The raw records, from the store alone.
    plan_copy, files = s.inputs(eid, tmp_path / "audit")
    assert open(plan_copy, "rb").read() == plan.read_bytes()
    assert [open(f, "rb").read() for f in files] == [(tmp_path / "data" / "PY-TRUST.csv").read_bytes()]
    # No password in any message.
    with pytest.raises(gyrolab.Error) as e:
        s.issue(eid, key, user="arun", password="not-the-password")
    assert "not-the-password" not in str(e.value)


def test_a_reevaluation_from_python_names_its_account(location, root, tmp_path, monkeypatch):
    monkeypatch.delenv("GYROLAB_USER", raising=False)
    monkeypatch.delenv("GYROLAB_PASSWORD", raising=False)
    s = Store(location)
    plan = _write_device(root, tmp_path, "PY-RE", 1.0)
    gyrolab.evaluate_plan(plan, tmp_path / "r")
    eid = s.add(tmp_path / "r")
    r = s.reevaluate(eid, tmp_path / "re", "new version", by="CI")
    assert r["changes"] == [] and r["superseded"] == eid
    with pytest.raises(gyrolab.Error, match="password"):
        s.add(tmp_path / "r", user="someone")
