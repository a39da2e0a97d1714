"""Φ of a step (adhesive_contact.scheme.contact_energy) against finite differences:
its gradient against its value and its Hessian against its gradient, in 2D
and 3D, nodal and Gauss quadrature; and the Hessian's linear map against
the sparse products it replaces."""

import numpy as np
import pytest
import scipy.sparse as sp

from adhesive_contact import build_problem, scene_from_dict
from adhesive_contact.scheme.contact_energy import HessianMap
from adhesive_contact.scheme.state import ContactStep

NORMAL = {"law": "adhesive_compliance", "c": 1e4, "gamma": 5e3, "L": 0.01}
SPRING = {"law": "adhesive_spring", "gamma": 2e3, "L": 0.01}
WEAKENING = {"law": "nonmonotone", "a": 2.0, "b": 1.0, "alpha": 50.0}


def energy_of(dim, quadrature):
    mesh = ({"domain": "rectangle", "size": [4.0, 0.5], "cells": [16, 2]} if dim == 2 else
            {"domain": "box", "size": [4.0, 1.0, 2.0], "cells": [4, 1, 2]})
    friction = [WEAKENING, SPRING] if quadrature == "nodal" else [SPRING]   # kinks: nodal only
    doc = {"dim": dim, "mesh": mesh, "material": {"E": 1000.0, "nu": 0.3},
           "boundary": {"dirichlet": ["left"], "contact": ["bottom"]},
           "time": {"T": 1.0, "steps": 2},
           "contact": {"gap": 0.05, "quadrature": quadrature, "normal": NORMAL,
                       "friction": friction,
                       "bonding": {"law": "fremond", "beta0": 1.0, "gamma_nu": 1e5,
                                   "gamma_tau": 5e4, "eps_a": 0.0, "L": 0.01}}}
    problem = build_problem(scene_from_dict(doc))
    energy = ContactStep(problem).energy
    # a bonding field that is not uniform: each facet its own β
    rng = np.random.default_rng(3)
    energy.set_bonding(rng.uniform(0.2, 1.0, problem.boundary.facets.size))
    return energy


CASES = [(2, "nodal"), (2, "gauss"), (3, "nodal"), (3, "gauss")]


def point(energy, seed):
    """Unknowns whose normal parts straddle 0 and L and whose slips are
    nonzero: every branch of the laws is visited, away from the kinks."""
    rng = np.random.default_rng(seed)
    return rng.uniform(-0.02, 0.02, energy.nz)


@pytest.mark.parametrize("dim, quadrature", CASES)
def test_gradient_is_the_derivative_of_the_value(dim, quadrature):
    energy = energy_of(dim, quadrature)
    z = point(energy, 0)
    g = energy.gradient(z)
    # central differences along random directions: error O(ε² Φ''') plus
    # round-off 1e-16 |Φ| / ε, both far below 1e-6 of the slope here
    rng = np.random.default_rng(1)
    eps = 1e-6
    for _ in range(5):
        v = rng.standard_normal(energy.nz)
        slope = (energy.value(z + eps * v) - energy.value(z - eps * v)) / (2 * eps)
        assert slope == pytest.approx(g @ v, rel=1e-6, abs=1e-9 * np.abs(g).sum())


@pytest.mark.parametrize("dim, quadrature", CASES)
def test_hessian_is_the_derivative_of_the_gradient(dim, quadrature):
    energy = energy_of(dim, quadrature)
    z = point(energy, 2)
    H = energy.hessian(z)
    assert sp.issparse(H) and H.shape == (energy.nz, energy.nz)
    np.testing.assert_allclose(H.toarray(), H.toarray().T, rtol=0, atol=1e-12 * abs(H).max())
    rng = np.random.default_rng(4)
    eps = 1e-7
    for _ in range(5):
        v = rng.standard_normal(energy.nz)
        fd = (energy.gradient(z + eps * v) - energy.gradient(z - eps * v)) / (2 * eps)
        np.testing.assert_allclose(H @ v, fd, rtol=0, atol=1e-5 * np.abs(fd).max())


@pytest.mark.parametrize("dim, quadrature", CASES)
def test_hessian_map_equals_the_sparse_products(dim, quadrature):
    """H = Nᵀ diag(n) N + Σ_ij T_iᵀ diag(b_ij) T_j for arbitrary n, b:
    the map's data against the products formed by scipy."""
    energy = energy_of(dim, quadrature)
    N, T, nq = energy.N, energy.T, energy.w.size
    m = len(T)
    rng = np.random.default_rng(5)
    n, b = rng.standard_normal(nq), rng.standard_normal((nq, m, m))
    expected = N.T @ sp.diags(n) @ N
    for i in range(m):
        for j in range(m):
            expected = expected + T[i].T @ sp.diags(b[:, i, j]) @ T[j]
    H = HessianMap(N, T, nq, energy.nz)(n, b)
    np.testing.assert_allclose(H.toarray(), expected.toarray(), rtol=0,
                               atol=1e-13 * abs(expected).max())
    # without a term: the other alone
    np.testing.assert_allclose(HessianMap(N, [], nq, energy.nz)(n).toarray(),
                               (N.T @ sp.diags(n) @ N).toarray(), rtol=0,
                               atol=1e-13 * abs(expected).max())


def test_hessian_map_on_a_vector_of_a_million_unknowns():
    """Φ as a function of all free dofs of a large mesh (the AMG step):
    the keys k·size + l of its entries pass 2³¹ and must not wrap."""
    size, nq = 1_000_000, 3
    cols = np.array([999_990, 999_995, 500_000])
    N = sp.csr_matrix((np.ones(nq), cols, np.arange(nq + 1)), shape=(nq, size))
    T = [sp.csr_matrix((np.full(nq, 2.0), cols[::-1], np.arange(nq + 1)), shape=(nq, size))]
    n, b = np.array([1.0, 2.0, 3.0]), np.array([4.0, 5.0, 6.0])[:, None, None]
    H = HessianMap(N, T, nq, size)(n, b)
    expected = N.T @ sp.diags(n) @ N + T[0].T @ sp.diags(b[:, 0, 0]) @ T[0]
    assert H.shape == (size, size) and H.nnz == 3
    assert abs(H - expected).max() == 0.0
