"""Work–precision in time: the paper's scheme, the second-order scheme and
adaptive steps, error against wall time on three cases.

    python studies/convergence/work_precision_time/run.py [--cases smooth strip relaxation]

- ``smooth``: case (a) of studies/convergence (``../a_separated_slipping.toml``,
  the glue held while slipping, no set change), on its 16 × 16 mesh
  (refine 2), T = 1; the error against a second-order run of 2048 steps.
- ``strip``: the debonding strip (h) (``../h_debonding_strip.toml``); the
  error against the uniform paper's-scheme reference of 16384 steps of
  ``../adaptive/run.py`` (its records are shared).
- ``relaxation``: Lee & Radok's held approach (studies/validation/lee_radok/
  relaxation.toml, its own mesh block_L1): the error is the quantity of
  interest against the closed form, max_n |P_n/P_0 − E(t_n)/E_0|.

For ``smooth`` and ``strip``, E = max_n (‖u_n − u_ref(t_n)‖/max‖u_ref‖ +
rms_{Γ_C}(β_n − β_ref(t_n))), the reference interpolated linearly in time
(``../adaptive/run.py``). Each route is run at a ladder of uniform steps
(the paper's scheme, ``time.scheme = "second-order"``) or of
``[time.adaptive] tol`` (the paper's scheme, step doubling, k_max = T over
the coarsest uniform grid of the paper's scheme); wall time is
the solve's (``adhesive_contact.solve``, in-process, one run each: read it
as a ratio between routes on this machine). Writes ``results/CASE.csv``
and ``results/work_precision.png``; runs are kept in ``results/runs/``.
"""

import argparse
import sys
import time
import tomllib
from pathlib import Path

import numpy as np

from adhesive_contact import build_problem, scene_from_dict, solve
from adhesive_contact.storage import saved_or_computed, write_csv

HERE = Path(__file__).resolve().parent
RESULTS = HERE / "results"
sys.path.insert(0, str(HERE.parent / "adaptive"))
sys.path.insert(0, str(HERE.parents[1] / "validation"))
import run as adaptive_study  # noqa: E402  (../adaptive/run.py)

ROUTES = {"paper": "uniform, paper's scheme", "second-order": "uniform, second-order",
          "adaptive": "adaptive (tol), paper's scheme"}
LADDERS = {
    "smooth": {"paper": (4, 8, 16, 32, 64, 128), "second-order": (4, 8, 16, 32, 64),
               "adaptive": (0.1, 0.03, 0.01, 0.003, 0.001)},
    "strip": {"paper": (32, 64, 128, 256, 512, 1024, 2048),
              "second-order": (32, 64, 128, 256, 512, 1024),
              "adaptive": (0.1, 0.03, 0.01, 0.003, 0.001)},
    "relaxation": {"paper": (12, 24, 48, 96, 192, 384), "second-order": (6, 12, 24, 48, 96),
                   "adaptive": (0.1, 0.03, 0.01, 0.003, 0.001)},
}


def scene_data(case):
    """(scene dict, base folder) of a case."""
    path = {"smooth": HERE.parent / "a_separated_slipping.toml",
            "strip": HERE.parent / "h_debonding_strip.toml",
            "relaxation": HERE.parents[1] / "validation" / "lee_radok" / "relaxation.toml"}[case]
    data = tomllib.loads(path.read_text())
    if case == "smooth":
        data["mesh"]["refine"] = 2
    return data, path.parent


def built(case, route, value):
    """The scene of one run: ``value`` steps, or the tol of an adaptive run."""
    data, base = scene_data(case)
    if route == "adaptive":
        # k_max = T over the coarsest uniform grid of the paper's scheme,
        # so that the controller is free to take the steps it needs
        data["time"]["steps"] = min(LADDERS[case]["paper"])
        data["time"]["adaptive"] = {"tol": float(value)}
    else:
        data["time"]["steps"] = int(value)
        data["time"]["scheme"] = route
    return scene_from_dict(data, base_dir=base)


def reference(case):
    """What a run of ``case`` is measured against."""
    if case == "strip":
        return adaptive_study.reference()
    if case == "smooth":
        path = RESULTS / "smooth_reference_2048.npz"
        if not path.is_file():
            solution = solve(build_problem(built("smooth", "second-order", 2048)),
                             raise_on_failure=True)
            RESULTS.mkdir(parents=True, exist_ok=True)
            np.savez_compressed(path, t=solution.t, u=solution.u, beta=solution.beta)
        with np.load(path) as data:
            return data["t"], data["u"], data["beta"], 0.0
    return None


def measured(case, route, value, ref):
    """One run's record (steps, E, seconds), kept in results/runs/."""
    def compute():
        problem = build_problem(built(case, route, value))
        t0 = time.perf_counter()
        solution = solve(problem, raise_on_failure=True)
        seconds = time.perf_counter() - t0
        if case == "relaxation":
            import lee_radok
            from adhesive_contact.postprocess import reaction_sides, reactions
            top = reaction_sides(problem).index("top")
            force = -reactions(solution)[:, top, 1]
            exact = lee_radok.relaxation_modulus(solution.t) / lee_radok.E_0
            E = float(np.abs(force / force[0] - exact).max())
        else:
            M = adaptive_study.mass_matrix(problem.mesh)
            measure = np.asarray(problem.boundary.measure, dtype=float)
            E = adaptive_study.error(solution, ref, M, measure)[0]
        return {"case": case, "route": route, "value": value, "steps": int(solution.steps),
                "E": E, "seconds": seconds}
    return saved_or_computed(RESULTS / "runs" / f"{case}_{route}_{value:g}.json", compute)


def cheapest(rows, target):
    """The route reaching E ≤ target in the least wall time: (route, seconds)
    or None."""
    best = [(r["seconds"], r["route"]) for r in rows if r["E"] <= target]
    return min(best) if best else None


def plot(tables, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(tables), figsize=(5.2 * len(tables), 4.2), squeeze=False)
    for ax, (case, rows) in zip(axes[0], tables.items()):
        for route, marker in zip(ROUTES, "osd"):
            sel = [r for r in rows if r["route"] == route]
            if sel:
                ax.loglog([r["seconds"] for r in sel], [r["E"] for r in sel], "-",
                          marker=marker, label=ROUTES[route])
        ax.set_xlabel("wall time of the solve (s)")
        ax.set_ylabel("E (max over levels)")
        ax.set_title(case)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle("Work–precision in time: error against wall time")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", nargs="+", default=list(LADDERS))
    args = parser.parse_args()
    tables = {}
    for case in args.cases:
        ref = reference(case)
        rows = [measured(case, route, value, ref)
                for route, ladder in LADDERS[case].items() for value in ladder]
        tables[case] = rows
        RESULTS.mkdir(parents=True, exist_ok=True)
        write_csv(RESULTS / f"{case}.csv", ("route", "value", "steps", "E", "seconds"),
                  [(r["route"], r["value"], r["steps"], r["E"], r["seconds"]) for r in rows])
        print(f"{case}:")
        for r in rows:
            print(f"  {r['route']:13s} {r['value']:>8g}: {r['steps']:6d} steps, "
                  f"E = {r['E']:.3g}, {r['seconds']:.2f} s")
        for target in (0.1, 0.03, 0.01, 0.003):
            best = cheapest(rows, target)
            print(f"  E <= {target:g}: " + ("none" if best is None else
                                            f"{best[1]} in {best[0]:.2f} s"))
    plot(tables, RESULTS / "work_precision.png")


if __name__ == "__main__":
    main()
