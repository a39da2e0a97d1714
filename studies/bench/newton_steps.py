"""Newton iterations per step of the default step method, and where the
step method's time goes.

    python studies/bench/newton_steps.py [--scenes strip,box] [--scale 1] [--tag now]

The scenes are the full models of ``ratio/`` (the 2D glued strip, 1.04e5
dofs, 50 steps; the 3D block, 1.09e5 dofs, 20 steps), run in-process with
``adhesive_contact.solve``; ``--scale s`` divides every cell count by s
(rounded, at least 2) for quick runs. For each scene it prints and saves:

- the Newton iterations of the t = 0 solve (level 0) and of the steps
  n ≥ 1: mean, max, and the mean over the steps in which the contact sets
  move ("moving": a contact node changes state — separated, compliance,
  wall, stick, slip — or crosses the glue's reach L in u_ν or |u_τ|,
  read off the fields of the level and the one before) and over the rest;
- the Newton systems solved (factorised, or AMG-preconditioned afresh:
  one an iteration, two where the semismooth step is refused) and the
  chord solves with a kept one (docs/scheme.md, "Step methods"), which
  the iterations do not count;
- the share of the step method's seconds (``timings.contact_solve``) in
  the Newton systems (``newton_solve``: factorisations and solves, minus
  the AMG hierarchy's updates), in those updates, in the Hessian of Φ,
  in products with the step matrix, in the line search and the sets
  (energy values along the trial points, the set identification, products
  excluded) and in the residual
  (pseudo-gradient, products excluded): exclusive times of wrapped
  functions, the rest "other".

Rows go to ``newton_steps.json`` (keyed by ``--tag``, so that the runs of
two versions of the code sit side by side) and ``newton_steps.csv``
beside this script. Timings are one in-process run each: read them as
shares, not as speeds (studies/bench/ratio.py compares whole processes).
"""

import argparse
import csv
import json
import time
import tomllib
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
#: name -> (scene file, tables replaced); "strip0" is the strip loaded from t = 0 on
#: (its t = 0 solve with memory: the proximal iteration of docs/scheme.md)
SCENES = {"strip": (HERE / "ratio" / "strip_full.toml", {}),
          "box": (HERE / "ratio" / "box_full.toml", {}),
          "strip0": (HERE / "ratio" / "strip_full.toml",
                     {"loads": {"traction": {"right": ["7*(0.5 + t)", "14*(0.5 + t)"]}},
                      "time": {"T": 0.5, "steps": 10}})}
FIELDS = ("tag", "scene", "scale", "dofs", "contact_unknowns", "steps", "linear", "t0",
          "mean", "max", "moving_steps", "moving_mean", "moving_max", "quiet_mean",
          "total_iterations", "newton_systems", "chord_solves", "contact_solve_s",
          "stepping_s", "share_newton_solve",
          "share_updates", "share_hessian", "share_products", "share_line_search",
          "share_residual", "share_other")


class Profile:
    """Exclusive seconds of wrapped functions, by category."""

    def __init__(self):
        self.seconds = {}
        self.stack = []
        self.calls = {}   # category -> calls that returned something (not None)

    def wrap(self, owner, name, category):
        inner = getattr(owner, name)
        profile = self

        def timed(*args, **kwargs):
            profile.stack.append(0.0)
            t0 = time.perf_counter()
            try:
                out = inner(*args, **kwargs)
                if out is not None:
                    profile.calls[name] = profile.calls.get(name, 0) + 1
                return out
            finally:
                spent = time.perf_counter() - t0
                children = profile.stack.pop()
                profile.seconds[category] = profile.seconds.get(category, 0.0) + spent - children
                if profile.stack:
                    profile.stack[-1] += spent
        setattr(owner, name, timed)
        return inner


def instrument(profile):
    """Wrap the step method's pieces (module attributes, looked up at call time)."""
    from adhesive_contact.linear_solvers.amg import AMGSolver
    from adhesive_contact.scheme import condensed, full_system
    from adhesive_contact.scheme.contact_energy import ContactEnergy
    from adhesive_contact.step_methods import base, newton

    for cls in (condensed.DenseSchur, condensed.ImplicitSchur, full_system.FullSystemMatrix):
        profile.wrap(cls, "newton_solve", "newton_solve")
        if hasattr(cls, "chord_solve"):   # the chord steps' solves with the same matrix
            profile.wrap(cls, "chord_solve", "newton_solve")
    profile.wrap(AMGSolver, "updated", "updates")
    profile.wrap(ContactEnergy, "hessian", "hessian")
    profile.wrap(condensed.RememberedProduct, "__matmul__", "products")
    profile.wrap(condensed.ImplicitSchur, "__matmul__", "products")
    profile.wrap(newton, "backtrack", "line_search")
    for name in ("semismooth_step", "chord_step"):   # their sets and line searches
        if hasattr(newton, name):
            profile.wrap(newton, name, "line_search")
    profile.wrap(newton, "stationarity", "residual")
    for name in ("update_factor", "bordered_solve"):   # factor updates, where the code has them
        for cls in (condensed.DenseSchur,):
            if hasattr(cls, name):
                profile.wrap(cls, name, "updates")
    del base


def scaled_scene(name, scale):
    from adhesive_contact import scene_from_dict

    path, replaced = SCENES[name]
    doc = {**tomllib.loads(Path(path).read_text()), **replaced}
    if scale != 1:
        doc["mesh"]["cells"] = [max(2, round(c / scale)) for c in doc["mesh"]["cells"]]
    return scene_from_dict(doc)


def regimes(solution):
    """A code per contact node and level: the state of
    adhesive_contact.postprocess plus the glue's reach in u_ν and |u_τ|."""
    from adhesive_contact.postprocess import contact_state_codes

    codes = contact_state_codes(solution).astype(np.int64)
    fd = solution.frame_displacement
    law = solution.problem.normal_law
    L = getattr(law, "L", np.inf)
    beyond_n = fd[..., 0] < -L
    slip = np.linalg.norm(fd[..., 1:], axis=-1)
    L_t = min((getattr(f, "L", np.inf) for f in getattr(solution.problem.friction, "laws", ())),
              default=np.inf)
    beyond_t = slip > L_t
    return codes + 8 * beyond_n + 16 * beyond_t


def measure(name, scale, tag):
    from adhesive_contact import build_problem, solve

    profile = Profile()
    instrument(profile)
    scene = scaled_scene(name, scale)
    problem = build_problem(scene)
    solution = solve(problem)
    if not solution.success:
        raise SystemExit(f"{name}: {solution.message}")
    it = solution.iterations
    codes = regimes(solution)
    moving = np.any(codes[1:] != codes[:-1], axis=1)   # steps 1..N
    steps_it = it[1:]
    solve_s = solution.timings["contact_solve"]
    shares = {k: v / solve_s for k, v in profile.seconds.items()}
    row = {"tag": tag, "scene": name, "scale": scale, "dofs": int(problem.ndofs),
           "contact_unknowns": int(problem.columns.size), "steps": int(steps_it.size),
           "linear": solution.linear.get("method"), "t0": int(it[0]),
           "mean": float(steps_it.mean()), "max": int(steps_it.max()),
           "moving_steps": int(moving.sum()),
           "moving_mean": float(steps_it[moving].mean()) if moving.any() else 0.0,
           "moving_max": int(steps_it[moving].max()) if moving.any() else 0,
           "quiet_mean": float(steps_it[~moving].mean()) if (~moving).any() else 0.0,
           "total_iterations": int(it.sum()),
           "newton_systems": profile.calls.get("newton_solve", 0),
           "chord_solves": profile.calls.get("chord_solve", 0), "contact_solve_s": solve_s,
           "stepping_s": solution.timings["stepping"]}
    for key in ("newton_solve", "updates", "hessian", "products", "line_search", "residual"):
        row[f"share_{key}"] = shares.get(key, 0.0)
    row["share_other"] = 1.0 - sum(shares.values())
    row["iterations"] = [int(i) for i in it]
    row["moving"] = [bool(m) for m in moving]
    return row, solution


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", default="strip,box")
    parser.add_argument("--scale", type=float, default=1.0)
    parser.add_argument("--tag", default="now")
    parser.add_argument("--out", default=str(HERE))
    parser.add_argument("--fields", default=None,
                        help="save u, beta of each run to FIELDS_NAME.npz (for comparisons)")
    args = parser.parse_args()
    from machine import describe  # studies/bench/machine.py, beside this script

    out = Path(args.out)
    store = out / "newton_steps.json"
    saved = json.loads(store.read_text()) if store.exists() else {"runs": {}}
    for name in args.scenes.split(","):
        row, solution = measure(name, args.scale, args.tag)
        if args.fields:
            np.savez(f"{args.fields}_{name}.npz", u=solution.u, beta=solution.beta,
                     iterations=solution.iterations)
        key = f"{args.tag}/{name}/{args.scale:g}"
        saved["runs"][key] = {"machine": describe(), **row}
        print(f"{args.tag} {name} (scale {args.scale:g}, {row['dofs']} dofs, "
              f"{row['contact_unknowns']} contact unknowns, {row['linear']}): t = 0 {row['t0']}; "
              f"steps mean {row['mean']:.2f}, max {row['max']}; moving ({row['moving_steps']} "
              f"steps) {row['moving_mean']:.2f} max {row['moving_max']}, quiet "
              f"{row['quiet_mean']:.2f}; {row['newton_systems']} Newton systems and "
              f"{row['chord_solves']} chord solves; step method {row['contact_solve_s']:.2f} s: Newton "
              f"systems {row['share_newton_solve']:.0%}, updates {row['share_updates']:.0%}, "
              f"Hessian {row['share_hessian']:.0%}, products {row['share_products']:.0%}, line "
              f"search {row['share_line_search']:.0%}, residual {row['share_residual']:.0%}, "
              f"other {row['share_other']:.0%}", flush=True)
        print("  per step:", " ".join(map(str, row["iterations"])), flush=True)

    from adhesive_contact.storage import write_atomic, write_json

    write_json(store, saved)

    def table(f):
        writer = csv.DictWriter(f, fieldnames=FIELDS, lineterminator="\n", extrasaction="ignore")
        writer.writeheader()
        for row in saved["runs"].values():
            writer.writerow({k: (round(v, 4) if isinstance(v, float) else v)
                             for k, v in row.items()})
    write_atomic(out / "newton_steps.csv", table)


if __name__ == "__main__":
    main()
