"""Run a committed scene and read β and the contact forces over time.

    python examples/run_scene.py [STEPS]

Loads studies/scenes/debonding.toml (a glued strip peeled off its
foundation), runs it with STEPS time steps (default 20: the explicit Euler
bound of its bonding law needs at least 15 for T = 1) and prints, per
level, the mean and minimum of β, the total normal force of the foundation
on the body (positive in compression) and the number of separated contact
nodes. Writes nothing.
"""

import sys
from dataclasses import replace
from pathlib import Path

from adhesive_contact import build_problem, load_scene, solve
from adhesive_contact.postprocess import beta_mean, contact_state_counts, total_contact_force

ROOT = Path(__file__).resolve().parents[1]


def main(steps=20):
    scene = load_scene(ROOT / "studies" / "scenes" / "debonding.toml")
    scene = replace(scene, steps=steps)          # T stays 1: k = 1/steps
    solution = solve(build_problem(scene))
    if not solution.success:                     # the history before the failure is kept
        print(solution.message)

    mean = beta_mean(solution)                   # (M+1,), facet-measure weighted
    normal = solution.total_normal_force()       # (M+1,), compression > 0
    force = total_contact_force(solution)        # (M+1, d), global components
    states = contact_state_counts(solution)      # counts per level
    print(f"{'t':>5} {'beta mean':>9} {'beta min':>9} {'normal F':>9} {'F_x':>9} separated")
    for n, t in enumerate(solution.t):
        print(f"{t:5.2f} {mean[n]:9.4f} {solution.beta[n].min():9.4f} {normal[n]:9.3f} "
              f"{force[n, 0]:9.3f} {states['separated'][n]:9d}")
    return solution


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 20)
