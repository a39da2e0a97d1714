"""Adaptive time steps against uniform ones on the debonding strip.

    python studies/convergence/adaptive/run.py [--tols 0.1 ... 0.001] [--steps 32 ... 2048]
                                               [--reference 16384] [--held]
                                               [--scheme second-order]

The scene is (h) of studies/convergence (``../h_debonding_strip.toml``: a
glued strip with memory, slip weakening and Frémond bonding, peeled and
sheared off in a burst; the paper's scheme with the explicit integrator),
run on uniform grids of N steps and with ``[time.adaptive] tol`` (k_max =
T/32, k_min = k_max/1024, the defaults). Each run is measured against one
fine uniform reference (``--reference`` steps, 16384 by default: k =
2 k_min), interpolated linearly in time at the run's levels:

    E = max_n ( ‖u_n − u_ref(t_n)‖_{L²(Ω)} / max_m ‖u_ref(t_m)‖_{L²(Ω)}
                + (∫_{Γ_C} (β_n − β_ref(t_n))² / |Γ_C|)^½ ),

the relative L² error of u plus the rms of β over Γ_C, max over the run's
levels. For each adaptive run the uniform N with the same E is read off
the uniform curve (log-log interpolation); the goal is an adaptive run
with at most half those steps at every tol, and some tol with E ≤ 0.05.

``--scheme second-order`` runs both the uniform grids and the adaptive ones
with ``time.scheme = "second-order"`` (results in ``results/second_order/``,
or ``results/held/second_order/``), against a uniform reference of the same
scheme (4096 steps by default: its own error is far below the runs').

Writes ``results/adaptive.csv``, ``results/uniform.csv`` and
``results/adaptive.png``; every run's numbers are kept in ``results/runs/``
(a run already there is not recomputed), the reference's levels in
``results/reference_16384.npz`` (not committed: 50 MB; about a minute to
recompute).
"""

import argparse
import copy
import math
import time
import tomllib
from pathlib import Path

import numpy as np

from adhesive_contact import scene_from_dict
from adhesive_contact.problem.build import build_problem
from adhesive_contact.scheme import solve
from adhesive_contact.storage import saved_or_computed, write_csv

HERE = Path(__file__).resolve().parent
RESULTS = HERE / "results"
SCENE = HERE.parent / "h_debonding_strip.toml"
TOLS = (0.1, 0.03, 0.01, 0.003, 0.001)
STEPS = (32, 64, 128, 256, 512, 1024, 2048)
REFERENCE = 16384


#: ``--held``: the same strip to T = 2 with its load held from t = 0.8 on, so
#: that it debonds in a burst under the held load (β mean 0.95 at t = 0.8,
#: 0.10 at 1.34, 1e-4 at 1.9) and then creeps with the glue gone: a burst
#: followed by relaxation (k_max = T/32 again, within the explicit bound)
HELD = {"T": 2.0, "right": ["7*minimum(t, 0.8)", "14*minimum(t, 0.8)"]}
held = False


def scene(steps=32, tol=None, scheme="paper"):
    data = tomllib.loads(SCENE.read_text())
    data = copy.deepcopy(data)
    if held:
        data["time"]["T"] = HELD["T"]
        data["loads"]["traction"]["right"] = list(HELD["right"])
    data["time"]["steps"] = steps
    if scheme != "paper":
        data["time"]["scheme"] = scheme
    if tol is not None:
        data["time"]["adaptive"] = {"tol": tol}
    return scene_from_dict(data)


def mass_matrix(mesh):
    """The P1 mass matrix of the mesh (scalar)."""
    from skfem import Basis, BilinearForm, ElementTriP1, asm

    @BilinearForm
    def mass(u, v, _):
        return u * v
    return asm(mass, Basis(mesh, ElementTriP1()))


def reference(steps=REFERENCE, scheme="paper"):
    """(t, u, beta, seconds) of the uniform reference, saved once."""
    path = RESULTS / f"reference_{steps}.npz"
    if path.is_file():
        with np.load(path) as data:
            return data["t"], data["u"], data["beta"], float(data["seconds"])
    t0 = time.perf_counter()
    solution = solve(build_problem(scene(steps, scheme=scheme)), raise_on_failure=True)
    seconds = time.perf_counter() - t0
    RESULTS.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(path, t=solution.t, u=solution.u, beta=solution.beta,
                        seconds=seconds)
    return solution.t, solution.u, solution.beta, seconds


def interpolate(levels, t_ref, t):
    """The levels (M+1, ...) of a uniform grid t_ref, linearly at times t."""
    k = t_ref[1] - t_ref[0]
    s = np.asarray(t) / k
    m = np.minimum(np.floor(s + 1e-9).astype(int), t_ref.size - 2)
    w = (s - m).reshape(-1, *([1] * (levels.ndim - 1)))
    w = np.where(np.abs(w) < 1e-9, 0.0, w)
    return (1.0 - w) * levels[m] + w * levels[m + 1]


def error(solution, ref, M, measure):
    """E of the module docstring, and its two parts (max over levels)."""
    t_ref, u_ref, beta_ref, _ = ref
    u = interpolate(u_ref, t_ref, solution.t)
    beta = interpolate(beta_ref, t_ref, solution.t)

    def l2(v):   # (levels, npoints, d) -> (levels,)
        return np.sqrt(sum(np.sum(v[:, :, c] * (M @ v[:, :, c].T).T, axis=1)
                           for c in range(v.shape[2])))

    size = l2(u_ref).max()
    e_u = l2(np.asarray(solution.u) - u) / size
    e_b = np.sqrt(((np.asarray(solution.beta) - beta) ** 2) @ measure / measure.sum())
    E = e_u + e_b
    return float(E.max()), float(e_u.max()), float(e_b.max())


def run(name, built, ref, M, measure):
    """One run's record, saved under results/runs/."""
    def compute():
        problem = build_problem(built)
        t0 = time.perf_counter()
        solution = solve(problem, raise_on_failure=True)
        seconds = time.perf_counter() - t0
        E, e_u, e_b = error(solution, ref, M, measure)
        facts = solution.adaptive or {}
        return {"steps": int(solution.steps), "E": E, "e_u": e_u, "e_beta": e_b,
                "seconds": seconds,
                "step_solves": int(facts.get("step_solves", solution.steps + 1)),
                "rejected_pairs": int(facts.get("rejected_pairs", 0)),
                "forced_pairs": int(facts.get("forced_pairs", 0)),
                "k_smallest": float(np.diff(solution.t).min()),
                "k_largest": float(np.diff(solution.t).max())}
    return saved_or_computed(RESULTS / "runs" / f"{name}.json", compute)


def uniform_steps_for(E, uniform):
    """The N of the uniform curve with error E (log-log interpolation;
    extrapolated by the last two points outside it)."""
    N = np.array([r["steps"] for r in uniform], dtype=float)
    e = np.array([r["E"] for r in uniform])
    order = np.argsort(N)
    N, e = np.log(N[order]), np.log(e[order])
    x = math.log(E)
    i = int(np.clip(np.searchsorted(-e, -x) - 1, 0, N.size - 2))
    slope = (N[i + 1] - N[i]) / (e[i + 1] - e[i])
    return float(math.exp(N[i] + slope * (x - e[i])))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tols", type=float, nargs="+", default=TOLS)
    parser.add_argument("--steps", type=int, nargs="+", default=STEPS)
    parser.add_argument("--reference", type=int, default=None,
                        help=f"uniform steps of the reference ({REFERENCE}; 4096 for "
                             "--scheme second-order)")
    parser.add_argument("--held", action="store_true",
                        help="the load held from t = 0.8 to T = 2 (results/held/)")
    parser.add_argument("--scheme", choices=("paper", "second-order"), default="paper",
                        help="time.scheme of every run (results/.../second_order/)")
    args = parser.parse_args()
    global RESULTS, held
    if args.held:
        held, RESULTS = True, RESULTS / "held"
    if args.scheme != "paper":
        RESULTS = RESULTS / "second_order"
    if args.reference is None:
        args.reference = REFERENCE if args.scheme == "paper" else 4096
    ref = reference(args.reference, args.scheme)
    problem = build_problem(scene())
    M = mass_matrix(problem.mesh)
    measure = np.asarray(problem.boundary.measure, dtype=float)
    uniform = [run(f"uniform_{N}", scene(N, scheme=args.scheme), ref, M, measure)
               for N in args.steps]
    adaptive = [dict(run(f"adaptive_{tol:g}", scene(tol=tol, scheme=args.scheme), ref, M,
                         measure), tol=tol)
                for tol in args.tols]
    for record in adaptive:
        record["uniform_steps"] = uniform_steps_for(record["E"], uniform)
        record["ratio"] = record["steps"] / record["uniform_steps"]
    RESULTS.mkdir(parents=True, exist_ok=True)
    write_csv(RESULTS / "uniform.csv", ("steps", "E", "e_u", "e_beta", "seconds"),
              [(r["steps"], r["E"], r["e_u"], r["e_beta"], r["seconds"]) for r in uniform])
    write_csv(RESULTS / "adaptive.csv",
              ("tol", "steps", "E", "e_u", "e_beta", "uniform_steps_same_E", "ratio",
               "step_solves", "rejected_pairs", "forced_pairs", "k_smallest", "k_largest",
               "seconds"),
              [(r["tol"], r["steps"], r["E"], r["e_u"], r["e_beta"], r["uniform_steps"],
                r["ratio"], r["step_solves"], r["rejected_pairs"], r["forced_pairs"],
                r["k_smallest"], r["k_largest"], r["seconds"]) for r in adaptive])
    print(f"reference: {args.reference} uniform steps ({args.scheme}), {ref[3]:.1f} s")
    print(f"{'N':>6} {'E':>10} {'seconds':>8}")
    for r in uniform:
        print(f"{r['steps']:6d} {r['E']:10.4g} {r['seconds']:8.2f}")
    print(f"{'tol':>6} {'steps':>6} {'E':>10} {'N same E':>9} {'ratio':>6} {'solves':>7} "
          f"{'rejected':>8} {'seconds':>8}")
    for r in adaptive:
        print(f"{r['tol']:6g} {r['steps']:6d} {r['E']:10.4g} {r['uniform_steps']:9.0f} "
              f"{r['ratio']:6.2f} {r['step_solves']:7d} {r['rejected_pairs']:8d} "
              f"{r['seconds']:8.2f}")
    plot(uniform, adaptive, args.scheme)


def plot(uniform, adaptive, scheme):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for key, ax, label in (("steps", axes[0], "accepted steps"),
                           ("seconds", axes[1], "wall time (s)")):
        ax.loglog([r[key] for r in uniform], [r["E"] for r in uniform], "o-",
                  label=f"uniform ({scheme})")
        ax.loglog([r[key] for r in adaptive], [r["E"] for r in adaptive], "s-",
                  label="adaptive (step doubling)")
        for r in adaptive:
            ax.annotate(f"tol {r['tol']:g}", (r[key], r["E"]), fontsize=7)
        ax.axhline(0.05, color="grey", lw=0.8, ls=":")
        ax.set_xlabel(label)
        ax.set_ylabel("E (u rel. L² + β rms, max over levels)")
        ax.legend(fontsize=8)
    fig.suptitle("(h) debonding strip" + (", load held from t = 0.8 to T = 2" if held else "")
                 + f": adaptive against uniform steps, {scheme} scheme")
    fig.tight_layout()
    fig.savefig(RESULTS / "adaptive.png", dpi=120)


if __name__ == "__main__":
    main()
