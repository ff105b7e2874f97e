"""gyrolab on a Dask cluster (issue 37, Python part): records evaluated on a
distributed.LocalCluster of two worker processes on loopback give the single-process results;
a failing record is named; the dask.bag path gives the same table."""
import numpy as np
import pandas as pd
import pytest

import gyrolab
import gyrolab.dask

distributed = pytest.importorskip("distributed", reason="dask.distributed is installed by scripts/install-test-deps.sh")


def records(folder, count=6):
    paths = []
    for i in range(count):
        rng = np.random.default_rng(100 + i)
        n = 12_000
        p = folder / f"rec{i}.csv"
        pd.DataFrame(
            {"time_s": np.arange(n) / 100.0, "gx_dps": rng.standard_normal(n) * 0.01, "ax_m_s2": rng.standard_normal(n) * 1e-3}
        ).to_csv(p, index=False)
        paths.append(str(p))
    return paths


def single_process(paths, **options):
    tables = []
    for p in paths:
        t = gyrolab.allan(p, **options).noise_table()
        t.insert(0, "record", p)
        tables.append(t)
    return pd.concat(tables, ignore_index=True)


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address=None
    )
    c = distributed.Client(cluster)
    yield c
    c.close()
    cluster.close()


def test_local_cluster_equals_single_process(client, tmp_path):
    paths = records(tmp_path)
    got = gyrolab.dask.allan_records(paths, client=client)
    want = single_process(paths)
    pd.testing.assert_frame_equal(got, want, check_exact=True)
    assert len(client.scheduler_info()["workers"]) == 2
    curves = gyrolab.dask.allan_records(paths[:2], client=client, what="curves", kind="mdev")
    np.testing.assert_array_equal(
        curves[(curves.record == paths[1]) & (curves.channel == "gx_dps")].dev.to_numpy(),
        gyrolab.allan(paths[1], kind="mdev")["gx_dps"].dev,
    )


def test_a_failing_record_is_named(client, tmp_path):
    paths = records(tmp_path, 3)
    bad = tmp_path / "broken.csv"
    bad.write_text("time_s,gx_dps\n0,0.1\n0.01,oops\n0.02,0.3\n")
    with pytest.raises(gyrolab.Error) as e:
        gyrolab.dask.allan_records(paths + [str(bad)], client=client)
    assert str(bad) in str(e.value) and e.value.file == str(bad) and e.value.line == 3
    table = gyrolab.dask.allan_records(paths + [str(bad)], client=client, errors="collect")
    assert sorted(set(table.record)) == sorted(paths)
    (failure,) = table.attrs["failures"]
    assert failure["record"] == str(bad) and "oops" in failure["error"]


def test_dask_bag_path_gives_the_same_table(tmp_path):
    import dask

    paths = records(tmp_path, 3)
    with dask.config.set(scheduler="threads"):
        got = gyrolab.dask.allan_records(paths)
    pd.testing.assert_frame_equal(got, single_process(paths), check_exact=True)
