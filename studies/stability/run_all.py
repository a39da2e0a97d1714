"""Stability maps: regenerate every sweep, CSV and PNG of studies/stability/.

    python studies/stability/run_all.py [--jobs 2]

Each map is a parameter sweep of the sweep runner
(:class:`adhesive_contact.studies.Sweep`, resumable: a finished run is
kept in ``NAME/runs/`` and not recomputed), post-processed into one CSV
and one PNG beside it. A few minutes in all on the project's 2-core
machine. See studies/README.md, "Stability maps", for the discussion.

1. ``integrators``: contact.bonding.integrator × time.steps × γ_ν on the
   peeled strip (coarse): outcome and error of mean β(T) against
   Λ = k (γ_ν + γ_τ) L², explicit Euler's threshold being Λ = 1.
2. ``solvers``: solver.method × α (slip weakening, a − b = 4) × c
   (normal compliance) on a strip sheared along a wall: converged or not,
   iterations, and whether the methods that converge agree; the smallness
   and step-convexity lines of the theory drawn with the trace constant
   of the mesh. ``starting_points.csv``: one step solved by "newton" from
   several starting points at each (α, c).
3. ``penalty``: solver.penalty on the same strip: wall violation,
   iterations and distance to the exact method.
4. ``work_precision``: solver.method × solver.tol (and solver.penalty for
   "penalty") with Tresca friction: error of the final normal force
   against the cost.
"""

import argparse
import csv
import tomllib
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from adhesive_contact import build_problem, scene_from_dict  # noqa: E402
from adhesive_contact.scheme.operators import StepOperators  # noqa: E402
from adhesive_contact.scheme.state import ContactStep  # noqa: E402
from adhesive_contact.step_methods import StepOptions, minimise  # noqa: E402
from adhesive_contact.studies import Sweep  # noqa: E402

HERE = Path(__file__).resolve().parent
METHODS = ["newton", "newton-plain", "penalty", "optimizer"]
MARKERS = {"newton": "o", "newton-plain": "s", "penalty": "^", "optimizer": "D",
           "explicit": "o", "implicit": "s", "exponential": "^"}


def sweep(name, scene, settings, jobs, mode="grid"):
    """Run (or resume) a sweep in HERE/name; its records."""
    result = Sweep(HERE / scene, settings, mode, folder=HERE / name).run(jobs=jobs)
    return result.records


def write_csv(path, rows):
    with open(path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]), lineterminator="\n")
        writer.writeheader()
        for row in rows:
            writer.writerow({k: "" if v is None else v for k, v in row.items()})


def relative(a, b):
    return abs(a - b) / max(abs(b), 1e-300)


# ---------------------------------------------------------------- 1. integrators

STEPS = [4, 6, 8, 10, 12, 15, 20, 30, 40, 60, 80, 160]
GAMMA_NU = [5e4, 1e5, 2e5]
REFERENCE_STEPS = 1280


def integrators(jobs):
    doc = tomllib.loads((HERE / "integrators.toml").read_text())
    bonding = doc["contact"]["bonding"]
    records = sweep("integrators", "integrators.toml",
                    [("contact.bonding.integrator", ["explicit", "implicit", "exponential"]),
                     ("contact.bonding.gamma_nu", GAMMA_NU), ("time.steps", STEPS)], jobs)
    # fine explicit references of mean β(T) per γ_ν (Λ = 15 / 1280 ≈ 0.01)
    refs = {r["values"]["contact.bonding.gamma_nu"]: r["beta_mean_T"] for r in sweep(
        "integrators_reference", "integrators.toml",
        [("contact.bonding.gamma_nu", GAMMA_NU), ("time.steps", [REFERENCE_STEPS])], jobs)}
    rows = []
    for r in records:
        v = r["values"]
        g_nu, N = v["contact.bonding.gamma_nu"], v["time.steps"]
        lam = (g_nu + bonding["gamma_tau"]) * bonding["L"] ** 2 * doc["time"]["T"] / N
        ok = r["outcome"] == "ok"
        rows.append({"integrator": v["contact.bonding.integrator"], "gamma_nu": g_nu,
                     "steps": N, "Lambda": lam, "outcome": r["outcome"],
                     "failed_step": r["failure"]["step"] if not ok else None,
                     "beta_min_T": r.get("beta_min_T"), "beta_mean_T": r.get("beta_mean_T"),
                     "error_beta_mean_T": relative(r["beta_mean_T"], refs[g_nu]) if ok else None,
                     "newton_total": r.get("newton_total"), "seconds": r["seconds"]})
    write_csv(HERE / "integrators.csv", rows)

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
    for i, name in enumerate(["explicit", "implicit", "exponential"]):
        mine = [r for r in rows if r["integrator"] == name]
        ok = [r for r in mine if r["outcome"] == "ok"]
        bad = [r for r in mine if r["outcome"] != "ok"]
        ax1.scatter([r["Lambda"] for r in ok], [i] * len(ok), marker="o", color="tab:green",
                    label="β in [0, 1], converged" if i == 0 else None)
        ax1.scatter([r["Lambda"] for r in bad], [i] * len(bad), marker="x", color="tab:red",
                    label="stopped: β left [0, 1]" if bad and i == 0 else None)
        ax2.loglog([r["Lambda"] for r in ok], [r["error_beta_mean_T"] for r in ok],
                   MARKERS[name], label=name, alpha=0.7)
    for ax in (ax1, ax2):
        ax.axvline(1.0, color="k", ls="--", lw=1)
        ax.set_xscale("log")
        ax.set_xlabel("Λ = k (γ_ν + γ_τ) L²   (explicit Euler bound: Λ ≤ 1)")
    ax1.set_yticks([0, 1, 2], ["explicit", "implicit", "exponential"])
    ax1.legend(loc="center left", fontsize=8)
    ax1.set_title("outcome (3 values of γ_ν per Λ)")
    ax2.set_ylabel("relative error of mean β(T)")
    ax2.set_title(f"against explicit Euler with {REFERENCE_STEPS} steps")
    ax2.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(HERE / "integrators.png", dpi=110)
    plt.close(fig)


# ---------------------------------------------------------------- 2. solvers

ALPHA = [1.0, 10.0, 50.0, 200.0, 1000.0]
COMPLIANCE = [1e1, 1e2, 1e3, 1e4, 1e5]


def smallness_terms(scene_file):
    problem = build_problem(scene_from_dict(tomllib.loads((HERE / scene_file).read_text())))
    s = problem.smallness
    return s["m_A"], s["trace_constant_squared"]


def solvers(jobs):
    doc = tomllib.loads((HERE / "solvers.toml").read_text())
    friction = doc["contact"]["friction"][0]
    spread = friction["a"] - friction["b"]
    records = sweep("solvers", "solvers.toml",
                    [("contact.friction.0.alpha", ALPHA), ("contact.normal.c", COMPLIANCE),
                     ("solver.method", METHODS), ("solver.tol", [1e-7])], jobs)
    m_A, ce2 = smallness_terms("solvers.toml")
    by_point = {}
    for r in records:
        v = r["values"]
        by_point.setdefault((v["contact.friction.0.alpha"], v["contact.normal.c"]), {})[
            v["solver.method"]] = r
    rows = []
    for (alpha, c), runs in sorted(by_point.items()):
        exact_ok = [m for m in ("newton", "newton-plain", "optimizer")
                    if runs[m]["outcome"] == "ok"]
        forces = [runs[m]["normal_force_T"] for m in exact_ok]
        spread_force = (max(relative(f, forces[0]) for f in forces) if len(forces) > 1
                        else None)
        for m in METHODS:
            r = runs[m]
            rows.append({"alpha": alpha, "c": c, "nonconvexity": alpha * spread,
                         "method": m, "outcome": r["outcome"],
                         "iterations": r["newton_total"] if r["outcome"] == "ok"
                         else r["failure"]["iterations"],
                         "residual": r["residual"], "normal_force_T": r.get("normal_force_T"),
                         "slip_T": r.get("slip_T"), "stick_T": r.get("stick_T"),
                         "exact_methods_spread": spread_force,
                         "estimate_holds": m_A > (alpha * spread + c) * ce2,
                         "step_convex": m_A > alpha * spread * ce2})
    write_csv(HERE / "solvers.csv", rows)

    fig, axes = plt.subplots(1, 4, figsize=(16, 4), sharey=True)
    X, Y = np.meshgrid(np.array(ALPHA) * spread, COMPLIANCE)
    for ax, m in zip(axes, METHODS):
        mine = [r for r in rows if r["method"] == m]
        for r in mine:
            ok = r["outcome"] == "ok"
            ax.scatter(r["nonconvexity"], r["c"], marker="o" if ok else "x",
                       color="tab:green" if ok else "tab:red", s=60)
            ax.annotate(str(r["iterations"]), (r["nonconvexity"], r["c"]), fontsize=7,
                        xytext=(4, 4), textcoords="offset points")
        mc = np.logspace(0, np.log10(X.max() * 2), 50)
        ax.plot(mc, np.maximum(m_A / ce2 - mc, 1e-1), "k--", lw=1,
                label="smallness m_A = (m_τ + c) c_e²")
        ax.axvline(m_A / ce2, color="tab:blue", lw=1, label="convexity m_A = α(a−b) c_e²")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_ylim(3, 3e5)
        ax.set_title(f"{m} (numbers: total iterations)")
        ax.set_xlabel("α (a − b)")
    axes[0].set_ylabel("contact stiffness c")
    axes[0].legend(fontsize=7, loc="lower left")
    fig.tight_layout()
    fig.savefig(HERE / "solvers.png", dpi=110)
    plt.close(fig)
    starting_points(spread)


def starting_points(spread, tries=6, seed=0):
    """One step (n = 1) at each (α, c) solved by "newton" from z0 = 0 and
    from random starting points of the size of the solution: the number of
    distinct solutions (relative distance > 1e-6) it finds."""
    rng = np.random.default_rng(seed)
    rows = []
    doc = tomllib.loads((HERE / "solvers.toml").read_text())
    doc["time"]["steps"] = 1
    for alpha in ALPHA:
        for c in COMPLIANCE:
            doc["contact"]["friction"][0]["alpha"] = alpha
            doc["contact"]["normal"]["c"] = c
            problem = build_problem(scene_from_dict(doc))
            ops = StepOperators.build(problem, problem.options.k)
            step = ops.at(False)
            rhs = step.reduce(ops.to_frames(problem.loads(problem.options.k)))
            contact = ContactStep(problem)
            contact.energy.set_bonding(problem.beta0)
            contact.kink.radius = contact.energy.node_kink(problem.boundary.point_node,
                                                           problem.boundary.nodes.size)
            upper = problem.upper_bound(None if problem.gap is None else problem.gap.at(problem.options.k))
            options = StepOptions(1e-10, 200)
            first = minimise("newton", step.S, rhs, contact.energy, upper,
                             np.zeros(rhs.size), options, contact.kink)
            size = max(np.abs(first.z).max(), 1e-12)
            solutions, energies, failed = [first.z], [first.energy], 0
            for _ in range(tries):
                z0 = first.z + 2 * size * rng.standard_normal(rhs.size)
                out = minimise("newton", step.S, rhs, contact.energy, upper, z0, options,
                               contact.kink)
                if not out.success:
                    failed += 1
                    continue
                if all(np.abs(out.z - s).max() > 1e-6 * size for s in solutions):
                    solutions.append(out.z)
                    energies.append(out.energy)
            rows.append({"alpha": alpha, "c": c, "nonconvexity": alpha * spread,
                         "starts": tries + 1, "failed": failed + (not first.success),
                         "distinct_solutions": len(solutions),
                         "energy_spread": (max(energies) - min(energies)) / abs(energies[0])})
    write_csv(HERE / "starting_points.csv", rows)


# ---------------------------------------------------------------- 3. penalty

PENALTY = [1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8]


def penalty(jobs):
    records = sweep("penalty", "solvers.toml", [("solver.method", ["penalty"]),
                                                ("solver.penalty", PENALTY)], jobs)
    ref = sweep("penalty_reference", "solvers.toml", [("solver.method", ["newton"])], jobs)[0]
    rows = []
    for r in records:
        ok = r["outcome"] == "ok"
        rows.append({"penalty": r["values"]["solver.penalty"], "outcome": r["outcome"],
                     "wall_violation": r.get("max_un_minus_g"),
                     "iterations": r["newton_total"] if ok else r["failure"]["iterations"],
                     "force_error": relative(r["normal_force_T"], ref["normal_force_T"])
                     if ok else None, "seconds": r["seconds"]})
    write_csv(HERE / "penalty.csv", rows)
    ok = [r for r in rows if r["outcome"] == "ok"]
    fig, ax = plt.subplots(figsize=(6, 4.2))
    ax.loglog([r["penalty"] for r in ok], [r["wall_violation"] for r in ok], "o-",
              label="max (u_ν − g) (wall violation)")
    ax.loglog([r["penalty"] for r in ok], [r["force_error"] for r in ok], "s-",
              label="relative error of the normal force at T")
    for r in rows:
        if r["outcome"] != "ok":
            ax.axvline(r["penalty"], color="tab:red", ls=":", lw=1)
    ax2 = ax.twinx()
    ax2.plot([r["penalty"] for r in rows], [r["iterations"] for r in rows], "k^--", lw=1,
             label="Newton iterations (all steps)")
    ax2.set_ylabel("iterations")
    ax.set_xlabel("solver.penalty (ρ / max S_ii); red: no convergence")
    ax.legend(fontsize=8, loc="lower left")
    ax2.legend(fontsize=8, loc="upper center")
    fig.tight_layout()
    fig.savefig(HERE / "penalty.png", dpi=110)
    plt.close(fig)


# ---------------------------------------------------------------- 4. work-precision

TOLS = [1e-4, 1e-6, 1e-8, 1e-10, 1e-12]


def work_precision(jobs):
    records = sweep("work_precision", "tresca.toml",
                    [("solver.method", ["newton", "newton-plain", "optimizer"]),
                     ("solver.tol", TOLS)], jobs)
    records += sweep("work_precision_penalty", "tresca.toml",
                     [("solver.method", ["penalty"]), ("solver.penalty", PENALTY[1:7])], jobs)
    ref = sweep("work_precision_reference", "tresca.toml",
                [("solver.method", ["newton"]), ("solver.tol", [1e-13])], jobs)[0]
    rows = []
    for r in records:
        v, ok = r["values"], r["outcome"] == "ok"
        rows.append({"method": v["solver.method"], "tol": v.get("solver.tol"),
                     "penalty": v.get("solver.penalty"), "outcome": r["outcome"],
                     "iterations": r["newton_total"] if ok else r["failure"]["iterations"],
                     "seconds": r["seconds"],
                     "force_error": relative(r["normal_force_T"], ref["normal_force_T"])
                     if ok else None})
    write_csv(HERE / "work_precision.csv", rows)
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
    for m in METHODS:
        ok = [r for r in rows if r["method"] == m and r["outcome"] == "ok"]
        if not ok:
            continue
        err = [max(r["force_error"], 1e-16) for r in ok]
        ax1.loglog([r["iterations"] for r in ok], err, MARKERS[m] + "-", label=m)
        ax2.loglog([r["seconds"] for r in ok], err, MARKERS[m] + "-", label=m)
    ax1.set_xlabel("iterations, all steps (L-BFGS-B: its own)")
    ax2.set_xlabel("seconds (build and solve)")
    for ax in (ax1, ax2):
        ax.set_ylabel("relative error of the normal force at T (floored at 1e-16)")
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(HERE / "work_precision.png", dpi=110)
    plt.close(fig)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--jobs", type=int, default=1)
    parser.add_argument("maps", nargs="*",
                        default=["integrators", "solvers", "penalty", "work_precision"])
    args = parser.parse_args()
    for name in args.maps:
        globals()[name](args.jobs)
        print("wrote", name)


if __name__ == "__main__":
    main()
