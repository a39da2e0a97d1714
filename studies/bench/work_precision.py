"""Work and precision: the error E against the wall time of a run, across
the choices a user makes.

    python studies/bench/work_precision.py            # about 5 minutes here

The scene is the manufactured case (b) of ``studies/convergence/``
(``b_wall_multiplier.toml``: memory, adhesive compliance, a wall with a
positive multiplier on half of Γ_C, an adhesive spring, Frémond bonding),
whose friction law is smooth, so both contact quadratures apply. Each
point is one run, a (choice, h, k) with T = 1, measured by
:func:`adhesive_contact.studies.levels.run_level` against the scene's
``[exact]`` solution:

    E = max_n (‖ε(u(t_n) − u_n^hk)‖_{L²(Ω)} + ‖β(t_n) − β_n^hk‖_{L²(Γ_C)})

(docs/verification.md), and its wall time, in-process: building the
problem (mesh, assembly, manufactured loads) and solving it
(factorisations, Schur complements, every step); the error evaluation is
not counted. Each run is timed 3 times (twice above 1 s) and the fastest
is kept, and the runs go size by size, every choice in turn: the machine
is shared, and timings of the same run made minutes apart differed by up
to 1.8×. Each backend is warmed up first (imports, MKL).

Series:

- the hk path (h and k halved together from 4 × 4 cells and 4 steps) for
  each linear backend (SuperLU, PARDISO where installed, AMG + CG), for
  AMG at several CG tolerances, and for Gauss contact quadrature;
- an h × k grid with SuperLU and nodal quadrature (8 × 8 to 128 × 128
  cells × 4–128 steps): rows are h-sweeps at fixed k, columns k-sweeps at fixed h.

The AMG tolerance is the scene key ``[solver] linear_tol`` (default 1e-10).

Writes ``work_precision.csv``, ``work_precision.json`` (the points, the
machine and the cheapest run with E ≤ 1e-3) and ``work_precision.png``
beside this script, and prints a table.
"""

import argparse
import csv
import math
import time
from dataclasses import replace
from pathlib import Path

from machine import describe  # studies/bench/machine.py, beside this script

HERE = Path(__file__).resolve().parent
SCENE = HERE.parent / "convergence" / "b_wall_multiplier.toml"
TARGET = 1e-3
REPEAT_BELOW = 1.0    # seconds: runs faster than this are timed 3 times, others twice
HK_LEVELS = 6         # 4 × 4 cells / 4 steps to 128 × 128 / 128
AMG_LEVELS = 5        # AMG forms S by one CG solve per contact unknown: slow
AMG_TOLS = (1e-10, 1e-8, 1e-6, 1e-4)
GRID_REFINE = range(1, 6)
GRID_STEPS = (4, 8, 16, 32, 64, 128)


def variant(base, *, linear="superlu", quadrature="nodal", refine=0, steps=4, amg_tol=None):
    """The base scene with a backend (and AMG's tolerance), a quadrature, a
    refinement and steps."""
    from adhesive_contact.studies.levels import with_discretisation

    solver = replace(base.solver, linear=linear)
    if amg_tol is not None:
        solver = replace(solver, linear_tol=amg_tol)
    scene = replace(base, solver=solver,
                    contact=replace(base.contact, quadrature=quadrature))
    return with_discretisation(scene, refine, steps)


def measure(scene):
    """One run (level 0 of an h-study of ``scene``): its record, timed by
    the fastest of 3 when it takes under REPEAT_BELOW seconds, else of 2."""
    from adhesive_contact.studies.levels import run_level

    try:
        record = run_level(scene, "h", 0)
    except Exception as err:   # a failed point is a result too
        return {"status": f"failed: {type(err).__name__}: {err}".splitlines()[0]}
    repeats = 2 if record["seconds"] < REPEAT_BELOW else 1
    runs = [record] + [run_level(scene, "h", 0) for _ in range(repeats)]
    best = min(runs, key=lambda r: r["seconds"])
    return {**best, "status": "ok"}


def points(base, backends):
    """(series, choice, linear, quadrature, amg_tol, refine, steps) of every run."""
    out = []
    for linear in backends:
        levels = AMG_LEVELS if linear == "amg" else HK_LEVELS
        tols = AMG_TOLS if linear == "amg" else (None,)
        for tol in tols:
            choice = linear if tol is None else f"amg tol {tol:.0e}" + (
                " (default)" if tol == 1e-10 else "")
            out += [("hk", choice, linear, "nodal", tol, l, 4 * 2**l) for l in range(levels)]
    out += [("hk", "superlu, gauss", "superlu", "gauss", None, l, 4 * 2**l)
            for l in range(HK_LEVELS)]
    out += [("grid", "superlu", "superlu", "nodal", None, r, s)
            for r in GRID_REFINE for s in GRID_STEPS]
    # size by size, every choice in turn: a spell of load from other work on
    # the machine then falls on all choices of a size, not on one series
    return sorted(out, key=lambda point: (point[5], point[6]))


FIELDS = ("series", "choice", "linear", "quadrature", "amg_tol", "refine", "cells", "steps",
          "dofs", "h", "k", "err_u", "err_beta", "E", "seconds", "setup_seconds",
          "stepping_seconds", "newton_iterations", "status")


def cheapest(rows, target=TARGET):
    """The fastest run with E ≤ target, or None."""
    good = [r for r in rows if r["status"] == "ok" and r["E"] <= target]
    return min(good, key=lambda r: r["seconds"]) if good else None


def plot(rows, best, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ok = [r for r in rows if r["status"] == "ok"]
    fig, (left, right) = plt.subplots(1, 2, figsize=(13, 5.2), sharey=True)
    hk = [r for r in ok if r["series"] == "hk"]
    for choice in dict.fromkeys(r["choice"] for r in hk):
        line = [r for r in hk if r["choice"] == choice]
        style = "--" if choice.startswith("amg tol") and "default" not in choice else "-"
        left.loglog([r["seconds"] for r in line], [r["E"] for r in line], style, marker="o",
                    ms=4, label=choice)
    left.set_title("h and k halved together (hk path), 4×4 cells / 4 steps onwards")
    grid = [r for r in ok if r["series"] == "grid"]
    cmap = plt.get_cmap("viridis")
    refines = sorted({r["refine"] for r in grid})
    for i, refine in enumerate(refines):
        line = sorted((r for r in grid if r["refine"] == refine), key=lambda r: r["steps"])
        right.loglog([r["seconds"] for r in line], [r["E"] for r in line], "-o", ms=4,
                     color=cmap(i / max(len(refines) - 1, 1)),
                     label=f"{line[0]['cells']}×{line[0]['cells']} cells, 4–128 steps")
    for steps in GRID_STEPS:
        line = sorted((r for r in grid if r["steps"] == steps), key=lambda r: r["refine"])
        right.loglog([r["seconds"] for r in line], [r["E"] for r in line], ":", color="grey",
                     lw=0.8)
    right.set_title("h × k grid, SuperLU, nodal (dotted: fixed steps)")
    for ax in (left, right):
        ax.axhline(TARGET, color="k", lw=0.6)
        if best is not None:
            ax.plot(best["seconds"], best["E"], "r*", ms=14, zorder=5,
                    label=f"cheapest to E ≤ 1e-3: {best['choice']}, {best['cells']}² cells, "
                          f"{best['steps']} steps")
        ax.set_xlabel("wall time of the run [s] (set-up + stepping, in-process)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    left.set_ylabel("E = max_n ‖ε(u − u_hk)‖ + ‖β − β_hk‖")
    fig.suptitle("Work and precision on the manufactured case (b), T = 1")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def write(rows, meta, out):
    from adhesive_contact.storage import write_atomic, write_json

    write_json(out / "work_precision.json", {"meta": meta, "rows": rows})

    def table(f):
        writer = csv.DictWriter(f, fieldnames=FIELDS, extrasaction="ignore",
                                lineterminator="\n")
        writer.writeheader()
        writer.writerows(rows)

    write_atomic(out / "work_precision.csv", table)
    plot(rows, meta["cheapest"], out / "work_precision.png")


def fmt(value, spec):
    return "" if value is None or (isinstance(value, float) and math.isnan(value)) \
        else format(value, spec)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(HERE), help="folder of the outputs")
    args = parser.parse_args()

    from adhesive_contact.linear_solvers import pardiso
    from adhesive_contact.scene import load_scene

    base = load_scene(SCENE)
    backends = ["superlu"] + (["pardiso"] if pardiso.available() else []) + ["amg"]
    t_start = time.perf_counter()
    for linear in backends:   # imports, MKL's loading, the manufactured data's code
        measure(variant(base, linear=linear))
    measure(variant(base, quadrature="gauss"))

    print(f"{'series':>6} {'choice':>24} {'cells':>6} {'steps':>5} {'dofs':>6} {'E':>9} "
          f"{'seconds':>8} {'set-up':>7} {'stepping':>8}  status", flush=True)
    rows = []
    for series, choice, linear, quadrature, tol, refine, steps in points(base, backends):
        scene = variant(base, linear=linear, quadrature=quadrature, refine=refine, steps=steps,
                        amg_tol=tol)
        record = measure(scene)
        cells = base.mesh.cells[0] * 2**refine
        row = {"series": series, "choice": choice, "linear": linear, "quadrature": quadrature,
               "amg_tol": tol,
               "refine": refine, "cells": cells, "steps": steps, **record}
        rows.append(row)
        print(f"{series:>6} {choice:>24} {cells:>6} {steps:>5} {fmt(row.get('dofs'), 'd'):>6} "
              f"{fmt(row.get('E'), '.3e'):>9} {fmt(row.get('seconds'), '.3f'):>8} "
              f"{fmt(row.get('setup_seconds'), '.3f'):>7} "
              f"{fmt(row.get('stepping_seconds'), '.3f'):>8}  {row['status']}", flush=True)
    best = cheapest(rows)
    meta = {"scene": str(SCENE.relative_to(HERE.parent.parent)), "target": TARGET,
            "machine": describe(), "cheapest": best,
            "total_seconds": time.perf_counter() - t_start,
            "seconds": "run_level's wall time: build_problem + solve (set-up + stepping), "
                       "fastest of 3 runs (of 2 above 1 s); errors excluded"}
    write(rows, meta, Path(args.out))
    if best is not None:
        print(f"cheapest run with E <= {TARGET:g}: {best['choice']} ({best['quadrature']}), "
              f"{best['cells']}x{best['cells']} cells, {best['steps']} steps, "
              f"{best['dofs']} dofs: E = {best['E']:.3e} in {best['seconds']:.3f} s")
    print(f"total {meta['total_seconds']:.0f} s", flush=True)


if __name__ == "__main__":
    main()
