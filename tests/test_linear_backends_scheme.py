"""Every linear backend gives the scheme the same solution: the full model
(memory, adhesion, slip weakening, bonding, wall) in 2D and 3D run with
SuperLU, PARDISO (where installed) and AMG-CG. Direct backends agree to
round-off amplified by the Newton iterations (1e-9 relative); AMG solves
each column of the Schur complement to a relative residual of 1e-10, and
its solutions agree to 1e-7."""

from dataclasses import replace

import numpy as np
import pytest
from conftest import glued_contact, prony, scene_dict

from adhesive_contact import build_problem, scene_from_dict, solve
from adhesive_contact.linear_solvers import pardiso

GLUED = {
    "memory": prony((200.0, 0.3, 0.5)),
    "contact": glued_contact(),
    "boundary": {"dirichlet": ["left"], "contact": ["bottom"]},
    "time": {"T": 1.0, "steps": 20},
}
SCENES = {
    2: scene_dict({**GLUED, "mesh": {"domain": "rectangle", "size": [4.0, 0.5],
                                     "cells": [40, 5]},
                   "loads": {"traction": {"right": ["7*t", "14*t"]}}}),
    3: scene_dict({**GLUED, "dim": 3, "mesh": {"domain": "box", "size": [4.0, 1.0, 2.0],
                                               "cells": [12, 4, 4]},
                   "loads": {"traction": {"right": ["7*t", "14*t", "0"]}}}),
}
BACKENDS = ["superlu", "amg"] + (["pardiso"] if pardiso.available() else [])


@pytest.mark.parametrize("dim", [2, 3])
def test_backends_give_the_same_run(dim):
    scene = scene_from_dict(SCENES[dim])
    runs = {}
    for backend in BACKENDS:
        problem = build_problem(replace(scene, solver=replace(scene.solver, linear=backend)))
        runs[backend] = solve(problem)
        assert runs[backend].success, (backend, runs[backend].message)
        assert runs[backend].linear["method"] == backend
    ref = runs["superlu"]
    assert ref.beta[-1].min() < 0.9   # the glue is breaking: the nonlinear terms are at work
    for backend, run in runs.items():
        tol = 1e-7 if backend == "amg" else 1e-9
        for key in ("u", "beta", "contact_force"):
            a, b = getattr(run, key), getattr(ref, key)
            assert np.abs(a - b).max() <= tol * np.abs(b).max(), (backend, key)
