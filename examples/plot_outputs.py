"""Plot from a finished output folder of ``adhcontact solve``.

    python examples/plot_outputs.py [FOLDER]

FOLDER holds summary.json and solution.npz. Without it, the script first
runs ``adhcontact solve`` on a short copy of studies/scenes/debonding.toml
into a temporary folder. ``load_solution`` reads the folder back as the
Solution that ``solve`` returns (its problem rebuilt from the scene kept in
summary.json), so the library's post-processing works on it. It draws β
along the contact side at a few times and the total normal force over time
into beta_and_force.png, beside the outputs when FOLDER is given, else in
the temporary folder. (The files are plain too: ``numpy.load`` and
``json.load`` read them, docs/outputs.md.) The package's own figures of
the run are ``adhesive_contact.visuals`` (docs/python.md, "Figures"):
``visuals.figure_beta(solution)`` draws ``beta.png`` again from the folder.
"""

import subprocess
import sys
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from adhesive_contact import load_solution  # noqa: E402
from adhesive_contact.postprocess import beta_mean  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def solve_into(folder):
    """Run a short debonding scene with the command line into ``folder``."""
    text = (ROOT / "studies" / "scenes" / "debonding.toml").read_text()
    short = text.replace("steps = 50", "steps = 20").replace("cells = [80, 10]", "cells = [40, 5]")
    if short.count("\n") != text.count("\n") or short == text:
        raise RuntimeError("debonding.toml changed: update the replacements here")
    scene = folder / "debonding.toml"
    scene.write_text(short)
    command = [sys.executable, "-c", "from adhesive_contact_cli.main import main; main()",
               "solve", str(scene), "--out", str(folder / "run")]
    subprocess.run(command, check=True, capture_output=True)
    return folder / "run"


def plot(folder):
    solution = load_solution(folder)
    problem = solution.problem
    t, beta = solution.t, solution.beta                        # (M+1,), (M+1, nf)
    x = problem.mesh.p[0, problem.boundary.facet_nodes].mean(axis=0)   # facet midpoints
    order = np.argsort(x)
    force = solution.total_normal_force()                      # compression > 0

    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
    for n in np.linspace(0, t.size - 1, 5).astype(int):
        left.plot(x[order], beta[n, order], label=f"t = {t[n]:.2f}")
    left.set(xlabel="x on the contact side", ylabel="β", ylim=(-0.05, 1.05))
    left.legend()
    right.plot(t, force)
    right.set(xlabel="t", ylabel="total normal force (compression > 0)")
    status = "complete" if solution.success else solution.message
    fig.suptitle(f"{problem.scene.title} ({status})")
    path = folder / "beta_and_force.png"
    fig.savefig(path, dpi=80)
    plt.close(fig)
    print(f"{path}: {t.size} levels, β mean at T {beta_mean(solution)[-1]:.3f}")
    return path


if __name__ == "__main__":
    if len(sys.argv) > 1:
        plot(Path(sys.argv[1]))
    else:
        with tempfile.TemporaryDirectory() as tmp:
            plot(solve_into(Path(tmp)))
