"""3D Hertz contact, against the closed form.

    python studies/validation/hertz3d.py [--levels 0 1]

(the meshes are written by hertz3d_meshes.py on first use).

A rigid sphere of radius R = 1 (the foundation ``shape = "sphere"``)
pressed into an elastic block (E = 1000, ν = 0.3), frictionless Signorini
contact (``[contact.normal] law = "none"``), the quarter x ≥ 0, y ≥ 0 held
in x and y on its symmetry planes (hertz3d_sphere.toml). The approach
δ(t) = δ_1 t² is prescribed (four steps, a/R ≈ 0.025, 0.05, 0.075, 0.1);
at each level the computed total force P (four times the quarter's) gives
Hertz's radius and peak pressure,

    a = (3 P R / (4 E*))^{1/3},   p0 = 3 P / (2 π a²),   p(r) = p0 sqrt(1 − r²/a²),

E* = E / (1 − ν²) (one elastic body), against which the run is measured:
the radius from the pressure's moments, a_h² = (5/2) Σ_a F_a r_a² / Σ_a F_a
(∫ p r² = (2/5) a² P for Hertz's p; F_a the nodal forces), and the peak
pressure p_h(0) = F_0 / w_0 at the node on the axis (w_a = ∫_{Γ_C} φ_a).
Writes hertz3d.csv and hertz3d.png here; each run is saved in
hertz3d_runs/ as it finishes (a second call reads them back).
"""

import argparse
import time
import tomllib
from pathlib import Path

import numpy as np

from adhesive_contact import build_problem, scene_from_dict, solve
from adhesive_contact.postprocess import normal_traction
from adhesive_contact.storage import saved_or_computed, write_csv

HERE = Path(__file__).resolve().parent
LEVELS = (0, 1)
COMPARED = (1, 2, 3, 4)
R = 1.0
COLUMNS = ("mesh", "h_c", "dofs", "contact_nodes", "level", "t", "delta", "P", "a_over_R",
           "a_over_h", "a_hertz", "a_moment", "err_a", "p0_hertz", "p0", "err_p0",
           "a_bracket_lo", "a_bracket_hi", "seconds")


def scene(level, meshes=HERE / "meshes"):
    """The committed scene on mesh ``level``, read from the folder ``meshes``
    (made there by hertz3d_meshes.py when missing)."""
    import hertz3d_meshes
    path = Path(meshes) / f"sphere_{level}.msh"
    if not path.exists():
        hertz3d_meshes.main((level,), Path(meshes))
    data = tomllib.loads((HERE / "hertz3d_sphere.toml").read_text())
    data["mesh"]["file"] = str(path.resolve())
    return scene_from_dict(data, HERE)


def hertz(P, E_star):
    """(a, p0) of the 3D Hertz contact of a sphere of radius R under P."""
    a = (3.0 * P * R / (4.0 * E_star)) ** (1.0 / 3.0)
    return a, 3.0 * P / (2.0 * np.pi * a ** 2)


def measure(problem, solution, n):
    """The Hertz quantities of time level n of a run (a dict of COLUMNS)."""
    material = problem.scene.material
    E_star = material.E / (1.0 - material.nu ** 2)
    X = problem.mesh.p[:, problem.boundary.nodes]
    r2 = X[0] ** 2 + X[1] ** 2
    axis = int(np.argmin(r2))
    F = -solution.contact_force[n, :, 0]                   # compressive normal forces
    pressure = normal_traction(solution)[n]                # F_a / w_a, w_a = ∫ φ_a
    P = 4.0 * F.sum()                                      # the quarter model's four times
    a, p0 = hertz(P, E_star)
    a_moment = np.sqrt(2.5 * (F @ r2) / F.sum())
    on_x = np.flatnonzero(np.abs(X[1]) < 1e-12)           # the nodes along y = 0, by x
    on_x = on_x[np.argsort(X[0, on_x])]
    last = np.flatnonzero(solution.on_wall[n, on_x]).max()
    return {"t": float(solution.t[n]), "P": float(P), "a_over_R": float(a / R),
            "a_hertz": float(a), "a_moment": float(a_moment), "err_a": float(a_moment / a - 1),
            "p0_hertz": float(p0), "p0": float(pressure[axis]),
            "err_p0": float(pressure[axis] / p0 - 1),
            "a_bracket_lo": float(X[0, on_x[last]]), "a_bracket_hi": float(X[0, on_x[last + 1]])}


def run(level, folder):
    """The records of one mesh (computed, or read back from ``folder``)."""
    import hertz3d_meshes

    def compute():
        t0 = time.perf_counter()
        problem = build_problem(scene(level))
        solution = solve(problem, raise_on_failure=True)
        seconds = time.perf_counter() - t0
        h_c = hertz3d_meshes.LEVELS[level]
        records = []
        for n in COMPARED:
            r = measure(problem, solution, n)
            records.append({"mesh": level, "h_c": h_c, "dofs": int(problem.ndofs),
                            "contact_nodes": int(problem.boundary.nodes.size), "level": n,
                            "delta": 0.01 * r["t"] ** 2, **r,
                            "a_over_h": r["a_hertz"] / h_c, "seconds": seconds})
        return records

    return saved_or_computed(folder / f"sphere_{level}.json", compute)


def plot(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.4))
    for mesh, marker in zip(sorted({r["mesh"] for r in rows}), "os^"):
        sel = [r for r in rows if r["mesh"] == mesh]
        label = f"h_c = {sel[0]['h_c']:g} ({sel[0]['dofs']} dofs)"
        axes[0].plot([r["a_over_R"] for r in sel], [100 * r["err_a"] for r in sel], "-",
                     marker=marker, label=label)
        axes[1].plot([r["a_over_R"] for r in sel], [100 * r["err_p0"] for r in sel], "-",
                     marker=marker, label=label)
    for ax, what, goal in zip(axes, ("a_h / a − 1 (moment radius), %", "p_h(0) / p0 − 1, %"),
                              (1.0, 2.0)):
        ax.axhspan(-goal, goal, color="0.88", zorder=0)
        ax.axhline(0.0, color="k", lw=0.6)
        ax.set_xlabel("a / R")
        ax.set_title(what)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("3D Hertz, a rigid sphere into a block: error against the closed form "
                 "at the computed force\n(bands: the goals 1 % and 2 %)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--levels", type=int, nargs="+", default=list(LEVELS))
    parser.add_argument("--folder", type=Path, default=HERE)
    args = parser.parse_args(argv)
    rows = []
    for level in args.levels:
        for r in run(level, args.folder / "hertz3d_runs"):
            rows.append(r)
            print(f"mesh {level} (h_c = {r['h_c']:g}, {r['dofs']} dofs) a/R = "
                  f"{r['a_over_R']:.4f} (a/h_c = {r['a_over_h']:.1f}): a {100 * r['err_a']:+.3f} %, "
                  f"p0 {100 * r['err_p0']:+.3f} %, {r['seconds']:.1f} s")
    write_csv(args.folder / "hertz3d.csv", COLUMNS, [[r[c] for c in COLUMNS] for r in rows],
              digits=6)
    plot(rows, args.folder / "hertz3d.png")


if __name__ == "__main__":
    main()
