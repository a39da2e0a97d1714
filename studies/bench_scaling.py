"""Cost of a run against mesh size and number of steps.

For a scene refined 0..R times (and for 10..N steps on the coarse mesh) it
measures: dofs, contact unknowns, the set-up (assembly, factorisation, the
Schur complement onto Γ_C), the time per step, and the cost of one linear
solve with the factors (the unit a step is measured in), and writes
``bench_scaling.json``, ``bench_scaling.csv`` and ``bench_scaling.png``
beside this script.

    python studies/bench_scaling.py [SCENE] [--max-refine R]

Timings are wall-clock on whatever machine runs it (2 shared cores here):
read them as orders of magnitude and as slopes.
"""

import argparse
import csv
import json
import os
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from adhesive_contact import build_problem, parse_scene, solve
from adhesive_contact.linear_solvers import SuperLUSolver as DirectSolver

HERE = Path(__file__).resolve().parent


def one_solve_seconds(problem, repeats=5):
    """Median time of one solve with a factorised step matrix."""
    scene = problem.scene
    A = problem.assembly.stiffness(scene.material.lam, scene.material.mu)
    solver = DirectSolver(A[problem.free][:, problem.free])
    b = np.random.default_rng(0).standard_normal(problem.free.size)
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        solver.solve(b)
        times.append(time.perf_counter() - t0)
    return float(np.median(times))


def measure(scene):
    problem = build_problem(scene)
    solution = solve(problem)
    steps = scene.steps + 1
    return {
        "refine": scene.mesh.refine, "steps": scene.steps, "dofs": int(problem.ndofs),
        "contact_unknowns": int(problem.columns.size),
        "assembly": solution.timings["assembly"],
        "factorisation": solution.timings["factorisation"],
        "schur": solution.timings["schur"],
        "stepping": solution.timings["stepping"],
        "per_step": solution.timings["stepping"] / steps,
        "one_solve": one_solve_seconds(problem),
        "newton_per_step": float(solution.iterations.mean()),
        "total": solution.timings["total"],
    }


def write_atomic(path, text):
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=path.name + ".")
    with os.fdopen(fd, "w") as f:
        f.write(text)
    os.replace(tmp, path)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene", nargs="?", default=str(HERE / "scenes" / "wall.toml"))
    parser.add_argument("--max-refine", type=int, default=3)
    parser.add_argument("--max-steps", type=int, default=320)
    args = parser.parse_args()
    base = parse_scene(Path(args.scene).read_text())

    rows = []
    for r in range(args.max_refine + 1):
        row = measure(replace(base, mesh=replace(base.mesh, refine=r)))
        rows.append({"study": "mesh", **row})
        print(f"refine {r}: {row['dofs']:7d} dofs, {row['contact_unknowns']:4d} contact "
              f"unknowns, set-up {row['factorisation']:.2f} s (Schur {row['schur']:.2f} s), "
              f"{1e3 * row['per_step']:.1f} ms/step = {row['per_step'] / row['one_solve']:.1f} "
              f"solves, {row['newton_per_step']:.1f} Newton it/step", flush=True)
    n = 10
    while n <= args.max_steps:
        row = measure(replace(base, steps=n))
        rows.append({"study": "steps", **row})
        print(f"steps {n:4d}: stepping {row['stepping']:.3f} s, "
              f"{1e3 * row['per_step']:.2f} ms/step", flush=True)
        n *= 2

    write_atomic(HERE / "bench_scaling.json", json.dumps(rows, indent=1))
    with open(HERE / "bench_scaling.csv.tmp", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    os.replace(HERE / "bench_scaling.csv.tmp", HERE / "bench_scaling.csv")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    mesh = [r for r in rows if r["study"] == "mesh"]
    steps = [r for r in rows if r["study"] == "steps"]
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.2))
    dofs = np.array([r["dofs"] for r in mesh])
    for key, label in [("assembly", "assembly"), ("factorisation", "factorisation + Schur"),
                       ("per_step", "one step"), ("one_solve", "one linear solve")]:
        a1.loglog(dofs, [r[key] for r in mesh], "o-", label=label)
    a1.loglog(dofs, mesh[-1]["one_solve"] * dofs / dofs[-1], "k:", label="slope 1")
    a1.set_xlabel("dofs")
    a1.set_ylabel("seconds")
    a1.set_title("cost against mesh size")
    a1.legend(fontsize=8)
    a1.grid(True, which="both", alpha=0.3)
    ns = np.array([r["steps"] for r in steps])
    a2.loglog(ns, [r["stepping"] for r in steps], "o-", label="time loop")
    a2.loglog(ns, steps[0]["stepping"] * ns / ns[0], "k:", label="slope 1")
    a2.set_xlabel("time steps N")
    a2.set_ylabel("seconds")
    a2.set_title(f"cost against steps ({steps[0]['dofs']} dofs)")
    a2.legend(fontsize=8)
    a2.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(HERE / "bench_scaling.png.tmp.png", dpi=110)
    os.replace(HERE / "bench_scaling.png.tmp.png", HERE / "bench_scaling.png")


if __name__ == "__main__":
    main()
