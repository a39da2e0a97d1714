"""Volumetric locking of the P1 elements as ν → ½: a plane-strain cantilever.

    python studies/locking/cantilever.py

The strip [0, 10] × [0, 1] (E = 1000) is clamped on the left and loaded on
the right by a shear traction of total force P = 0.1; its tip deflection
(the mean u_y over the right side) is divided by Timoshenko's beam formula
in plane strain,

    δ = P L³ / (3 E' I) + P L / (κ G h),   E' = E/(1 − ν²), I = h³/12, κ = 5/6,

for ν from 0.3 to 0.4999 on 2, 4 and 8 cells through the thickness
(20 × 2, 40 × 4, 80 × 8). A ratio well below 1 that moves with the mesh is
locking. Writes cantilever.csv and cantilever.png beside this file; the
warning of adhesive_contact/problem/plausibility.py quotes the 4-cell
column. About 10 s.
"""

import csv
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from adhesive_contact import build_problem, scene_from_dict, solve  # noqa: E402

HERE = Path(__file__).parent
L, H, E, P = 10.0, 1.0, 1000.0, 0.1
NUS = (0.3, 0.4, 0.45, 0.49, 0.499, 0.4999)
MESHES = ((20, 2), (40, 4), (80, 8))


def beam(nu):
    """Timoshenko's tip deflection of the plane-strain cantilever."""
    shear = E / (2.0 * (1.0 + nu))
    return P * L**3 / (3.0 * E / (1.0 - nu**2) * H**3 / 12.0) + P * L / (5.0 / 6.0 * shear * H)


def tip_deflection(nu, cells):
    """The mean −u_y over the loaded side of the P1 solution."""
    scene = {"dim": 2, "mesh": {"domain": "rectangle", "size": [L, H], "cells": list(cells)},
             "boundary": {"dirichlet": ["left"], "contact": []},
             "material": {"E": E, "nu": nu},
             "loads": {"traction": {"right": ["0", f"{-P / H}"]}},
             "time": {"T": 1.0, "steps": 1}}
    solution = solve(build_problem(scene_from_dict(scene)))
    tip = np.isclose(solution.problem.mesh.p[0], L)
    return float(-solution.u[-1][tip, 1].mean())


def main():
    rows = [[nu] + [tip_deflection(nu, cells) / beam(nu) for cells in MESHES] for nu in NUS]
    header = ["nu"] + [f"{c[0]}x{c[1]}" for c in MESHES]
    with open(HERE / "cantilever.csv", "w", newline="") as f:
        writer = csv.writer(f, lineterminator="\n")
        writer.writerow(header)
        writer.writerows([[f"{v:.6g}" for v in row] for row in rows])
    print("  ".join(f"{h:>8}" for h in header))
    for row in rows:
        print("  ".join(f"{v:8.4g}" for v in row))
    fig, ax = plt.subplots(figsize=(6, 4), layout="constrained")
    for j, cells in enumerate(MESHES):
        ax.plot([1 - 2 * r[0] for r in rows], [r[j + 1] for r in rows], "o-",
                label=f"{cells[1]} cells through the thickness")
    ax.set_xscale("log")
    ax.invert_xaxis()
    ax.set_xlabel("1 − 2ν")
    ax.set_ylabel("tip deflection / beam formula")
    ax.set_title("P1 locking of a plane-strain cantilever")
    ax.axvline(1 - 2 * 0.45, color="0.5", ls=":", label="ν = 0.45 (the warning's bound)")
    ax.legend(loc="lower left")
    fig.savefig(HERE / "cantilever.png", dpi=120)


if __name__ == "__main__":
    main()
