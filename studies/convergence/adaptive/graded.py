"""Graded grids chosen by hand against the reference: how few steps can
any grid of the paper's scheme take on the held strip (``run.py --held``)
for a given error?

    python studies/convergence/adaptive/graded.py     # after run.py --held --reference 8192

Each grid is a step size per stretch of [0, T] (the quantised steps
k_max 2^−j of [time.adaptive], so the runs share its loop): the
controller is replaced by one that accepts every pair and takes the
stretch's step. The stretches and sizes were picked by measuring, on the
grid "tuned", how much E falls per step added in each stretch (halving its
step) and moving steps to where that is largest (studies/README.md): it is
largest in the slow softening before the burst, then in the burst, and
nil after it. E is that of run.py; "N same E" the uniform step count with
the same E (log-log interpolation of run.py's uniform curve). Writes
``results/held/graded.csv``.
"""

import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import run as study  # noqa: E402

from adhesive_contact.problem.build import build_problem  # noqa: E402
from adhesive_contact.scheme import adaptive_loop, solve  # noqa: E402
from adhesive_contact.scheme.adaptive import Controller  # noqa: E402
from adhesive_contact.storage import saved_or_computed, write_csv  # noqa: E402

EDGES = (0.0, 0.3, 0.6, 0.75, 0.9, 1.0, 1.1, 1.35)   # the stretches' starts; T = 2
GRIDS = {   # the step in each stretch
    "uniform": (1 / 256,) * 8,
    "coarse after the burst": (1 / 256,) * 7 + (1 / 32,),
    "tuned": (1 / 128, 1 / 256, 1 / 512, 1 / 512, 1 / 512, 1 / 512, 1 / 256, 1 / 32),
    "tuned, coarser": (1 / 64, 1 / 128, 1 / 512, 1 / 512, 1 / 512, 1 / 512, 1 / 128, 1 / 32),
    "tuned, finer": (1 / 64, 1 / 256, 1 / 1024, 1 / 1024, 1 / 1024, 1 / 1024, 1 / 256, 1 / 32),
}


def scheduled(steps):
    """A Controller that accepts every pair and takes the step of the
    stretch the next pair starts in."""
    class Scheduled(Controller):
        def judge(self, err, j, at, change=0.0, memory=0.0):
            self.accepted += 1
            after = at + 2 * self.sizes.span(j)
            t = after * self.sizes.size(self.sizes.halvings)
            stretch = int(np.searchsorted(EDGES, t, side="right")) - 1
            return True, self.sizes.index(steps[min(stretch, len(steps) - 1)], after)
    return Scheduled


def main():
    study.held, study.RESULTS = True, study.RESULTS / "held"
    ref = study.reference(8192)
    problem = build_problem(study.scene())
    M = study.mass_matrix(problem.mesh)
    measure = np.asarray(problem.boundary.measure, dtype=float)
    uniform = [study.run(f"uniform_{N}", study.scene(N), ref, M, measure)
               for N in study.STEPS]
    rows = []
    for name, steps in GRIDS.items():
        def compute(steps=steps):
            original = adaptive_loop.Controller
            adaptive_loop.Controller = scheduled(steps)
            try:
                solution = solve(build_problem(study.scene(tol=1.0)), raise_on_failure=True)
            finally:
                adaptive_loop.Controller = original
            E, e_u, e_b = study.error(solution, ref, M, measure)
            return {"steps": int(solution.steps), "E": E}
        slug = name.replace(" ", "_").replace(",", "")
        record = saved_or_computed(study.RESULTS / "runs" / f"graded_{slug}.json", compute)
        same = study.uniform_steps_for(record["E"], uniform)
        rows.append((name, record["steps"], record["E"], same, record["steps"] / same))
    write_csv(study.RESULTS / "graded.csv", ("grid", "steps", "E", "uniform_steps_same_E",
                                             "ratio"), rows)
    print(f"{'grid':>24} {'steps':>6} {'E':>8} {'N same E':>9} {'ratio':>6}")
    for name, steps, E, same, ratio in rows:
        print(f"{name:>24} {steps:6d} {E:8.4f} {same:9.0f} {ratio:6.2f}")


if __name__ == "__main__":
    main()
