"""The full model's cost over its elastic baseline as a user meets it, and
the floor under that ratio.

    python studies/bench/ratio.py [--dims 2,3] [--repeat 3]   # about 2 min (2D), 6 min (3D)

The scenes are beside this script in ``ratio/``: the ladder's strip (2D,
1.04e5 dofs, 640 × 80 cells, 50 steps) and box (3D, 1.09e5 dofs,
64 × 16 × 32 cells, 20 steps), each as the full model (Prony memory,
adhesive compliance, slip weakening and an adhesive spring, Frémond
bonding, a wall) and as its baseline "elastic" (the same mesh and loads,
no contact terms, no memory). Each runs as a user runs it,
``adhcontact solve SCENE --out DIR --quiet`` (outputs and plots
included), full and elastic alternating, ``--repeat`` times each; the
figures are medians of the wall seconds.

From each full run's ``summary.json``: ``timings.contact_solve``, the
seconds of the step method (the nonsmooth solve on the contact unknowns),
and the Newton iterations. Everything else the full model adds (its
set-up, the contact bookkeeping of a step, the contact outputs and plots)
is paid whatever the step method does, so

    floor = (full − contact_solve) / elastic

is the ratio a step method costing nothing would give, and a target ratio
r leaves the step method ``r × elastic − (full − contact_solve)`` seconds
(``budget``), shown per step and per Newton iteration of today's method.

Writes ``ratio.csv`` and ``ratio.json`` (with the machine) beside this
script and prints one row per dimension.
"""

import argparse
import csv
import json
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

from machine import adhcontact, describe  # studies/bench/machine.py, beside this script

HERE = Path(__file__).resolve().parent
# dim -> (scene name, the target ratio: 1.3 and 1.5 when the speed targets were
# first set, re-set to 1.5 and 3 for what two or three Newton iterations a step allow)
SCENES = {2: ("strip", 1.5), 3: ("box", 3.0)}
FIELDS = ("dim", "dofs", "contact_unknowns", "steps", "repeats", "full_s", "elastic_s", "ratio",
          "contact_solve_s", "floor", "target", "budget_s", "budget_per_step_ms",
          "newton_iterations", "newton_now_ms", "full_runs_s", "elastic_runs_s")


def run(scene):
    """(wall seconds, summary.json) of one ``adhcontact solve`` of ``scene``."""
    cli = adhcontact()
    with tempfile.TemporaryDirectory() as folder:
        out = Path(folder) / "out"
        t0 = time.perf_counter()
        subprocess.run([cli, "solve", str(scene), "--out", str(out), "--quiet"], check=True,
                       stdout=subprocess.DEVNULL)
        seconds = time.perf_counter() - t0
        summary = json.loads((out / "summary.json").read_text())
    return seconds, summary


def measure(dim, repeats):
    """The row of one dimension (see the module doc)."""
    name, target = SCENES[dim]
    full, elastic, solves, newton = [], [], [], []
    for _ in range(repeats):
        seconds, summary = run(HERE / "ratio" / f"{name}_full.toml")
        full.append(seconds)
        solves.append(summary["timings"]["contact_solve"])
        newton.append(sum(summary["iterations"]))
        elastic.append(run(HERE / "ratio" / f"{name}_elastic.toml")[0])
    full_s, elastic_s = statistics.median(full), statistics.median(elastic)
    solve_s = statistics.median(solves)
    steps = summary["scene"]["time"]["steps"]
    budget = target * elastic_s - (full_s - solve_s)
    return {"dim": dim, "dofs": summary["mesh"]["dofs"],
            "contact_unknowns": summary["resources"]["used"]["contact_unknowns"],
            "steps": steps, "repeats": repeats, "full_s": full_s, "elastic_s": elastic_s,
            "ratio": full_s / elastic_s, "contact_solve_s": solve_s,
            "floor": (full_s - solve_s) / elastic_s, "target": target, "budget_s": budget,
            "budget_per_step_ms": 1e3 * budget / steps,
            "newton_iterations": statistics.median(newton),
            "newton_now_ms": 1e3 * solve_s / statistics.median(newton),
            "full_runs_s": [round(s, 2) for s in full],
            "elastic_runs_s": [round(s, 2) for s in elastic]}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dims", default="2,3")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--out", default=str(HERE), help="folder of the CSV and JSON")
    args = parser.parse_args()
    rows = []
    for dim in (int(d) for d in args.dims.split(",")):
        row = measure(dim, args.repeat)
        rows.append(row)
        print(f"{dim}D, {row['dofs']} dofs, {row['steps']} steps: full {row['full_s']:.2f} s, "
              f"elastic {row['elastic_s']:.2f} s, ratio {row['ratio']:.2f} (target "
              f"{row['target']}); step method {row['contact_solve_s']:.2f} s in "
              f"{row['newton_iterations']:g} Newton iterations "
              f"({row['newton_now_ms']:.0f} ms each); floor {row['floor']:.2f}; the target "
              f"leaves it {row['budget_s']:.2f} s ({row['budget_per_step_ms']:.0f} ms a step)",
              flush=True)

    from adhesive_contact.storage import write_atomic, write_json

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    write_json(out / "ratio.json", {"machine": describe(), "rows": rows})

    def table(f):
        writer = csv.DictWriter(f, fieldnames=FIELDS, lineterminator="\n")
        writer.writeheader()
        for row in rows:
            writer.writerow({k: (round(v, 4) if isinstance(v, float) else v)
                             for k, v in row.items()})
    write_atomic(out / "ratio.csv", table)


if __name__ == "__main__":
    main()
