"""The bulk operators by the two paths: the vectorised P1 kernels
(``fem/p1.py``, every scene's path) against scikit-fem's assembly of the
forms of ``fem/forms.py`` (the reference path), on the unit square (2D,
224 × 224 cells, 1.01e5 dofs) and cube (3D, 32³ cells, 1.08e5 dofs).

    python studies/bench/forms_vs_kernels.py [--dims 2,3] [--repeat 3]   # about 1 min

For each path it measures (the median of ``--repeat`` runs, the paths
alternating):

- ``assembly_s``: ``Assembly(mesh, path=...)``, what ``build_problem``
  assembles once per mesh (K_λ, K_μ and the strain map);
- ``stiffness_s``: one λ K_λ + μ K_μ (the step matrices' combination);
- ``load_setup_s``: the ``LoadMap`` of a body force varying in space and a
  traction on one side; ``load_step_s``: one evaluation of it after the
  first (which makes the kernels' quadrature points, as ``build_problem``'s
  check of the loads does), what every step pays;

and, once, the largest difference of K_λ, K_μ, the strain map and the
load between the paths over the largest entry (round-off). Prints one row
per dimension and path, and writes ``forms_vs_kernels.csv`` and
``forms_vs_kernels.json`` (with the machine) beside this script.
"""

import argparse
import csv
import statistics
import time
from pathlib import Path

import numpy as np

from machine import describe  # studies/bench/machine.py, beside this script

HERE = Path(__file__).resolve().parent
CELLS = {2: 224, 3: 32}            # per side: 1.01e5 and 1.08e5 dofs
PATHS = ("kernels", "forms")
E, NU = 1000.0, 0.3
LAM, MU = E * NU / ((1 + NU) * (1 - 2 * NU)), E / (2 * (1 + NU))
BODY = ["x*y - t", "sin(3*x) + y", "x*z"]
TRACTION = ["x*t", "1 + y", "y*z"]
FIELDS = ("dim", "cells", "dofs", "path", "assembly_s", "stiffness_s", "load_setup_s",
          "load_step_s", "assembly_ratio", "load_step_ratio")


def mesh_of(dim):
    from skfem import MeshTet, MeshTri

    from adhesive_contact.fem.meshes import side_tests

    axes = [np.linspace(0.0, 1.0, CELLS[dim] + 1)] * dim
    return (MeshTri if dim == 2 else MeshTet).init_tensor(*axes).with_boundaries(
        side_tests([1.0] * dim))


def timed(make):
    t0 = time.perf_counter()
    out = make()
    return time.perf_counter() - t0, out


def once(mesh, path):
    """(seconds per measured part, the assembly, the load at t = 0.5)."""
    from adhesive_contact.expressions import compile_expression
    from adhesive_contact.fem.assembly import Assembly, LoadMap, vector_of

    d = mesh.dim()
    body = vector_of([compile_expression(e) for e in BODY[:d]])
    traction = vector_of([compile_expression(e) for e in TRACTION[:d]])
    assembly_s, assembly = timed(lambda: Assembly(mesh, path=path))
    stiffness_s, _ = timed(lambda: assembly.stiffness(LAM, MU))
    load_setup_s, loads = timed(lambda: LoadMap(mesh, body, [(mesh.boundaries["right"],
                                                               traction)], assembly=assembly))
    loads(0.25)   # made on first use: the kernels' quadrature points (build_problem's check)
    load_step_s, load = timed(lambda: loads(0.5))
    return ({"assembly_s": assembly_s, "stiffness_s": stiffness_s,
             "load_setup_s": load_setup_s, "load_step_s": load_step_s}, assembly, load)


def relative(a, b):
    difference = a - b
    difference = abs(difference).max() if hasattr(difference, "tocsr") else np.abs(difference).max()
    scale = abs(b).max() if hasattr(b, "tocsr") else np.abs(b).max()
    return float(difference / scale)


def measure(dim, repeat):
    mesh = mesh_of(dim)
    runs = {path: [] for path in PATHS}
    made = {}
    for _ in range(repeat):
        for path in PATHS:
            seconds, assembly, load = once(mesh, path)
            runs[path].append(seconds)
            made[path] = (assembly, load)
    (k, load_k), (f, load_f) = made["kernels"], made["forms"]
    agreement = {"K_lam": relative(k.K_lam.tocsr(), f.K_lam),
                 "K_mu": relative(k.K_mu.tocsr(), f.K_mu),
                 "strain": relative(k.strain, f.strain), "load": relative(load_k, load_f)}
    rows = []
    for path in PATHS:
        row = {"dim": dim, "cells": int(mesh.t.shape[1]), "dofs": int(k.ndofs), "path": path}
        row.update({key: statistics.median(r[key] for r in runs[path]) for key in runs[path][0]})
        rows.append(row)
    for row in rows:
        row["assembly_ratio"] = row["assembly_s"] / rows[0]["assembly_s"]
        row["load_step_ratio"] = row["load_step_s"] / rows[0]["load_step_s"]
    return rows, agreement


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--dims", default="2,3")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--out", default=str(HERE), help="folder of the CSV and JSON")
    args = parser.parse_args()
    rows, agreements = [], {}
    for dim in (int(d) for d in args.dims.split(",")):
        dim_rows, agreement = measure(dim, args.repeat)
        rows += dim_rows
        agreements[f"{dim}D"] = agreement
        for row in dim_rows:
            print(f"{dim}D, {row['dofs']} dofs, {row['path']:7s}: assembly "
                  f"{row['assembly_s']:.3f} s (x{row['assembly_ratio']:.1f}), stiffness "
                  f"{row['stiffness_s']:.3f} s, load map {row['load_setup_s']:.3f} s, a step's "
                  f"load {row['load_step_s']:.3f} s (x{row['load_step_ratio']:.1f})", flush=True)
        print(f"{dim}D, forms against kernels (largest difference over largest entry): "
              + ", ".join(f"{key} {value:.1e}" for key, value in agreement.items()), flush=True)

    from adhesive_contact.storage import write_atomic, write_json

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    write_json(out / "forms_vs_kernels.json", {"machine": describe(), "repeat": args.repeat,
                                               "rows": rows, "agreement": agreements})

    def table(f):
        writer = csv.DictWriter(f, fieldnames=FIELDS, lineterminator="\n")
        writer.writeheader()
        for row in rows:
            writer.writerow({k: (round(v, 4) if isinstance(v, float) else v)
                             for k, v in row.items()})
    write_atomic(out / "forms_vs_kernels.csv", table)


if __name__ == "__main__":
    main()
