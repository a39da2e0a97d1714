"""u_0 solves the t = 0 problem with the elastic stiffness alone (docs/scheme.md).

With memory the t = 0 Schur complement is applied, not formed, and the
Newton systems are solved by CG preconditioned with the Schur complement of
A + k R(0) (linear.ImplicitSchur). Without memory the same problem goes
through the formed, dense Schur complement: the two paths must agree.
"""

import numpy as np
import pytest
from conftest import law, prony, scene_dict

from adhesive_contact import build_problem, scene_from_dict, solve

# the strip of conftest.BLOCK pressed onto a wall, sheared, for 3 steps
CHANGES = {"loads.body": ["30*(1 + x)", "-400 - 100*x*(1 + t)"],
         "contact.gap": "0.01 + 0.05*(x - 1)**2",
         "contact.normal": law("compliance", c=5000.0), "time.steps": 3}
MEMORY = prony((300.0, 0.3, 0.2))


@pytest.mark.parametrize("friction", [None, law("tresca", mu=20.0)])
def test_initial_state_with_memory_equals_the_elastic_problem(friction):
    changes = {**CHANGES, "contact.friction": friction} if friction else CHANGES
    with_memory = solve(build_problem(scene_from_dict(scene_dict({**changes,
                                                                   "memory": MEMORY}))))
    without = solve(build_problem(scene_from_dict(scene_dict(changes))))
    u0, ref = with_memory.u[0], without.u[0]
    # the case exercises the wall and (with friction) both stick and slip
    assert with_memory.on_wall[0].any() and not with_memory.on_wall[0].all()
    if friction:
        assert with_memory.stuck[0].any() and not with_memory.stuck[0].all()
    assert np.abs(u0 - ref).max() <= 1e-10 * np.abs(ref).max()
    # and the memory does act afterwards
    assert np.abs(with_memory.u[-1] - without.u[-1]).max() > 1e-3 * np.abs(ref).max()
