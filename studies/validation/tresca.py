"""Tresca friction: the onset of sliding, against exact statics.

    python studies/validation/tresca.py

- ``tresca/block.toml``: a block 1 × 0.5 sheared by its top (u_x = 0.01 t,
  u_y = 0) on a flat with Tresca friction μ = 2 (a stress bound, no normal
  law): once every node of Γ_C slides, the shear force is the bound times
  the area, Q = μ |Γ_C| = 2, exactly (the nodal rule's weights sum to |Γ_C|).
- ``tresca/strip.toml``: a strip 10 × 0.5 (h = 0.5) on a flat without glue,
  Tresca μ = 1, its top on rollers (u_y = 0), pulled at its right end by
  F = 1 … 8 (load control: only the friction holds the slide). Where it
  slides the friction carries μ per unit length; the rest of F goes into
  the sticking part just ahead of the slip front over a shear-lag length
  of the order of h, so the slip zone is ℓ = F/μ − c h with c ≈ 0.6–0.75.
  The front lies between the last sticking and the first sliding node;
  ℓ is measured to its midpoint (± half a cell), on three meshes.

Writes ``tresca/block.csv``, ``tresca/strip.csv`` and ``tresca/tresca.png``;
each run's numbers are kept in ``tresca/runs/`` (not recomputed).
"""

import tomllib
from pathlib import Path

import numpy as np

from adhesive_contact.storage import saved_or_computed, write_csv

HERE = Path(__file__).resolve().parent / "tresca"
MU_BLOCK, MU_STRIP, LENGTH, THICKNESS = 2.0, 1.0, 10.0, 0.5
#: cells of the strip: 20, 40, 80 per unit length
STRIP_CELLS = ((200, 10), (400, 20), (800, 40))


def scene(name, cells=None):
    from adhesive_contact import scene_from_dict

    data = tomllib.loads((HERE / f"{name}.toml").read_text())
    if cells is not None:
        data["mesh"]["cells"] = list(cells)
    return scene_from_dict(data, base_dir=HERE)


def run_block():
    from adhesive_contact import build_problem, solve
    from adhesive_contact.postprocess import reaction_sides, reactions

    problem = build_problem(scene("block"))
    solution = solve(problem)
    if not solution.success:
        raise RuntimeError(solution.message)
    top = reaction_sides(problem).index("top")
    sliding = (~solution.stuck).sum(axis=1)
    return {"t": solution.t.tolist(), "shift": (0.01 * solution.t).tolist(),
            "Q": reactions(solution)[:, top, 0].tolist(), "sliding": sliding.tolist(),
            "nodes": int(problem.boundary.nodes.size),
            "area": float(problem.boundary.node_weights.sum())}


def slip_length(x, stuck):
    """The slip zone from the pulled end x = LENGTH to the midpoint between
    the last sticking and the first sliding node."""
    order = np.argsort(x)
    x, stuck = x[order], stuck[order]
    first = x[~stuck].min()
    last = x[stuck & (x < first)].max()
    return LENGTH - 0.5 * (first + last), first - last


def run_strip(cells):
    from adhesive_contact import build_problem, solve
    from adhesive_contact.postprocess import applied_traction

    problem = build_problem(scene("strip", cells))
    solution = solve(problem)
    if not solution.success:
        raise RuntimeError(solution.message)
    x = problem.mesh.p[0, problem.boundary.nodes]
    pull = applied_traction(problem, "right", solution.t)[:, 0]
    rows = []
    for n in range(1, solution.t.size):
        ell, spacing = slip_length(x, solution.stuck[n])
        rows.append({"F": float(pull[n]), "slip_length": ell, "cell": spacing})
    return {"cells": list(cells), "rows": rows}


def cached(name, compute, folder=HERE / "runs"):
    """The record ``name`` of ``folder``, computed only when no run saved it."""
    return saved_or_computed(folder / f"{name}.json", compute)


def main():
    import matplotlib.pyplot as plt

    block = cached("block", run_block)
    bound = MU_BLOCK * block["area"]
    write_csv(HERE / "block.csv", ["t", "shift", "Q", "Q_over_bound", "sliding_nodes"],
              [(t, s, q, q / bound, k) for t, s, q, k in
               zip(block["t"], block["shift"], block["Q"], block["sliding"])])
    strips = [cached(f"strip_{c[0]}x{c[1]}", lambda c=c: run_strip(c)) for c in STRIP_CELLS]
    rows = []
    for rec in strips:
        for r in rec["rows"]:
            offset = (r["F"] / MU_STRIP - r["slip_length"]) / THICKNESS
            rows.append((f"{rec['cells'][0]}x{rec['cells'][1]}", r["F"], r["slip_length"],
                         r["F"] / MU_STRIP, offset, r["cell"] / THICKNESS))
    write_csv(HERE / "strip.csv", ["cells", "F", "slip_length", "F_over_mu",
                                   "offset_over_h", "front_cell_over_h"], rows)

    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2))
    left.plot(block["shift"], np.array(block["Q"]) / bound, "o-")
    left.axhline(1.0, color="k", lw=1)
    left.set(xlabel="shift of the top", ylabel="Q / (μ |Γ_C|)",
             title="block sheared on a flat: the onset of sliding")
    for rec in strips:
        F = np.array([r["F"] for r in rec["rows"]])
        ell = np.array([r["slip_length"] for r in rec["rows"]])
        right.plot(F, (F / MU_STRIP - ell) / THICKNESS, "o-",
                   label=f"{rec['cells'][0]} × {rec['cells'][1]} cells")
    right.axhspan(0.6, 0.75, color="0.9", label="0.6–0.75 h")
    right.set(xlabel="pull F", ylabel="(F/μ − slip length) / h",
              title="strip pulled along a flat: shear-lag offset", ylim=(0.0, 1.2))
    right.legend(fontsize=8)
    fig.tight_layout()
    partial = HERE / "tresca.partial.png"
    fig.savefig(partial, dpi=110)
    plt.close(fig)
    partial.replace(HERE / "tresca.png")

    slid = [q for q, k in zip(block["Q"], block["sliding"]) if k == block["nodes"]]
    print(f"block: Q = {slid[0]:.12g} once all {block['nodes']} nodes slide "
          f"(μ |Γ_C| = {bound:g}; largest deviation {max(abs(q - bound) for q in slid):.1e})")
    for row in rows:
        print(f"strip {row[0]}: F = {row[1]:g}: slip length {row[2]:.4f}, F/μ − ℓ = "
              f"{row[4]:.3f} h (± {row[5] / 2:.3f} h)")


if __name__ == "__main__":
    main()
