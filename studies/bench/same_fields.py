"""Do two versions of the code give the same fields on the committed scenes?

    python studies/bench/same_fields.py save DIR          # with one version installed
    python studies/bench/same_fields.py save DIR2         # with the other
    python studies/bench/same_fields.py compare DIR DIR2  # prints, writes DIR2/same_fields.json

``save`` runs every ``studies/scenes/*.toml`` in-process and keeps u, β,
the contact forces and the Newton iterations of every level in
``DIR/NAME.npz``. ``compare`` prints per scene the largest difference of u
over the largest |u| of the run (and the same for β and the contact
force), the iterations of both, and the largest relative residual of the
second run's steps (what the step method reached; the scheme's residual
checks).
"""

import json
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
SCENES = sorted((HERE.parent / "scenes").glob("*.toml"))


def save(folder):
    from adhesive_contact import build_problem, load_scene, solve

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    for path in SCENES:
        solution = solve(build_problem(load_scene(path)))
        np.savez(folder / f"{path.stem}.npz", u=solution.u, beta=solution.beta,
                 force=solution.contact_force, iterations=solution.iterations,
                 residual=solution.residual, success=solution.success)
        print(path.stem, solution.message, int(solution.iterations.sum()), flush=True)


def relative(a, b):
    return float(np.abs(a - b).max(initial=0.0) / max(np.abs(b).max(initial=0.0), 1e-300))


def compare(first, second):
    rows = {}
    for path in SCENES:
        a = np.load(Path(first) / f"{path.stem}.npz")
        b = np.load(Path(second) / f"{path.stem}.npz")
        row = {"u": relative(b["u"], a["u"]), "beta": relative(b["beta"], a["beta"]),
               "force": relative(b["force"], a["force"]),
               "iterations": [int(a["iterations"].sum()), int(b["iterations"].sum())],
               "max_step": [int(a["iterations"].max()), int(b["iterations"].max())],
               "residual": float(b["residual"].max())}
        rows[path.stem] = row
        print(f"{path.stem:14s} u {row['u']:.1e}  beta {row['beta']:.1e}  force "
              f"{row['force']:.1e}  iterations {row['iterations'][0]} -> "
              f"{row['iterations'][1]} (max a step {row['max_step'][0]} -> "
              f"{row['max_step'][1]})  residual {row['residual']:.1e}")
    (Path(second) / "same_fields.json").write_text(json.dumps(rows, indent=1))


if __name__ == "__main__":
    {"save": lambda: save(sys.argv[2]), "compare": lambda: compare(sys.argv[2], sys.argv[3])}[
        sys.argv[1]]()
