"""The cohesive law against linear elastic fracture mechanics: a double
cantilever beam, one arm on its symmetry plane.

    python studies/validation/dcb.py

``dcb/dcb.toml``: an arm 30 × 1 (h = 1, plane strain, E = 1000, ν = 0.3)
glued to its symmetry plane by the bilinear cohesive law (σ_max = 1.5,
G_c = 0.01, K = 1.5·10⁴) beyond a precrack a0 = 10, its end lifted by
δ = 1.6 t. Beam theory with the root-rotation correction gives, with
E' = E/(1 − ν²), I = h³/12 per unit width and a_e = a + χh,

    before the crack grows:  δ = P a_e³ / (3 E' I),
    while it grows:          P = √(2 E' I G_c) / a_e,
                             so P = ((2 E' I G_c)^{3/2} / (3 E' I δ))^{1/2},

the peak P_c = √(2 E' I G_c)/(a0 + χh), and χ = (E'/(11 G) (3 − 2 (Γ/(1 +
Γ))²))^{1/2}, Γ = 1.18 E'/G (Williams' correction for an isotropic arm,
G = E/(2(1 + ν))). Compared: the peak force (5 %), the force–opening
curve while the crack grows, the peak at twice the steps (rate
independence of the law, 2 %), and the glue's dissipated energy per unit
of new crack area, Δ(dissipated.debonding)/Δ(∫(1 − β)) while the crack
front moves from 12 to 16 (2 %).

Writes ``dcb/dcb.csv`` (P against δ for both step counts and LEFM, 400
levels of each) and
``dcb/dcb.png``; each run's numbers are kept in ``dcb/runs/`` (not
recomputed).
"""

import tomllib
from pathlib import Path

import numpy as np

from adhesive_contact.storage import saved_or_computed, write_csv

HERE = Path(__file__).resolve().parent / "dcb"
E, NU, H, A0, OPENING = 1000.0, 0.3, 1.0, 10.0, 1.6
#: the step counts compared (rate independence: the second is twice the first)
STEPS = (3200, 6400)
#: the crack growth over which the energy per unit new area is measured
GROWTH = (12.0, 16.0)


def constants(data):
    """(E' I, G_c, χ) of the scene ``data``."""
    Ep = E / (1.0 - NU * NU)
    G = E / (2.0 * (1.0 + NU))
    gamma = 1.18 * Ep / G
    chi = np.sqrt(Ep / (11.0 * G) * (3.0 - 2.0 * (gamma / (1.0 + gamma)) ** 2))
    return Ep * H ** 3 / 12.0, data["contact"]["normal"]["toughness"], chi


def lefm(delta, EI, Gc, chi):
    """P(δ) of beam theory with root rotation: the elastic line up to the
    peak, the propagation curve after it."""
    elastic = 3.0 * EI * delta / (A0 + chi * H) ** 3
    growing = np.sqrt((2.0 * EI * Gc) ** 1.5 / (3.0 * EI * np.maximum(delta, 1e-300)))
    return np.minimum(elastic, growing)


def scene_data(steps=None, cells=None):
    data = tomllib.loads((HERE / "dcb.toml").read_text())
    if steps is not None:
        data["time"]["steps"] = int(steps)
    if cells is not None:
        data["mesh"]["cells"] = list(cells)
    return data


def run(steps=None, cells=None):
    """P, δ, the glue's and the numerical dissipation, ∫(1 − β) and the
    front per level, of the DCB with ``steps`` levels on ``cells``."""
    from adhesive_contact import build_problem, scene_from_dict, solve
    from adhesive_contact.postprocess import (debond_fronts, debonded_area, energies,
                                              reaction_sides, reactions)
    from adhesive_contact.problem.warnings import solution_warnings

    data = scene_data(steps, cells)
    problem = build_problem(scene_from_dict(data, base_dir=HERE))
    solution = solve(problem)
    if not solution.success:
        raise RuntimeError(solution.message)
    left = reaction_sides(problem).index("left")
    history = energies(solution)
    _, damage = debonded_area(solution)
    fronts = [float(f[:, 0].max()) if f.shape[0] else A0 for f in debond_fronts(solution)]
    return {"steps": int(data["time"]["steps"]), "cells": data["mesh"]["cells"],
            "t": solution.t.tolist(), "delta": (OPENING * solution.t).tolist(),
            "P": kept(reactions(solution)[:, left, 1]),
            "debonding": kept(history.dissipated["debonding"]),
            "numerical": kept(history.dissipated["numerical"]),
            "damage": kept(damage), "front": kept(fronts),
            "warnings": solution_warnings(solution)}


def kept(values, digits=9):
    """A list of ``values`` to ``digits`` significant digits (the runs/ files)."""
    return [float(f"{v:.{digits}g}") for v in np.asarray(values, dtype=float)]


def energy_per_new_area(record, growth=GROWTH):
    """Δ(dissipated.debonding)/Δ(∫(1 − β)) between the levels where the
    front first passes growth[0] and growth[1]; also with the numerical part."""
    front = np.array(record["front"])
    i, j = (int(np.argmax(front >= g)) for g in growth)
    if not front[j] >= growth[1]:
        raise RuntimeError(f"the crack did not grow to {growth[1]}")
    area = record["damage"][j] - record["damage"][i]
    glue = (record["debonding"][j] - record["debonding"][i]) / area
    both = glue + (record["numerical"][j] - record["numerical"][i]) / area
    return glue, both


def summary(record, data):
    EI, Gc, chi = constants(data)
    P, delta = np.array(record["P"]), np.array(record["delta"])
    peak = float(P.max())
    exact = float(np.sqrt(2.0 * EI * Gc) / (A0 + chi * H))
    front = np.array(record["front"])
    growing = (front > GROWTH[0]) & (front < GROWTH[1])
    curve = float(np.max(np.abs(P[growing] / lefm(delta[growing], EI, Gc, chi) - 1.0)))
    glue, both = energy_per_new_area(record)
    return {"steps": record["steps"], "peak": peak, "lefm_peak": exact,
            "peak_error": peak / exact - 1.0, "curve_error": curve,
            "glue_per_area_over_Gc": glue / Gc, "with_numerical_over_Gc": both / Gc}


def cached(name, compute, folder=HERE / "runs"):
    """The record ``name`` of ``folder``, computed only when no run saved it."""
    return saved_or_computed(folder / f"{name}.json", compute)


def main():
    import matplotlib.pyplot as plt

    data = scene_data()
    EI, Gc, chi = constants(data)
    records = [cached(f"steps_{n}", lambda n=n: run(n)) for n in STEPS]
    rows = []
    for rec in records:          # every level of 400 per run in the CSV
        every = max(1, rec["steps"] // 400)
        for d, p, a in list(zip(rec["delta"], rec["P"], rec["front"]))[::every]:
            rows.append((rec["steps"], d, p, float(lefm(np.array(d), EI, Gc, chi)), a))
    write_csv(HERE / "dcb.csv", ["steps", "opening", "P", "P_lefm", "front"], rows)

    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2))
    d = np.linspace(1e-3, OPENING, 400)
    left.plot(d, lefm(d, EI, Gc, chi), "k-", lw=1.2, label="LEFM, root rotation")
    for rec in records:
        left.plot(rec["delta"], rec["P"], "-", label=f"cohesive, {rec['steps']} steps")
    left.set(xlabel="opening δ of the arm's end", ylabel="force P per unit width",
             title="DCB arm: force against opening")
    left.legend(fontsize=8)
    for rec in records:
        right.plot(rec["delta"], rec["front"], "-", label=f"{rec['steps']} steps")
    right.set(xlabel="opening δ", ylabel="debond front (β = ½)", title="crack length")
    right.legend(fontsize=8)
    fig.tight_layout()
    partial = HERE / "dcb.partial.png"
    fig.savefig(partial, dpi=110)
    plt.close(fig)
    partial.replace(HERE / "dcb.png")

    results = [summary(rec, data) for rec in records]
    for r in results:
        print(f"{r['steps']} steps: peak {r['peak']:.5g} (LEFM {r['lefm_peak']:.5g}, "
              f"{100 * r['peak_error']:+.2f} %), force-opening while growing within "
              f"{100 * r['curve_error']:.2f} % of LEFM, glue's energy per new area "
              f"{r['glue_per_area_over_Gc']:.4f} G_c ({r['with_numerical_over_Gc']:.4f} "
              f"with the numerical part)")
    print(f"peak at {STEPS[1]} against {STEPS[0]} steps: "
          f"{100 * (results[1]['peak'] / results[0]['peak'] - 1):+.2f} %")


if __name__ == "__main__":
    main()
