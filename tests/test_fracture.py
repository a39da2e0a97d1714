"""What debonded and where (adhesive_contact.postprocess.fracture): for a
bonding linear along the contact side the debond front is where that line
crosses ½, exactly (linear interpolation between facet midpoints is exact
for it), in 2D and 3D; the debonded area and ∫(1 − β) against their
integrals by hand."""

from types import SimpleNamespace

import numpy as np
from conftest import law, scene_dict

from adhesive_contact import build_problem, scene_from_dict
from adhesive_contact.postprocess import (debond_front, debonded_area, energy_per_area)
from adhesive_contact.postprocess.fracture import adjacent_facets


def glued(dim=2):
    if dim == 2:
        mesh = {"domain": "rectangle", "size": [4.0, 0.25], "cells": [80, 2]}
    else:
        mesh = {"domain": "box", "size": [1.0, 0.2, 0.5], "cells": [6, 1, 3]}
    return build_problem(scene_from_dict(scene_dict({
        "dim": dim, "mesh": mesh,
        "contact": {"normal": law("adhesive_compliance", c=1e4, gamma=5e3, L=0.01)}})))


def midpoints(problem):
    return problem.mesh.p[:, problem.boundary.facet_nodes].mean(axis=1)


def test_front_of_a_linear_bonding_2d():
    problem = glued(2)
    x = midpoints(problem)[0]
    front = debond_front(problem, 1.0 - 0.3 * x)       # β = ½ at x = 5/3
    np.testing.assert_allclose(front, [[5.0 / 3.0, 0.0]], atol=1e-12)
    assert debond_front(problem, np.ones_like(x)).shape == (0, 2)


def test_front_of_a_linear_bonding_3d():
    problem = glued(3)
    x = midpoints(problem)[0]
    front = debond_front(problem, x)                    # β = ½ at x = 0.5
    assert front.shape[0] >= 3 and front.shape[1] == 3
    np.testing.assert_allclose(front[:, 0], 0.5, atol=1e-12)
    np.testing.assert_allclose(front[:, 1], 0.0, atol=1e-12)
    # every facet has three neighbours across its edges, but those on the border
    pairs = adjacent_facets(problem)
    nf = problem.boundary.facets.size
    assert 3 * nf // 2 > pairs.shape[1] > nf


def test_debonded_area_by_hand():
    """β = 1 − x/4 on [0, 4]: β < ½ on x > 2 (length 2), ∫ (1 − β) = 2."""
    problem = glued(2)
    x = midpoints(problem)[0]
    beta = np.stack([np.ones_like(x), 1.0 - x / 4.0])
    fake = SimpleNamespace(problem=problem, beta=beta, t=np.array([0.0, 1.0]))
    area, damage = debonded_area(fake)
    np.testing.assert_allclose(area, [0.0, 2.0], atol=1e-12)
    np.testing.assert_allclose(damage, [0.0, 2.0], atol=1e-12)
    per = energy_per_area(np.array([0.0, 3.0]), area)
    assert np.isnan(per[0]) and per[1] == 1.5
