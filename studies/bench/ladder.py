"""The cost of a run from 1e3 to 1e6 dofs: the benchmark of the solver.

A ladder of scenes in 2D and 3D, frictionless (compliance and a wall), the
full model (memory, adhesive compliance, slip weakening and an adhesive
spring, Frémond bonding, a wall) and its baseline "elastic" (the same mesh
and loads with no contact terms and no memory), 20 steps each, for each
linear backend asked for. Every case runs in its own process (so its peak memory
is its own) and records:

- ``dofs``, ``contact_unknowns``;
- ``assembly`` (build_problem), ``setup`` (factorisation and Schur
  complement), ``stepping`` and ``total`` seconds, ``per_step``;
- ``solve_pair``: the linear work of one step alone (condensing the load
  and expanding the interior: a forward and a backward solve with PARDISO's
  partial factorisation, two solves with A_II otherwise; with AMG, whose
  step iterates on all free dofs, one AMG-CG solve of the step matrix),
  and ``pairs_per_step`` = per_step / solve_pair: what a step costs in
  units of its unavoidable linear work;
- ``newton_per_step``; ``cg_per_step``: with AMG, the CG iterations of
  the Newton systems a step; ``peak_mib``: the process's peak resident memory;
- ``estimate_seconds``, ``estimate_mib``: what
  :func:`adhesive_contact.resources.estimate` predicted from the scene;
- ``repeats``, ``spread``: with ``--repeat R`` a case (up to
  ``--max-repeat-dofs``) runs R times, each in its own process, and its
  fastest run is the row; ``spread`` is its slowest total over its fastest.

It writes ``ladder.csv``, ``ladder.json`` (with the machine) and
``ladder.png`` beside this script, and prints the fitted growth exponents
of set-up and step time in the dofs and, per size, the full model's total
time over its fastest elastic baseline's (any backend).

    python studies/bench/ladder.py [--max-dofs 1.1e6] [--backends auto,superlu,amg] [--dims 2,3]
                                   [--repeat 3]

(AMG and SuperLU stop below the largest sizes: see SKIP.)

Timings are wall-clock on whatever machine runs it (2 shared cores here):
read them as orders of magnitude and as slopes.
"""

import argparse
import csv
import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
from machine import describe  # studies/bench/machine.py, beside this script

HERE = Path(__file__).resolve().parent
STEPS = 20

# size parameter m -> cells; dofs ≈ 2 (8m+1)(m+1) in 2D, 3 (4m+1)(m+1)(2m+1) in 3D.
# The 3D full model at 1.1e5 dofs has 6336 contact unknowns, at 9.9e5 dofs
# 28152: "auto" takes AMG on all free dofs for it from 2000 on (a direct
# backend's dense Cholesky of that size per Newton iteration, some 260 of
# them in 20 steps, is what --backends pardiso shows)
LADDER = {(2, "frictionless"): [8, 25, 80, 250], (2, "full"): [8, 25, 80, 250],
          (2, "elastic"): [8, 25, 80, 250],
          (3, "frictionless"): [3, 7, 16, 34], (3, "full"): [3, 7, 16, 34],
          (3, "elastic"): [3, 7, 16, 34]}
# SuperLU in 3D: its minimum degree fill grows like n^(5/3) (39 s to factorise
# 4e4 dofs, studies/bench/linear_backends.py); a case takes up to three such
# factorisations, so 1e5 dofs would take a quarter of an hour: skipped; in
# 2D at 1e6 dofs its factors take 5 GB
SKIP = {("superlu", 3): 2e4, ("superlu", 2): 3e5,
        # PARDISO's dense Schur route at 28152 contact unknowns: S alone 6.3 GB
        # and a Cholesky of it per Newton iteration (minutes each)
        ("pardiso", 3): 2e5,
        # AMG in 2D: its Newton on all free dofs is 7 times slower than the
        # dense Schur route at 1e5 dofs (1282 contact unknowns), shown small;
        # in 3D at 1e6 dofs it is what "auto" runs
        ("amg", 2): 3e4, ("amg", 3): 2e5}

GLUE = {
    "normal": {"law": "adhesive_compliance", "c": 1e4, "gamma": 5e3, "L": 0.01},
    "friction": [{"law": "nonmonotone", "a": 2.0, "b": 1.0, "alpha": 50.0},
                 {"law": "adhesive_spring", "gamma": 2e3, "L": 0.01}],
    "bonding": {"law": "fremond", "beta0": 1.0, "gamma_nu": 1e5, "gamma_tau": 5e4,
                "eps_a": 0.0, "L": 0.01},
}


def scene(dim, m, model, backend):
    """The scene document of one case."""
    if dim == 2:
        mesh = {"domain": "rectangle", "size": [4.0, 0.5], "cells": [8 * m, m]}
        pull = ["7*t", "14*t"]
    else:
        mesh = {"domain": "box", "size": [4.0, 1.0, 2.0], "cells": [4 * m, m, 2 * m]}
        pull = ["7*t", "14*t", "0"]
    doc = {"title": f"ladder {dim}D {model}", "dim": dim, "mesh": mesh,
           "boundary": {"dirichlet": ["left"], "contact": ["bottom"]},
           "material": {"E": 1000.0, "nu": 0.3},
           "time": {"T": 1.0, "steps": STEPS},
           "solver": {"linear": backend}}
    if model in ("full", "elastic"):
        doc["memory"] = {"kernel": "prony", "terms": [{"E": 200.0, "nu": 0.3, "tau": 0.5}]}
        doc["loads"] = {"traction": {"right": pull}}
        doc["contact"] = {"gap": 0.05, **GLUE}
        if model == "elastic":   # the baseline: no contact terms, no memory
            doc.pop("memory"), doc.pop("contact"), doc["boundary"].pop("contact")
    else:   # pressed onto a compliant layer and a wall, no friction
        doc["loads"] = {"body": ["0", "-40*t"] + (["0"] if dim == 3 else [])}
        doc["contact"] = {"gap": 0.002, "normal": {"law": "compliance", "c": 1e4}}
    return doc


def run_case(doc):
    """One case, in this process: the record of the module docstring."""
    from adhesive_contact import build_problem, scene_from_dict, solve
    from adhesive_contact.resources import estimate
    from adhesive_contact.scheme.operators import StepOperators

    scene = scene_from_dict(doc)
    guess = estimate(scene)
    t0 = time.perf_counter()
    problem = build_problem(scene)
    assembly = time.perf_counter() - t0
    solution = solve(problem)
    total = time.perf_counter() - t0
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    timings = solution.timings
    # the linear work of one step, with the run's backend
    operators = StepOperators.build(problem, problem.options.k)
    step = operators.step
    b = np.random.default_rng(0).standard_normal(problem.free.size)
    pairs = []
    for _ in range(3):
        t = time.perf_counter()
        if operators.within is not None:   # AMG on all free dofs: one AMG-CG solve
            step.solver.solve(b)
        else:
            step.expand(step.reduce(b)[: step.contact.size] * 0.0, b)
        pairs.append(time.perf_counter() - t)
    per_step = timings["stepping"] / solution.t.size
    return {
        "dim": doc["dim"], "model": doc["title"].split()[-1],
        "backend": solution.linear["method"], "dofs": int(problem.ndofs),
        "contact_unknowns": int(problem.columns.size) if problem.boundary is not None else 0,
        "steps": STEPS,
        "success": bool(solution.success),
        "assembly": assembly, "setup": timings["factorisation"], "stepping": timings["stepping"],
        "total": total, "per_step": per_step,
        "solve_pair": float(np.median(pairs)),
        "pairs_per_step": per_step / float(np.median(pairs)),
        "newton_per_step": float(solution.iterations[1:].mean()) if solution.t.size > 1 else 0.0,
        # AMG on all free dofs: the CG iterations of its Newton systems a step
        "cg_per_step": solution.linear.get("cg_iterations", 0) / max(solution.t.size - 1, 1),
        "peak_mib": peak,
        # adhesive_contact.resources' estimate from the scene alone, which a
        # run must not exceed by much (it refuses runs beyond the machine)
        "estimate_seconds": guess.seconds, "estimate_mib": guess.memory_bytes / 2**20,
    }


def growth(rows, key):
    """Least-squares exponent p of key ∝ dofs^p over the rows."""
    if len(rows) < 2:
        return None
    x = np.log([r["dofs"] for r in rows])
    y = np.log([max(r[key], 1e-9) for r in rows])
    return float(np.polyfit(x, y, 1)[0])


def write(rows, exponents):
    with open(HERE / "ladder.csv.tmp", "w", newline="") as f:
        # every key of every row (rows kept from an older ladder.json may lack
        # the newer columns: empty there)
        fields = list(dict.fromkeys(key for row in rows for key in row))
        writer = csv.DictWriter(f, fieldnames=fields, restval="")
        writer.writeheader()
        writer.writerows(rows)
    os.replace(HERE / "ladder.csv.tmp", HERE / "ladder.csv")
    machine = describe()
    (HERE / "ladder.json.tmp").write_text(json.dumps(
        {"machine": machine, "rows": rows, "growth": exponents}, indent=1))
    os.replace(HERE / "ladder.json.tmp", HERE / "ladder.json")

    plot(rows, machine)


COLOURS = {"frictionless": "tab:blue", "full": "tab:red", "elastic": "0.45"}
STYLES = {"pardiso": ("o", "-"), "superlu": ("s", "--"), "amg": ("^", ":")}


def plot(rows, machine):
    """ladder.png: set-up, one step and a step in solve pairs against the
    dofs, 2D above and 3D below; colour the model, marker the backend."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D

    fig, axes = plt.subplots(2, 3, figsize=(15, 8.2), layout="constrained")
    for (dim, model, backend), group in _groups(rows).items():
        dofs = [r["dofs"] for r in group]
        marker, line = STYLES.get(backend, ("x", "-."))
        style = {"marker": marker, "linestyle": line, "color": COLOURS.get(model, "k")}
        row = axes[dim - 2]
        row[0].loglog(dofs, [r["setup"] for r in group], **style)
        row[1].loglog(dofs, [r["per_step"] for r in group], **style)
        row[2].semilogx(dofs, [r["pairs_per_step"] for r in group], **style)
    for dim, row in zip((2, 3), axes):
        for ax, title, ylabel in zip(row, ["set-up (factorisation + Schur)", "one step",
                                           "a step in solve pairs"],
                                     ["seconds", "seconds", "per step / solve pair"]):
            ax.set(title=f"{dim}D: {title}", xlabel="dofs", ylabel=ylabel)
            ax.grid(True, which="both", alpha=0.3)
        row[2].set_yscale("log")
    handles = ([Line2D([], [], color=c, label=m) for m, c in COLOURS.items()]
               + [Line2D([], [], color="k", marker=mk, linestyle=ls, label=b)
                  for b, (mk, ls) in STYLES.items()])
    fig.legend(handles=handles, loc="outside right center", fontsize=9)
    fig.suptitle(f"ladder: {STEPS} steps per case, {machine['cpus']} cores")
    fig.savefig(HERE / "ladder.tmp.png", dpi=100)
    os.replace(HERE / "ladder.tmp.png", HERE / "ladder.png")


def _groups(rows):
    """Rows by (dim, model, backend), one per size (the first: "auto" and
    the backend it picked give the same case)."""
    out = {}
    for r in rows:
        group = out.setdefault((r["dim"], r["model"], r["backend"]), {})
        group.setdefault(r["dofs"], r)
    return {key: [group[n] for n in sorted(group)] for key, group in out.items()}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--max-dofs", type=float, default=1.1e6)
    parser.add_argument("--backends", default="auto")
    parser.add_argument("--dims", default="2,3",
                        help="the dimensions to run; the rows of the others are kept "
                             "from ladder.json")
    parser.add_argument("--repeat", type=int, default=1,
                        help="runs of each case, the fastest kept (timings on a shared "
                             "machine move by 20-45 %% from run to run)")
    parser.add_argument("--max-repeat-dofs", type=float, default=2e5,
                        help="cases above this size run once whatever --repeat says")
    parser.add_argument("--case", help=argparse.SUPPRESS)   # one case, in a child process
    parser.add_argument("--replot", action="store_true",
                        help="redraw ladder.png from ladder.json without running")
    args = parser.parse_args()
    if args.replot:
        document = json.loads((HERE / "ladder.json").read_text())
        plot(document["rows"], document["machine"])
        return
    if args.case:
        print(json.dumps(run_case(json.loads(args.case))))
        return
    dims = [int(d) for d in args.dims.split(",")]
    rows = []
    if set(dims) != {2, 3} and (HERE / "ladder.json").exists():
        rows = [r for r in json.loads((HERE / "ladder.json").read_text())["rows"]
                if r["dim"] not in dims]
    for (dim, model), sizes in LADDER.items():
        if dim not in dims:
            continue
        for backend in args.backends.split(","):
            for m in sizes:
                dofs = 2 * (8 * m + 1) * (m + 1) if dim == 2 else \
                    3 * (4 * m + 1) * (m + 1) * (2 * m + 1)
                if dofs > args.max_dofs:
                    continue
                if dofs > SKIP.get((backend, dim), np.inf):
                    print(f"{dim}D {model} {backend}: {dofs} dofs skipped (see SKIP)")
                    continue
                row = run_repeated(scene(dim, m, model, backend),
                                   args.repeat if dofs <= args.max_repeat_dofs else 1)
                if isinstance(row, str):
                    print(f"{dim}D {model} {backend} m={m}: failed\n{row}")
                    continue
                rows.append(row)
                print(f"{dim}D {model:12s} {row['backend']:8s} {row['dofs']:8d} dofs, "
                      f"{row['contact_unknowns']:5d} on Γ_C: set-up {row['setup']:7.2f} s, "
                      f"{1e3 * row['per_step']:8.1f} ms/step = "
                      f"{row['pairs_per_step']:5.1f} solve pairs, "
                      f"{row['newton_per_step']:4.1f} Newton/step, total {row['total']:7.1f} s,"
                      f" peak {row['peak_mib']:6.0f} MiB", flush=True)
    exponents = {f"{dim}D {model} {backend}": {"setup": growth(g, "setup"),
                                               "per_step": growth(g, "per_step")}
                 for (dim, model, backend), g in _groups(rows).items()}
    for name, e in exponents.items():
        if e["setup"] is not None:
            print(f"growth in dofs, {name}: set-up ~ n^{e['setup']:.2f}, "
                  f"step ~ n^{e['per_step']:.2f}")
    for row in rows:
        row["over_elastic"] = over_elastic(row, rows)
        if row["model"] == "full" and row["over_elastic"] is not None:
            print(f"{row['dim']}D full / elastic, {row['backend']}, {row['dofs']} dofs: "
                  f"{row['over_elastic']:.2f} x")
    write(rows, exponents)


def run_repeated(doc, repeat):
    """The row of the fastest of ``repeat`` runs of a case, each in its own
    process, with ``repeats`` and ``spread`` (slowest over fastest total);
    the child's stderr tail when a run fails."""
    found = []
    for _ in range(repeat):
        done = subprocess.run([sys.executable, __file__, "--case", json.dumps(doc)],
                              capture_output=True, text=True)
        if done.returncode:
            return done.stderr[-2000:]
        found.append(json.loads(done.stdout.splitlines()[-1]))
    totals = [row["total"] for row in found]
    return min(found, key=lambda row: row["total"]) | {
        "repeats": repeat, "spread": max(totals) / min(totals)}


def over_elastic(row, rows):
    """The total time of ``row`` over that of the fastest elastic baseline
    of its dimension and size (whichever backend: what the same mesh costs
    without contact terms and memory at best), or None."""
    baselines = [other["total"] for other in rows
                 if other["model"] == "elastic" and other["dim"] == row["dim"]
                 and other["dofs"] == row["dofs"]]
    return row["total"] / min(baselines) if baselines else None


if __name__ == "__main__":
    main()
