"""The cost of the study machinery for short runs.

A sweep of N variants of a small scene (each run ~0.1-0.5 s) is run three
ways: serially in this process, with ``jobs=2`` local worker processes, and
on a dask ``LocalCluster`` of two one-thread worker processes (started
before the clock runs, as a cluster is already up when a study is sent to
it; its workers import the package on their first run, which is counted).
One sweep per number of steps (``--steps``): short and longer runs. For each it records:

- ``validate_s``: building the :class:`~adhesive_contact.studies.Sweep`
  (every variant parsed and discretised, its warnings computed) in the
  driver, before anything runs;
- ``run_s``: the wall time of ``Sweep.run`` (start-up of the workers,
  every run, saving each record, runs.csv);
- ``runs_s``: the sum of the runs' own ``seconds`` (build and solve);
- ``startup_s``: the time to the first finished run less a mean run (the
  workers' start: spawning and importing the package, building the state);
- ``steady_per_run_s`` = (workers × (run_s − startup_s) − runs_s) / N: the
  worker time per run not spent in runs once started (sending the run,
  the record back, saving it);
- ``machinery_per_run_s``: the same with the start-up; and
  ``overhead_per_run_s`` = (workers × (validate_s + run_s) − runs_s) / N,
  everything included; each also as a percentage of the mean run
  (``*_pct``).

and writes ``study_overhead.csv`` and ``study_overhead.json`` beside this
script.

    python studies/bench/study_overhead.py [--runs N] [--steps S1,S2]

Timings are wall-clock on whatever machine runs it (2 shared cores here).
"""

import argparse
import csv
import json
import os
import platform
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
SCENE = HERE.parent / "scenes" / "block.toml"
COLUMNS = ("steps", "mode", "workers", "runs", "validate_s", "run_s", "runs_s", "mean_run_s",
           "validate_per_run_s", "startup_s", "steady_per_run_s", "machinery_per_run_s",
           "overhead_per_run_s", "validate_pct", "steady_pct", "machinery_pct", "overhead_pct")


def measure(mode, workers, text, settings, folder, executor=None):
    from adhesive_contact.studies import Sweep

    t0 = time.perf_counter()
    sweep = Sweep(text, settings, folder=folder)
    t1 = time.perf_counter()
    finished = []

    def progress(stage, done, total):
        if done > len(finished):
            finished.append(time.perf_counter())

    result = sweep.run(jobs=workers if executor is None else 1, executor=executor,
                       progress=progress)
    t2 = time.perf_counter()
    assert all(r["outcome"] == "ok" for r in result.records), "a run failed"
    n = len(result.records)
    runs_s = sum(r["seconds"] for r in result.records)
    mean = runs_s / n
    validate_s, run_s = t1 - t0, t2 - t1
    startup_s = max(finished[0] - t1 - mean, 0.0)
    machinery = (workers * run_s - runs_s) / n
    steady = (workers * (run_s - startup_s) - runs_s) / n
    overhead = (workers * (validate_s + run_s) - runs_s) / n
    return {"mode": mode, "workers": workers, "runs": n, "validate_s": validate_s,
            "run_s": run_s, "runs_s": runs_s, "mean_run_s": mean,
            "validate_per_run_s": validate_s / n, "startup_s": startup_s,
            "steady_per_run_s": steady, "machinery_per_run_s": machinery,
            "overhead_per_run_s": overhead, "validate_pct": 100 * validate_s / n / mean,
            "steady_pct": 100 * steady / mean, "machinery_pct": 100 * machinery / mean,
            "overhead_pct": 100 * overhead / mean}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=24)
    parser.add_argument("--steps", default="40,160",
                        help="comma-separated: one sweep per number of steps (the run length)")
    args = parser.parse_args()

    from distributed import LocalCluster

    from adhesive_contact.studies import dask_executor

    text = SCENE.read_text()
    values = [float(c) for c in range(10_000, 10_000 + 1_000 * args.runs, 1_000)]
    rows = []
    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                           dashboard_address=":0", silence_logs=40)
    try:
        with tempfile.TemporaryDirectory() as tmp, \
                dask_executor(cluster.scheduler_address) as executor:
            tmp = Path(tmp)
            # imports and first-call caches of this process, outside the clock
            measure("warm-up", 1, text, [("contact.normal.c", values[:1])], tmp / "warm")
            for steps in map(int, args.steps.split(",")):
                settings = [("contact.normal.c", values), ("time.steps", [steps])]
                for mode, workers, ex in (("serial", 1, None), ("jobs 2", 2, None),
                                          ("dask LocalCluster 2x1", 2, executor)):
                    row = measure(mode, workers, text, settings, tmp / f"{steps}-{workers}"
                                  f"-{ex is not None}", ex)
                    rows.append({"steps": steps, **row})
    finally:
        cluster.close()

    for row in rows:
        print(f"{row['mode']}, {row['steps']} steps: {row['runs']} runs of {row['mean_run_s']:.3f} s on "
              f"{row['workers']} worker(s), wall {row['validate_s'] + row['run_s']:.2f} s "
              f"for {row['runs_s']:.2f} s of runs\n"
              f"  validation (driver, before the runs) {row['validate_per_run_s'] * 1e3:.1f} "
              f"ms per run = {row['validate_pct']:.1f} %\n"
              f"  workers' start-up {row['startup_s']:.2f} s once; then "
              f"{row['steady_per_run_s'] * 1e3:.1f} ms per run = {row['steady_pct']:.1f} % "
              f"(start-up included: {row['machinery_pct']:.1f} %)\n"
              f"  all included: {row['overhead_per_run_s'] * 1e3:.1f} ms per run = "
              f"{row['overhead_pct']:.1f} % of a run")
    with open(HERE / "study_overhead.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, COLUMNS, lineterminator="\n")
        writer.writeheader()
        writer.writerows(rows)
    meta = {"scene": str(SCENE.relative_to(HERE.parent.parent)),
            "set": "contact.normal.c", "cpus": os.cpu_count(),
            "python": platform.python_version(), "rows": rows}
    (HERE / "study_overhead.json").write_text(json.dumps(meta, indent=2) + "\n")


if __name__ == "__main__":
    main()
