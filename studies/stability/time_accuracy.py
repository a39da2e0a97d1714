"""The time step's accuracy guides: the figures behind the warnings of
``adhesive_contact.problem.accuracy`` (docs/scheme.md, "Accuracy guides of
the time step").

    python studies/stability/time_accuracy.py      # about 10 s

1. **memory** (``time_accuracy/memory.csv``): a standard linear solid
   E(t) = E_∞ + E_1 e^{−t/τ} (E_∞ = E_1 = 500, τ = 1, ν = 0) stretched at
   t = 0 and held to T = 40 τ, on a 4 × 1 strip (the strain is uniform,
   so the run is the quadrature alone). Per k/τ and time.scheme: how far
   the stress at T has relaxed past E_∞ ε, from the run and from the
   closed forms of :func:`adhesive_contact.problem.accuracy.quadrature_excess`
   (the right rectangle rule's c/(1 − e^{−c}) − 1, the trapezoid's
   (c/2) coth(c/2) − 1, c = k/τ, times E_1/E_∞).
2. **peel** (``time_accuracy/peel.csv``): studies/scenes/peel.toml per
   contact.bonding.integrator (``midpoint`` with time.scheme =
   "second-order") and time.steps: the peak over the levels of the lifted
   end's reaction (the peel force) and the mean of β(T), against the
   committed scene (explicit Euler, 100 steps), with k over the bonding
   law's time scale 1/((γ_ν + γ_τ) L²) = 1/15. Explicit Euler's runs
   beyond that bound stop (β leaves [0, 1]) and are listed as such.

Prints both tables; a run is recomputed each time (they are small).
"""

import tomllib
from pathlib import Path

import numpy as np

from adhesive_contact import build_problem, scene_from_dict, solve
from adhesive_contact.postprocess import reaction_sides, reactions
from adhesive_contact.problem.accuracy import quadrature_excess
from adhesive_contact.storage import write_csv

HERE = Path(__file__).resolve().parent
OUT = HERE / "time_accuracy"
PEEL = HERE.parent / "scenes" / "peel.toml"
E_INF, E_1, STRAIN, HELD = 500.0, 500.0, 1e-3, 40.0
RATIOS = (0.5, 0.2, 0.1, 0.05, 0.02, 0.01)
PEEL_STEPS = (2, 5, 10, 15, 20, 30, 50, 100, 400)
INTEGRATORS = (("explicit", "paper"), ("implicit", "paper"), ("exponential", "paper"),
               ("midpoint", "second-order"))


def held_strain_stress(ratio, scheme):
    """σ_xx/ε at T = HELD τ of the standard linear solid held at STRAIN."""
    steps = int(round(HELD / ratio))
    scene = scene_from_dict({
        "dim": 2, "mesh": {"domain": "rectangle", "size": [4.0, 1.0], "cells": [4, 1]},
        "boundary": {"dirichlet": [], "displacement": {
            "left": ["0", "free"], "right": [repr(4.0 * STRAIN), "free"],
            "bottom": ["free", "0"]}},
        "memory": {"kernel": "relaxation", "long_term": {"E": E_INF, "nu": 0.0},
                   "terms": [{"E": E_1, "tau": 1.0}]},
        "time": {"T": HELD, "steps": steps, "scheme": scheme}})
    solution = solve(build_problem(scene))
    if not solution.success:
        raise RuntimeError(solution.message)
    return float(solution.stress[-1, :, 0, 0].mean()) / STRAIN


def memory_table():
    rows = []
    for ratio in RATIOS:
        for scheme in ("paper", "second-order"):
            measured = 1.0 - held_strain_stress(ratio, scheme) / E_INF
            closed = (E_1 / E_INF) * quadrature_excess(ratio, scheme)
            rows.append((ratio, scheme, measured, closed))
    return rows


def peel_run(integrator, scheme, steps):
    data = tomllib.loads(PEEL.read_text())
    data["time"]["steps"] = steps
    data["time"]["scheme"] = scheme
    data["contact"]["bonding"]["integrator"] = integrator
    problem = build_problem(scene_from_dict(data, base_dir=PEEL.parent))
    solution = solve(problem)
    force = np.abs(reactions(solution)[:, reaction_sides(problem).index("right"), 1])
    return problem, solution, force


def peel_table():
    _, reference, force = peel_run("explicit", "paper", 100)
    peak, beta = force.max(), reference.beta[-1].mean()
    rows = []
    for integrator, scheme in INTEGRATORS:
        for steps in PEEL_STEPS:
            problem, solution, force = peel_run(integrator, scheme, steps)
            scale = problem.bonding.stable_step()
            ratio = problem.scene.k / scale
            if not solution.success:
                rows.append((integrator, steps, problem.scene.k, ratio, "stopped", "", "", ""))
                continue
            n = int(np.argmax(force))
            rows.append((integrator, steps, problem.scene.k, ratio, float(force[n]),
                         float(solution.t[n]), 100.0 * (force[n] / peak - 1.0),
                         100.0 * (solution.beta[-1].mean() / beta - 1.0)))
    return peak, rows


def main():
    OUT.mkdir(exist_ok=True)
    rows = memory_table()
    write_csv(OUT / "memory.csv", ("k_over_tau", "scheme", "relaxed_too_far_run",
                                   "relaxed_too_far_closed_form"), rows)
    print("memory: a standard linear solid held at a fixed strain, relaxed past E_inf at T")
    for ratio, scheme, measured, closed in rows:
        print(f"  k/tau = {ratio:<5g} {scheme:13s} {100 * measured:7.3f} % "
              f"(closed form {100 * closed:7.3f} %)")
    peak, rows = peel_table()
    write_csv(OUT / "peel.csv", ("integrator", "steps", "k", "k_over_time_scale", "peak_force",
                                 "t_of_peak", "peak_change_percent", "mean_beta_T_change_percent"),
              rows, digits=6)
    print(f"peel: peak force {peak:.4f} of the committed scene (explicit, 100 steps)")
    for integrator, steps, k, ratio, force, t, change, beta in rows:
        if force == "stopped":
            print(f"  {integrator:12s} {steps:4d} steps, k = {k:<7.4g} ({ratio:.3g} x the "
                  "time scale): stopped, beta left [0, 1]")
        else:
            print(f"  {integrator:12s} {steps:4d} steps, k = {k:<7.4g} ({ratio:.3g} x the "
                  f"time scale): peak {force:.4f} at t = {t:.3g} ({change:+.1f} %), "
                  f"mean beta(T) {beta:+.1f} %")


if __name__ == "__main__":
    main()
