"""A symmetry side of the built-in "diagonal" pattern under a curved foundation.

    python studies/validation/symmetry_side.py [--quick]

A rigid cylinder or sphere (``[contact.foundation] shape = "sphere"`` or
``"cylinder"``, radius R) is pressed into the top of an elastic block on the
built-in rectangle or box, frictionless Signorini contact (``[contact.normal]
law = "none"``), the bottom lifted by δ(t). Each geometry is run as the whole
body (the foundation's centre above the middle node of the top) and as a half
or quarter model whose symmetry sides (held along their normal only) pass
through the foundation's closest point, on the "diagonal" pattern and, in 2D,
on "cross". The nodal pressure p_a = −F_{a,ν}/w_a is compared with Hertz's at
the computed total force P (twice or four times the model's):

- 2D (plane strain) and the cylinder (per unit length, front/back held in z):
  a = √(4PR/(πE*)), p0 = 2P/(πa), p(r) = p0 √(1 − r²/a²);
- the sphere: a = (3PR/(4E*))^(1/3), p0 = 3P/(2πa²), the same p(r);

E* = E/(1 − ν²), r the distance from the foundation's axis along the top.
Reported per time level: a/h (the contact half-width over the node spacing
at the top) and the largest error, by sign kept, of the node(s) at r = 0
(a cylinder's line of them), of the other nodes with r < a/2 on the planes
through the axis that a half or quarter model holds (the same planes in the
whole body; only the sphere in 3D has such nodes) and of those off them.
The cylinder's nodes on the front/back sides are left out: the pressure
does not vary across them, and they read within 1 % of those mid-length.
Writes symmetry_side.csv here (about two minutes; ``--quick``: the 2D
cases only, half a minute).

What it shows (docs/conventions.md#a-symmetry-side-of-the-diagonal-pattern):
the half model of a "diagonal" mesh is the whole body on the mesh mirrored at
the symmetry side, whose cells meet there in a chevron; its node on the axis
reads several per cent off while its neighbours read as the whole body's.
"cross" cells are mirror-symmetric about every grid line, so its half model
is its whole body.
"""

import argparse
import time
from pathlib import Path

import numpy as np

from adhesive_contact import build_problem, contact_traction, scene_from_dict, solve
from adhesive_contact.storage import write_csv

HERE = Path(__file__).resolve().parent
E, NU = 1000.0, 0.3
E_STAR = E / (1.0 - NU ** 2)
COLUMNS = ("case", "dim", "foundation", "pattern", "model", "refine", "dofs", "level", "t",
           "a_over_h", "err_axis", "err_on_sides", "err_off_sides", "seconds")

#: (name, dim, foundation, pattern, model, size, cells, refine, R, approach, steps, levels)
CASES_2D = [
    (f"disc {pattern} {model} r{refine}", 2, "sphere", pattern, model,
     (2.0, 1.0) if model == "whole" else (1.0, 1.0),
     (80, 40) if model == "whole" else (40, 40), refine, 1.0, "0.028*t**3", 8, range(3, 9))
    for refine in (1, 2)
    for pattern, model in (("diagonal", "whole"), ("diagonal", "left"), ("diagonal", "right"),
                           ("cross", "left"))]
CASES_3D = [
    ("cylinder diagonal whole r0", 3, "cylinder", "diagonal", "whole", (2.0, 1.0, 0.25),
     (80, 40, 10), 0, 1.0, "0.028*t**3", 4, range(2, 5)),
    ("cylinder diagonal left r0", 3, "cylinder", "diagonal", "left", (1.0, 1.0, 0.25),
     (40, 40, 10), 0, 1.0, "0.028*t**3", 4, range(2, 5)),
    ("sphere diagonal whole r0", 3, "sphere", "diagonal", "whole", (2.0, 1.0, 2.0),
     (48, 12, 48), 0, 5.0, "0.01*t**2", 4, range(2, 5)),
    ("sphere diagonal quarter r0", 3, "sphere", "diagonal", "quarter", (1.0, 1.0, 1.0),
     (24, 12, 24), 0, 5.0, "0.01*t**2", 4, range(2, 5)),
]

#: the sides held along their normal only, by model and dimension
SYMMETRY = {"whole": (), "left": ("left",), "right": ("right",), "quarter": ("left", "front")}


def axis_point(model, size):
    """(x, z) of the foundation's axis on the top: the middle of the whole
    body, the held side of a half model, the corner of a quarter model."""
    x = {"whole": size[0] / 2, "left": 0.0, "right": size[0], "quarter": 0.0}[model]
    z = 0.0 if len(size) == 2 or model == "quarter" else size[2] / 2
    return x, z


def scene_dict(dim, foundation, pattern, model, size, cells, refine, R, approach, steps):
    """The scene of a case: the bottom lifted by ``approach`` (held in x and
    z), the foundation above the top at the axis point, touching it."""
    x, z = axis_point(model, size)
    zero = ["0"] * dim
    lifted = list(zero)
    lifted[1] = approach
    held = {"bottom": lifted}
    normal_only = {"left": 0, "right": 0, "front": 2, "back": 2}
    sides = SYMMETRY[model] + (("front", "back") if foundation == "cylinder" else ())
    for side in sides:
        rollers = ["free"] * dim
        rollers[normal_only[side]] = "0"
        held[side] = rollers
    centre = [x, size[1] + R] + ([z] if dim == 3 else [])
    shape = {"shape": foundation, "point": centre, "radius": R}
    if foundation == "cylinder":
        shape["axis"] = [0.0, 0.0, 1.0]
    mesh = {"domain": "rectangle" if dim == 2 else "box", "size": list(size),
            "cells": list(cells), "refine": refine}
    if dim == 2:
        mesh["pattern"] = pattern
    return {"title": f"{foundation} pressed into a block ({model})", "dim": dim, "mesh": mesh,
            "boundary": {"contact": ["top"], "displacement": held},
            "material": {"E": E, "nu": NU},
            "contact": {"foundation": shape, "normal": {"law": "none"}},
            "time": {"T": 1.0, "steps": steps}}


def measure(problem, solution, case, n):
    """The errors of time level n of a run against Hertz's pressure."""
    _, dim, foundation, _, model, size, *_rest = case
    R = case[8]
    x, z = axis_point(model, size)
    points = problem.mesh.p[:, problem.boundary.nodes]
    if foundation == "sphere" and dim == 3:
        r = np.hypot(points[0] - x, points[2] - z)
    else:
        r = np.abs(points[0] - x)
    inside = np.ones(r.size, dtype=bool)
    if foundation == "cylinder":   # front/back are symmetry sides too: left out
        inside = (points[2] > 1e-9) & (points[2] < size[2] - 1e-9)
    force = -contact_traction(solution, "global")[n, :, 1] * problem.boundary.node_weights
    P = force.sum() * {"whole": 1, "left": 2, "right": 2, "quarter": 4}[model]
    if foundation == "cylinder":
        P /= size[2]
    if dim == 2 or foundation == "cylinder":
        a = np.sqrt(4.0 * P * R / (np.pi * E_STAR))
        p0 = 2.0 * P / (np.pi * a)
    else:
        a = (3.0 * P * R / (4.0 * E_STAR)) ** (1.0 / 3.0)
        p0 = 3.0 * P / (2.0 * np.pi * a * a)
    hertz = p0 * np.sqrt(np.clip(1.0 - (r / a) ** 2, 0.0, None))
    pressure = -contact_traction(solution)[n, :, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        err = np.where(hertz > 0, pressure / hertz - 1.0, np.nan)
    spacing = np.unique(np.round(r[inside], 12))
    h = spacing[1]
    near = inside & (r < 0.5 * a)
    axis = inside & (r < 1e-9)
    # the nodes on the planes through the axis that a half or quarter model
    # holds (the same lines in the whole body, for comparison)
    on_planes = np.abs(points[0] - x) < 1e-9
    if foundation == "sphere" and dim == 3:
        on_planes |= np.abs(points[2] - z) < 1e-9
    on_sides = near & on_planes & ~axis
    off_sides = near & ~on_planes
    def worst(mask):
        e = err[mask]
        e = e[np.isfinite(e)]
        return float(e[np.argmax(np.abs(e))]) if e.size else float("nan")

    return {"t": float(solution.t[n]), "a_over_h": float(a / h), "err_axis": worst(axis),
            "err_on_sides": worst(on_sides), "err_off_sides": worst(off_sides)}


def run(case):
    """The records of one case, one per compared time level."""
    name, dim, foundation, pattern, model, size, cells, refine, R, approach, steps, levels = case
    t0 = time.perf_counter()
    problem = build_problem(scene_from_dict(scene_dict(dim, foundation, pattern, model, size,
                                                       cells, refine, R, approach, steps)))
    solution = solve(problem, raise_on_failure=True)
    seconds = time.perf_counter() - t0
    return [{"case": name, "dim": dim, "foundation": foundation, "pattern": pattern,
             "model": model, "refine": refine, "dofs": int(problem.ndofs), "level": n,
             **measure(problem, solution, case, n), "seconds": seconds} for n in levels]


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="the 2D cases only")
    parser.add_argument("--out", type=Path, default=HERE / "symmetry_side.csv")
    args = parser.parse_args(argv)
    rows = []
    for case in CASES_2D + ([] if args.quick else CASES_3D):
        for r in run(case):
            rows.append(r)
            print(f"{r['case']:28s} t = {r['t']:.3f} a/h = {r['a_over_h']:5.1f}: axis "
                  f"{100 * r['err_axis']:+6.2f} %, on the planes {100 * r['err_on_sides']:+6.2f} %, "
                  f"off them {100 * r['err_off_sides']:+6.2f} %")
    write_csv(args.out, COLUMNS, [[r[c] for c in COLUMNS] for r in rows], digits=6)


if __name__ == "__main__":
    main()
