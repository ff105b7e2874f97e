"""Throughput of gyrolab.dask.allan_records on a distributed.LocalCluster: RECORDS simulated
static records (10 min at 100 Hz, two channels, Parquet) evaluated on one worker process and on
two, in one run (each worker one thread, gyrolab's own pool one thread: RAYON_NUM_THREADS=1, so
the processes are the only parallelism). Prints a Markdown table. Usage:
python bench/python_dask.py [RECORDS] [ROUNDS]"""
import os
import statistics
import sys
import tempfile
import time

os.environ["RAYON_NUM_THREADS"] = "1"  # inherited by the worker processes

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
from distributed import Client, LocalCluster

import gyrolab
import gyrolab.dask


def main():
    records = int(sys.argv[1]) if len(sys.argv) > 1 else 200
    rounds = int(sys.argv[2]) if len(sys.argv) > 2 else 3
    folder = tempfile.mkdtemp(prefix="gyrolab-dask-")
    paths = []
    for i in range(records):
        s = gyrolab.simulate_static(600.0, 100.0, seed=i + 1, arw_deg_rt_h=0.3, bias_instability_dph=5.0)
        ax = np.random.default_rng(i).standard_normal(s["output"].size) * 1e-3
        p = os.path.join(folder, f"rec{i:04d}.parquet")
        pq.write_table(pa.table({"time_s": s["time_s"], "gx_dps": s["output"], "ax_m_s2": ax}), p)
        paths.append(p)
    rows = []
    tables = {}
    for workers in (1, 2):
        with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, host="127.0.0.1",
                          dashboard_address=None) as cluster, Client(cluster) as client:
            gyrolab.dask.allan_records(paths[:4], client=client)  # warm the workers (imports)
            times = []
            for _ in range(rounds):
                t0 = time.perf_counter()
                tables[workers] = gyrolab.dask.allan_records(paths, client=client)
                times.append(time.perf_counter() - t0)
        rows.append((workers, statistics.median(times), min(times), max(times)))
    assert tables[1].equals(tables[2]), "results differ between one and two workers"
    base = rows[0][1]
    print(f"| workers ({records} records, 10 min at 100 Hz, 2 channels, Parquet) | median s | range s | records/s | vs 1 worker |")
    print("|---|---:|---:|---:|---:|")
    for w, med, lo, hi in rows:
        print(f"| {w} | {med:.2f} | {lo:.2f}-{hi:.2f} | {records / med:.0f} | {base / med:.2f}x |")
    print(f"load average at end: {os.getloadavg()[0]:.2f}", file=sys.stderr)


if __name__ == "__main__":
    main()
