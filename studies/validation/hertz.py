"""2D Hertz contact in plane strain, against the closed form.

    python studies/validation/hertz.py [--levels 0 1 2 3]

(the meshes beyond level 0 are written by hertz_meshes.py on first use).

Two geometries, frictionless Signorini contact (``[contact.normal] law =
"none"`` with ``[contact.foundation]``), half models with the symmetry
axis x = 0 held in x:

- ``disc`` (hertz_disc.toml): an elastic half-disc of radius R = 1 pressed
  by its flat top onto a rigid plane;
- ``block`` (hertz_block.toml): a rigid cylinder of radius R = 1 (the
  foundation ``shape = "sphere"``) pressed into an elastic block 4 × 4.

The indentation is driven by a prescribed approach δ(t) = δ_1 t³ (eight
steps); the levels t = 2/8, 3/8, 5/8, 1 (a/R ≈ 0.01, 0.02, 0.05, 0.1) are
compared. At each the computed total force P (twice the half model's)
gives Hertz's half-width and peak pressure,

    a = sqrt(4 P R / (π E*)),   p0 = 2 P / (π a),   p(x) = p0 sqrt(1 − x²/a²),

E* = E / (1 − ν²) (one elastic body, plane strain), against which the run
is measured: the half-width from the pressure's moments,
a_h² = 4 Σ_a F_a x_a² / Σ_a F_a (∫ p x² = P a²/4 for Hertz's p; F_a the
nodal forces), the peak pressure p_h(0) at the node x = 0, and the
pressure profile's relative L² error on Γ_C, ‖p_h − p‖/‖p‖ with p_h the
P1 function of the nodal pressures F_a / w_a (w_a = ∫ φ_a dx along the
flat), beside the floor ‖I_h p − p‖/‖p‖ of the P1 interpolant of the
exact p on the same nodes. Writes hertz.csv and hertz.png here; each run
is saved in hertz_runs/ as it finishes (a second call reads them back).
"""

import argparse
import json
import time
import tomllib
from pathlib import Path

import numpy as np

from adhesive_contact import build_problem, scene_from_dict, solve
from adhesive_contact.storage import write_csv

HERE = Path(__file__).resolve().parent
GEOMETRIES = ("disc", "block")
LEVELS = (0, 1, 2, 3)
H_C = {0: 0.005, 1: 0.0025, 2: 0.00125, 3: 0.000625}
COMPARED = (2, 3, 5, 8)       # the time levels compared: a/R ≈ 0.01, 0.02, 0.05, 0.1
STEPS = 8
R = 1.0
COLUMNS = ("geometry", "mesh", "h_c", "dofs", "contact_nodes", "level", "t", "delta", "P", "a_over_R",
           "a_hertz", "a_moment", "err_a", "p0_hertz", "p0", "err_p0", "err_profile",
           "floor_profile", "a_bracket_lo", "a_bracket_hi", "seconds")


def scene(geometry, level):
    """The committed scene of a geometry on mesh ``level`` (the meshes finer
    than level 0 are made by hertz_meshes.py when missing)."""
    if not (HERE / "meshes" / f"{geometry}_{level}.msh").exists():
        import hertz_meshes
        hertz_meshes.main()
    data = tomllib.loads((HERE / f"hertz_{geometry}.toml").read_text())
    data["mesh"]["file"] = f"meshes/{geometry}_{level}.msh"
    return scene_from_dict(data, HERE)


def hertz(P, E_star):
    """(a, p0) of the 2D Hertz contact of a cylinder of radius R under the
    force P per unit length."""
    a = np.sqrt(4.0 * P * R / (np.pi * E_star))
    return a, 2.0 * P / (np.pi * a)


def profile_errors(x, p_nodes, a, p0, samples=400):
    """‖p_h − p‖/‖p‖ and ‖I_h p − p‖/‖p‖ on [0, x_max] (L², sampled at
    ``samples`` midpoints per element), for the nodes x (sorted) with nodal
    pressures p_nodes, p the Hertz pressure."""
    def exact(s):
        return p0 * np.sqrt(np.clip(1.0 - (s / a) ** 2, 0.0, None))

    u = (np.arange(samples) + 0.5) / samples
    left, right = x[:-1, None], x[1:, None]
    s = left + (right - left) * u                           # (elements, samples)
    ds = (right - left) / samples
    p_h = p_nodes[:-1, None] * (1 - u) + p_nodes[1:, None] * u
    interp = exact(x[:-1])[:, None] * (1 - u) + exact(x[1:])[:, None] * u
    norm = np.sqrt(np.sum(exact(s) ** 2 * ds))
    return (np.sqrt(np.sum((p_h - exact(s)) ** 2 * ds)) / norm,
            np.sqrt(np.sum((interp - exact(s)) ** 2 * ds)) / norm)


def measure(problem, solution, n):
    """The Hertz quantities of time level n of a run (a dict of COLUMNS)."""
    material = problem.scene.material
    E, nu = material.E, material.nu
    E_star = E / (1.0 - nu ** 2)
    boundary = problem.boundary
    x = problem.mesh.p[0, boundary.nodes]
    order = np.argsort(x)
    x = x[order]
    F = -solution.contact_force[n, order, 0]              # compressive normal forces
    # w_a = ∫ φ_a dx along the flat (the foundation's tangent for the disc)
    facet_x = problem.mesh.p[0, boundary.facet_nodes]
    lengths = np.abs(facet_x[1] - facet_x[0])
    local = np.searchsorted(boundary.nodes, boundary.facet_nodes)
    w = np.zeros(boundary.nodes.size)
    for v in range(2):
        np.add.at(w, local[v], lengths / 2)
    w = w[order]
    P = 2.0 * F.sum()                                     # the half model's twice
    a, p0 = hertz(P, E_star)
    a_moment = np.sqrt(4.0 * F @ x ** 2 / F.sum())
    pressure = F / w
    err, floor = profile_errors(x, pressure, a, p0)
    wall = solution.on_wall[n, order]
    last = np.flatnonzero(wall).max()
    return {"t": float(solution.t[n]), "P": float(P), "a_over_R": float(a / R),
            "a_hertz": float(a), "a_moment": float(a_moment), "err_a": float(a_moment / a - 1),
            "p0_hertz": float(p0), "p0": float(pressure[0]), "err_p0": float(pressure[0] / p0 - 1),
            "err_profile": float(err), "floor_profile": float(floor),
            "a_bracket_lo": float(x[last]), "a_bracket_hi": float(x[last + 1])}


def run(geometry, level, folder):
    """The records of one mesh (computed, or read back from ``folder``)."""
    path = folder / f"{geometry}_{level}.json"
    if path.exists():
        return json.loads(path.read_text())
    t0 = time.perf_counter()
    problem = build_problem(scene(geometry, level))
    solution = solve(problem, raise_on_failure=True)
    seconds = time.perf_counter() - t0
    delta = {"disc": 0.02, "block": 0.028}[geometry]
    records = [{"geometry": geometry, "mesh": level, "h_c": H_C[level],
                "dofs": int(problem.ndofs), "contact_nodes": int(problem.boundary.nodes.size),
                "level": n, "delta": delta * float(solution.t[n]) ** 3,
                **measure(problem, solution, n),
                "seconds": seconds} for n in COMPARED]
    folder.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".tmp")
    tmp.write_text(json.dumps(records, indent=1))
    tmp.replace(path)
    return records


def plot(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 4, figsize=(20, 4.6))
    styles = dict(zip(COMPARED, (":", "-.", "--", "-")))
    finest = max(r["mesh"] for r in rows)
    for geometry, marker in zip(GEOMETRIES, "os"):
        for n in COMPARED:
            sel = [r for r in rows if r["geometry"] == geometry and r["level"] == n]
            if not sel:
                continue
            h = [r["h_c"] for r in sel]
            label = f"{geometry}, a/R = {sel[-1]['a_over_R']:.3f}"
            style = styles[n]
            axes[0].loglog(h, [abs(r["err_a"]) for r in sel], style, marker=marker, label=label)
            axes[1].loglog(h, [abs(r["err_p0"]) for r in sel], style, marker=marker, label=label)
            axes[2].loglog(h, [r["err_profile"] for r in sel], style, marker=marker,
                           label=f"{label}: computed")
            axes[2].loglog(h, [r["floor_profile"] for r in sel], ":", marker=marker, lw=0.7,
                           color=axes[2].lines[-1].get_color())
        sel = [r for r in rows if r["geometry"] == geometry and r["mesh"] == finest]
        aR = [r["a_over_R"] for r in sel]
        axes[3].plot(aR, [100 * r["err_a"] for r in sel], "-", marker=marker,
                     label=f"{geometry}: a")
        axes[3].plot(aR, [100 * r["err_p0"] for r in sel], "--", marker=marker,
                     label=f"{geometry}: p0")
    for ax, what in zip(axes, ("|a_h / a − 1| (moment half-width)", "|p_h(0) / p0 − 1|",
                               "‖p_h − p‖ / ‖p‖ on Γ_C (dotted: P1 floor)")):
        ax.set_xlabel("element size at the contact h_c")
        ax.set_title(what)
        ax.grid(True, which="both", alpha=0.3)
    axes[0].axhline(3e-3, color="k", lw=0.8)
    axes[1].axhline(5e-3, color="k", lw=0.8)
    axes[0].legend(fontsize=6)
    axes[2].legend(fontsize=5)
    axes[3].axhspan(-0.3, 0.3, color="0.85", zorder=0)
    axes[3].axhline(0.0, color="k", lw=0.6)
    axes[3].set_xlabel("a / R")
    axes[3].set_ylabel("error on the finest mesh, %")
    axes[3].set_title("the departure from Hertz against a/R (band: 0.3 %)")
    axes[3].grid(True, alpha=0.3)
    axes[3].legend(fontsize=7)
    fig.suptitle("2D Hertz (plane strain, frictionless Signorini), error against the closed "
                 "form at the computed force P; lines: the goals 0.3 % and 0.5 %")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--levels", type=int, nargs="+", default=list(LEVELS))
    parser.add_argument("--folder", type=Path, default=HERE)
    args = parser.parse_args(argv)
    rows = []
    for geometry in GEOMETRIES:
        for level in args.levels:
            for r in run(geometry, level, args.folder / "hertz_runs"):
                rows.append(r)
                print(f"{geometry:5s} mesh {level} (h_c = {r['h_c']:g}, {r['dofs']} dofs) "
                      f"a/R = {r['a_over_R']:.4f}: a {100 * r['err_a']:+.3f} %, "
                      f"p0 {100 * r['err_p0']:+.3f} %, profile {100 * r['err_profile']:.2f} % "
                      f"(P1 floor {100 * r['floor_profile']:.2f} %), {r['seconds']:.1f} s")
    write_csv(args.folder / "hertz.csv", COLUMNS, [[r[c] for c in COLUMNS] for r in rows],
              digits=6)
    plot(rows, args.folder / "hertz.png")


if __name__ == "__main__":
    main()
