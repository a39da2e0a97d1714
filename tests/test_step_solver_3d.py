"""The step solve in 3D, where a slipping node has two tangential
components: a glued block with memory, adhesive compliance, slip weakening
and an adhesive spring, Frémond bonding and a wall, pulled and lifted at
its free end (the scene of the 3D stall: with the slip direction of a node
leaving the kink not held, step 16 cycled between two iterates until the
iteration limit)."""

import numpy as np
from conftest import glued_contact, prony, scene_dict

from adhesive_contact import build_problem, scene_from_dict, solve
from adhesive_contact.postprocess import contact_state_counts

BLOCK_3D = scene_dict({
    "dim": 3,
    "mesh": {"domain": "box", "size": [4.0, 1.0, 2.0], "cells": [24, 12, 6]},
    "boundary": {"dirichlet": ["left"], "contact": ["bottom"]},
    "memory": prony((200.0, 0.3, 0.5)),
    "loads": {"traction": {"right": ["7*t", "14*t", "0"]}},
    "contact": glued_contact(),
    "time": {"T": 1.0, "steps": 20},
})


def test_glued_block_in_3d_converges_every_step():
    problem = build_problem(scene_from_dict(BLOCK_3D))
    assert problem.ndofs == 6825 and problem.dim == 3
    sol = solve(problem)
    assert sol.success, sol.message
    assert np.all(sol.residual <= problem.scene.solver.tol)
    # the run does what the scene is for: the glue lets go near the pulled end
    # while stick and slip coexist on Γ_C
    assert sol.beta[-1].min() < 0.5 < sol.beta[-1].max()
    states = contact_state_counts(sol)
    assert states["stick"].max() > 0 and states["slip"].max() > 0
