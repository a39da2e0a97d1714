"""Lee & Radok: a rigid cylinder and a viscoelastic block, against the
correspondence principle.

    python studies/validation/meshes.py        # once: the graded meshes
    python studies/validation/lee_radok.py [--steps 12 24 48 96 192 384]

The block (studies/validation/lee_radok/*.toml, half model on rollers at
x = 0, graded mesh ``block_L2``, h_c = 0.0025 at the contact) is a standard linear solid
E(t) = E_∞ + E_1 e^{−t/τ} (E_∞ = E_1 = 500, τ = 1, ν = 0.3 in both parts,
``kernel = "relaxation"``) resting on a rigid cylinder of radius R = 1.

- **creep** (``creep.toml``): a constant load P_0 applied at t = 0 (load
  control: only the cylinder holds the block's vertical translation).
  With the contact growing, Lee & Radok's solution is Hertz's with the
  creep compliance J(t) = 1/E_∞ − (1/E_∞ − 1/E_0) e^{−t E_∞/(τ E_0)} in
  place of 1/E: in plane strain a(t)² = 4R(1 − ν²)P_0 J(t)/π. The
  pressure is then not Hertz's of a(t) (its second moment gives a 6 %
  too large at t = 1.5 however small k), but the displacement is: the
  surface outside the contact opens by Hertz's separation
  h(x; a) = [x √(x² − a²) − a² ln((x + √(x² − a²))/a)]/(2R). a(t) is the
  root of h(x_j; a) = g_j − u_ν,j at each of the first three open nodes
  x_j beyond the contact, averaged (:func:`half_width`).
- **relaxation** (``relaxation.toml``): the top moved down at t = 0 and
  held; the contact does not change, and P(t)/P(0) = E(t)/E_0. The scheme's
  right rectangle rule gives, exactly (the same u at every level),
  P_n/P_0 = E_n/E_0 with E_n = E_0 − E_1 (k/τ)(1 − e^{−nk/τ})/(1 − e^{−k/τ}),
  which tends to E_∞ − E_1 ((k/τ)/(1 − e^{−k/τ}) − 1): −27 % at t → ∞ for
  k/τ = 0.5, −1 % for k/τ = 0.02 (first order in k).

Writes ``lee_radok/creep.csv``, ``lee_radok/relaxation.csv`` and
``lee_radok/lee_radok.png``; each run's numbers are kept in
``lee_radok/runs/`` (a run already there is not recomputed).
"""

import argparse
import math
import tomllib
from pathlib import Path

import numpy as np

from adhesive_contact.storage import saved_or_computed, write_csv

HERE = Path(__file__).resolve().parent / "lee_radok"
E_INF, E_1, TAU, NU, R = 500.0, 500.0, 1.0, 0.3, 1.0
E_0 = E_INF + E_1
TAU_CREEP = TAU * E_0 / E_INF
STEPS = (12, 24, 48, 96, 192, 384)
#: the mesh of the study (the scenes' own, block_L1, serves the tests)
MESH = "../meshes/block_L2.msh"
#: the times the creep table reports (levels of every step count above)
TIMES = (0.0, 1.5, 3.0, 6.0)


def creep_compliance(t):
    """J(t) of the standard linear solid."""
    return 1.0 / E_INF - (1.0 / E_INF - 1.0 / E_0) * np.exp(-np.asarray(t) / TAU_CREEP)


def relaxation_modulus(t):
    return E_INF + E_1 * np.exp(-np.asarray(t) / TAU)


def discrete_modulus(n, k):
    """E_n of the right rectangle rule under a strain held from t = 0."""
    r = k / TAU
    return E_0 - E_1 * r * (1.0 - np.exp(-n * r)) / (1.0 - math.exp(-r))


def lee_radok_half_width(t, load):
    """a(t) = sqrt(4 R (1 − ν²) P_0 J(t)/π), plane strain."""
    return np.sqrt(4.0 * R * (1.0 - NU ** 2) * load * creep_compliance(t) / np.pi)


def scene(name, steps=None, mesh=None, folder=HERE):
    """The scene ``name``.toml, with ``time.steps`` and ``mesh.file`` changed."""
    from adhesive_contact import scene_from_dict

    path = folder / f"{name}.toml"
    data = tomllib.loads(path.read_text())
    if steps is not None:
        data["time"]["steps"] = steps
    if mesh is not None:
        data["mesh"]["file"] = mesh
    return scene_from_dict(data, base_dir=path.parent)


def hertz_opening(x, a):
    """Hertz's separation outside the contact, |x| > a (plane strain)."""
    root = np.sqrt(x * x - a * a)
    return (x * root - a * a * np.log((x + root) / a)) / (2.0 * R)


def half_width(problem, solution, nodes=3):
    """a per level: the root of hertz_opening(x_j, a) = g_j − u_ν,j at the
    first ``nodes`` open contact nodes x_j beyond the closed ones, averaged."""
    from scipy.optimize import brentq

    x = problem.mesh.p[0, problem.boundary.nodes]
    order = np.argsort(x)
    x = x[order]
    opening = (solution.gap[0][None, :] - solution.frame_displacement[:, :, 0])[:, order]
    closed_below = 1e-9 * solution.gap[0].max()
    a = np.empty(solution.t.size)
    for n, d in enumerate(opening):
        last = int(np.flatnonzero(d <= closed_below).max())
        a[n] = np.mean([brentq(lambda s: hertz_opening(x[j], s) - d[j], 1e-9 * x[j],
                               x[j] * (1.0 - 1e-12))
                        for j in range(last + 1, last + 1 + nodes)])
    return a


def applied_load(problem):
    """P_0 of the full model: twice the top's traction times its width."""
    from adhesive_contact.postprocess import applied_traction

    return -2.0 * applied_traction(problem, "top", np.zeros(1))[0, 1]


def run_creep(steps, mesh=MESH):
    from adhesive_contact import build_problem, solve

    problem = build_problem(scene("creep", steps, mesh))
    solution = solve(problem)
    if not solution.success:
        raise RuntimeError(solution.message)
    a = half_width(problem, solution)
    load = applied_load(problem)
    return {"steps": steps, "k": problem.scene.k, "t": solution.t.tolist(), "a": a.tolist(),
            "load": load, "iterations": int(solution.iterations.sum())}


def run_relaxation(steps, mesh=MESH):
    from adhesive_contact import build_problem, solve
    from adhesive_contact.postprocess import reaction_sides, reactions

    problem = build_problem(scene("relaxation", steps, mesh))
    solution = solve(problem)
    if not solution.success:
        raise RuntimeError(solution.message)
    top = reaction_sides(problem).index("top")
    force = reactions(solution)[:, top, 1]              # the top pushes down: < 0
    drift = max(float(np.abs(solution.u[n] - solution.u[0]).max())
                for n in range(solution.t.size))
    return {"steps": steps, "k": problem.scene.k, "t": solution.t.tolist(),
            "force": (-force).tolist(), "drift": drift}


def cached(kind, steps, compute, folder=HERE / "runs"):
    """A run's record, from ``runs/`` or computed and kept there."""
    return saved_or_computed(folder / f"{kind}_{steps}.json", lambda: compute(steps))


def creep_rows(records):
    rows = []
    for rec in records:
        t, a = np.array(rec["t"]), np.array(rec["a"])
        exact = lee_radok_half_width(t, rec["load"])
        for time in TIMES:
            n = int(round(time / rec["k"]))
            ratio = (a[n] / a[0]) ** 2 / (creep_compliance(t[n]) / creep_compliance(0.0))
            rows.append({"steps": rec["steps"], "k_over_tau": rec["k"] / TAU, "t": t[n],
                         "a": a[n], "a_lee_radok": exact[n],
                         "error_a2": (a[n] / exact[n]) ** 2 - 1.0,
                         "error_a2_ratio": ratio - 1.0})
    return rows


def relaxation_rows(records):
    rows = []
    for rec in records:
        t, force = np.array(rec["t"]), np.array(rec["force"])
        for time in TIMES[1:]:
            n = int(round(time / rec["k"]))
            exact = relaxation_modulus(t[n]) / E_0
            scheme = discrete_modulus(n, rec["k"]) / E_0
            measured = force[n] / force[0]
            rows.append({"steps": rec["steps"], "k_over_tau": rec["k"] / TAU, "t": t[n],
                         "P_over_P0": measured, "E_over_E0": exact,
                         "error": measured / exact - 1.0,
                         "scheme_closed_form": scheme,
                         "error_against_scheme": measured / scheme - 1.0,
                         "u_drift": rec["drift"]})
    return rows


def write_table(path, rows):
    """``rows`` (dicts of one set of keys) as a CSV table, 8 digits."""
    write_csv(path, list(rows[0]), [list(row.values()) for row in rows], digits=8)


def figure(creep, relaxation, path):
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(15, 4.2))
    ax = axes[0]
    fine = np.linspace(0.0, 6.0, 200)
    ax.plot(fine, lee_radok_half_width(fine, creep[-1]["load"]), "k-", lw=2,
            label="Lee & Radok")
    for rec in creep[::2]:
        ax.plot(rec["t"], rec["a"], ".-", ms=3, label=f"k/τ = {rec['k'] / TAU:g}")
    ax.set(xlabel="t", ylabel="contact half-width a", title="creep under a constant load")
    ax.legend(fontsize=8)
    ax = axes[1]
    k = np.array([rec["k"] / TAU for rec in creep])
    for time in TIMES[1:]:
        err = [abs(r["error_a2"]) for r in creep_rows(creep) if r["t"] == time]
        ax.loglog(k, err, "o-", label=f"a² against Lee & Radok, t = {time:g}")
    first = abs(creep_rows(creep[:1])[-1]["error_a2"])
    ax.loglog(k, first * k / k[0], "k--", label="slope 1")
    ax.set(xlabel="k/τ", ylabel="relative error", title="first order in k")
    ax.legend(fontsize=8)
    ax = axes[2]
    ax.plot(fine, relaxation_modulus(fine) / E_0, "k-", lw=2, label="E(t)/E₀")
    for rec in relaxation[::2]:
        force = np.array(rec["force"])
        ax.plot(rec["t"], force / force[0], ".-", ms=3, label=f"k/τ = {rec['k'] / TAU:g}")
    ax.set(xlabel="t", ylabel="P(t)/P(0)", title="relaxation under a held approach")
    ax.legend(fontsize=8)
    fig.tight_layout()
    partial = path.with_suffix(".partial.png")
    fig.savefig(partial, dpi=110)
    plt.close(fig)
    partial.replace(path)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--steps", type=int, nargs="+", default=list(STEPS))
    args = parser.parse_args()
    creep = [cached("creep", n, run_creep) for n in args.steps]
    relaxation = [cached("relaxation", n, run_relaxation) for n in args.steps]
    write_table(HERE / "creep.csv", creep_rows(creep))
    write_table(HERE / "relaxation.csv", relaxation_rows(relaxation))
    figure(creep, relaxation, HERE / "lee_radok.png")
    for row in creep_rows(creep):
        print(f"creep steps {row['steps']:4d} t = {row['t']:4.2f}: a = {row['a']:.5f} "
              f"(Lee & Radok {row['a_lee_radok']:.5f}, a² {100 * row['error_a2']:+.2f} %; "
              f"(a/a₀)² against J/J₀ {100 * row['error_a2_ratio']:+.2f} %)")
    for row in relaxation_rows(relaxation):
        print(f"relaxation steps {row['steps']:4d} t = {row['t']:4.2f}: P/P0 = "
              f"{row['P_over_P0']:.5f} against E/E0 {row['E_over_E0']:.5f} "
              f"({100 * row['error']:+.2f} %); scheme's closed form "
              f"{row['error_against_scheme']:+.1e}")


if __name__ == "__main__":
    main()
