"""Do two versions of the code give the same fields on the committed scenes?

    python studies/bench/same_fields.py save DIR [--all]        # with one version installed
    python studies/bench/same_fields.py save DIR2 [--all]       # with the other
    python studies/bench/same_fields.py compare DIR DIR2        # prints, writes DIR2/same_fields.json

``save`` runs every ``studies/scenes/*.toml`` in-process and keeps u, β,
the contact forces and the Newton iterations of every level in
``DIR/NAME.npz``; with ``--all``, every committed scene under studies/ of
at most 2e5 dofs too (the convergence, validation, stability and bench
scenes, about 5 minutes here), and adaptive-step variants of the
default and debonding scenes (``[time.adaptive]``, both schemes), so that
both step controllers are compared. ``compare`` prints per scene the largest difference of u
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
STUDIES = HERE.parent
SCENES = sorted((STUDIES / "scenes").glob("*.toml"))
#: adaptive-step variants: (name, scene file, the [time.adaptive] and [time] keys added)
ADAPTIVE = (("adaptive_default", "scenes/default.toml", "tol = 0.01", ""),
            ("adaptive_debonding", "scenes/debonding.toml", "tol = 0.003", ""),
            ("adaptive_default_second_order", "scenes/default.toml", "tol = 0.01",
             'scheme = "second-order"'))
LARGEST = 2e5   # dofs of the largest scene run with --all


def scenes(every):
    """(name, scene) of the scenes compared."""
    from adhesive_contact import load_scene, parse_scene
    from adhesive_contact.resources import estimate

    if not every:
        return [(path.stem, load_scene(path)) for path in SCENES]
    out = []
    for path in sorted(STUDIES.rglob("*.toml")):
        scene = load_scene(path)
        if estimate(scene).dofs <= LARGEST:
            out.append((str(path.relative_to(STUDIES).with_suffix("")).replace("/", "."),
                        scene))
    for name, file, adaptive, time_keys in ADAPTIVE:
        text = (STUDIES / file).read_text().replace("[time]", f"[time]\n{time_keys}")
        out.append((name, parse_scene(text + f"\n[time.adaptive]\n{adaptive}\n",
                                      (STUDIES / file).parent)))
    return out


def save(folder, every=False):
    from adhesive_contact import build_problem, solve

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    for name, scene in scenes(every):
        solution = solve(build_problem(scene))
        np.savez(folder / f"{name}.npz", t=solution.t, u=solution.u, beta=solution.beta,
                 force=solution.contact_force, iterations=solution.iterations,
                 residual=solution.residual, success=solution.success,
                 reaction=solution.reaction)
        print(name, solution.message, int(solution.iterations.sum()), flush=True)


def relative(a, b):
    return float(np.abs(a - b).max(initial=0.0) / max(np.abs(b).max(initial=0.0), 1e-300))


def compare(first, second):
    rows = {}
    for path in sorted(Path(first).glob("*.npz")):
        a = np.load(path)
        b = np.load(Path(second) / path.name)
        if a["u"].shape != b["u"].shape:
            rows[path.stem] = {"u": float("inf")}
            print(f"{path.stem:14s} levels {a['u'].shape[0]} -> {b['u'].shape[0]}")
            continue
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
    {"save": lambda: save(sys.argv[2], "--all" in sys.argv[3:]),
     "compare": lambda: compare(sys.argv[2], sys.argv[3])}[sys.argv[1]]()
