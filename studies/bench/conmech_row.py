"""The conmech comparison row: our cost on conmech's static setup 0.

    python studies/bench/conmech_row.py            # about 15 s here

conmech (a Python contact code) reports 64 s of set-up, 1.7 s of solve and
9.6 GB for the static "schur" solve of its setup 0 at 5,233 nodes. Those
are conmech's published figures (their paper/repository), quoted in our
issue #8: they were not measured here, and conmech is not installed here.
The same scene is ``conmech_setup0.toml`` beside this script (cross mesh
80 × 32 cells, λ = μ = 4, body force (−0.2, −0.2), normal compliance
c r_+ with c = 1, clamped on the left, contact at the bottom, one step).

Measured on our side:

- whole process: ``adhcontact solve conmech_setup0.toml --quiet`` as a
  subprocess into a temporary folder (start-up, imports, run, and writing
  summary.json, the npz, XDMF and PNG outputs): its wall seconds (the
  fastest of 3) and its peak RSS (``resource.getrusage(RUSAGE_CHILDREN)``,
  the largest over the children; they run before this script imports
  NumPy, so a child does not inherit a large parent's high-water mark);
- in-process (after one warm-up run in the same process, fastest of 3;
  the warm-up's own figure, with first-use costs, is ``first_in_process_s``):
  set-up = ``build_problem`` (mesh, assembly, Γ_C) + the factorisation and
  Schur complement; solve = the time loop (both levels t = 0 and t = 1:
  the scheme solves the initial level too); and the nodes and dofs.

Writes ``conmech_row.csv`` and ``conmech_row.json`` (with the machine)
beside this script and prints the two rows.
"""

import argparse
import csv
import resource
import subprocess
import tempfile
import time
from pathlib import Path

from machine import adhcontact, describe  # studies/bench/machine.py, beside this script

HERE = Path(__file__).resolve().parent
SCENE = HERE / "conmech_setup0.toml"
REPEATS = 3
CONMECH = {   # quoted in issue #8 from conmech's paper/repository: NOT measured here
    "code": "conmech (published figures, quoted in issue #8; not measured here)",
    "nodes": 5233, "setup_s": 64.0, "solve_s": 1.7, "peak_rss_mb": 9.6e3,
}


def whole_process(scene, repeats=REPEATS):
    """(fastest wall seconds, peak RSS in MB) of ``adhcontact solve`` runs."""
    cli = adhcontact()
    seconds = []
    for _ in range(repeats):
        with tempfile.TemporaryDirectory() as out:
            t0 = time.perf_counter()
            subprocess.run([cli, "solve", str(scene), "--out", out, "--quiet"],
                           check=True, stdout=subprocess.DEVNULL)
            seconds.append(time.perf_counter() - t0)
    peak_kb = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss   # KiB on Linux
    return min(seconds), peak_kb / 1024


def in_process(scene_path, repeats=REPEATS):
    """The fastest of ``repeats`` runs after a warm-up: a dict of seconds and sizes."""
    from adhesive_contact.problem import build_problem
    from adhesive_contact.scene import load_scene
    from adhesive_contact.scheme import solve

    scene = load_scene(scene_path)
    runs = []
    for _ in range(repeats + 1):
        t0 = time.perf_counter()
        problem = build_problem(scene)
        built = time.perf_counter() - t0
        solution = solve(problem, raise_on_failure=True)
        total = time.perf_counter() - t0
        stepping = solution.timings["stepping"]
        runs.append({"setup_s": total - stepping, "build_problem_s": built,
                     "factorisation_s": solution.timings["factorisation"],
                     "solve_s": stepping, "in_process_s": total,
                     "newton_iterations": int(solution.iterations.sum()),
                     "backend": solution.linear["method"]})
    best = min(runs[1:], key=lambda r: r["in_process_s"])
    mesh = problem.mesh
    return {**best, "first_in_process_s": runs[0]["in_process_s"], "nodes": int(mesh.p.shape[1]), "cells": int(mesh.t.shape[1]),
            "dofs": int(problem.ndofs), "free_dofs": int(problem.free.size),
            "contact_nodes": int(problem.boundary.nodes.size)}


FIELDS = ("code", "nodes", "dofs", "setup_s", "solve_s", "in_process_s", "process_s",
          "peak_rss_mb", "backend")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(HERE), help="folder of the CSV and JSON")
    args = parser.parse_args()

    process_s, peak_mb = whole_process(SCENE)   # first: this process is still small
    ours = {"code": "adhesive_contact (measured here)", **in_process(SCENE),
            "process_s": process_s, "peak_rss_mb": peak_mb}

    from adhesive_contact.storage import write_atomic, write_json

    out = Path(args.out)
    write_json(out / "conmech_row.json", {
        "scene": str(SCENE.relative_to(HERE.parent.parent)), "machine": describe(),
        "ours": ours, "conmech_quoted": CONMECH,
        "notes": "setup_s: build_problem + factorisation + Schur complement (factorisation_s: "
                 "the step operators' build, both); solve_s: the "
                 "time loop (levels t = 0 and 1); fastest of 3 after a warm-up. process_s: "
                 "adhcontact solve --quiet as a subprocess, outputs included, fastest of 3; "
                 "peak_rss_mb: its peak RSS. conmech's row is quoted, not measured."})

    def table(f):
        writer = csv.DictWriter(f, fieldnames=FIELDS, extrasaction="ignore", lineterminator="\n")
        writer.writeheader()
        writer.writerows([CONMECH, ours])

    write_atomic(out / "conmech_row.csv", table)

    def cell(row, key, spec):
        return format(row[key], spec) if row.get(key) is not None else "–"

    print(f"{'':<66} {'nodes':>6} {'dofs':>6} {'set-up s':>9} {'solve s':>8} "
          f"{'in-proc s':>9} {'process s':>9} {'peak MB':>8}")
    for row in (CONMECH, ours):
        print(f"{row['code']:<66} {cell(row, 'nodes', 'd'):>6} {cell(row, 'dofs', 'd'):>6} "
              f"{cell(row, 'setup_s', '.3f'):>9} {cell(row, 'solve_s', '.3f'):>8} "
              f"{cell(row, 'in_process_s', '.3f'):>9} {cell(row, 'process_s', '.2f'):>9} "
              f"{cell(row, 'peak_rss_mb', '.0f'):>8}")
    print(f"ours: backend {ours['backend']}, {ours['newton_iterations']} Newton iterations, "
          f"{ours['contact_nodes']} contact nodes; conmech's figures are quoted from issue #8")


if __name__ == "__main__":
    main()
