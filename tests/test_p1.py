"""The vectorised P1 kernels against scikit-fem's forms on distorted 2D and
3D meshes: the same matrices up to round-off (relative 1e-13: both sum the
same few terms per entry in a different order)."""

import numpy as np
import pytest
from skfem import Basis, MeshTet, MeshTri, asm

from adhesive_contact import p1
from adhesive_contact.assembly import (
    divergence_product,
    quadrature_load_map,
    stiffness_basis,
    strain_map,
    strain_product,
    vector_element,
)


def distorted(mesh):
    """An affine-free perturbation, so no two cells share their gradients."""
    rng = np.random.default_rng(1)
    h = 0.1 * 2.0 ** -mesh.dim()
    return type(mesh)(mesh.p + h * rng.uniform(-0.5, 0.5, mesh.p.shape), mesh.t)


MESHES = {"tri": distorted(MeshTri.init_sqsymmetric().refined(3)),
          "tet": distorted(MeshTet().refined(2))}


def relative(a, b):
    return abs(a - b).max() / abs(b).max()


@pytest.mark.parametrize("name", sorted(MESHES))
def test_stiffness_parts_match_the_forms(name):
    mesh = MESHES[name]
    basis = stiffness_basis(mesh)
    K_lam, K_mu = p1.stiffness_parts(mesh)
    assert relative(K_lam, asm(divergence_product, basis)) < 1e-13
    assert relative(K_mu, asm(strain_product, basis)) < 1e-13
    # symmetric, and the rigid translations in the kernel, to round-off
    assert relative(K_mu, K_mu.T) < 1e-14   # duplicates summed in another order
    d = mesh.dim()
    for c in range(d):
        e = np.zeros(d * mesh.p.shape[1])
        e[c::d] = 1.0
        assert np.abs(K_mu @ e).max() < 1e-12 * abs(K_mu).max()


@pytest.mark.parametrize("name", sorted(MESHES))
def test_strain_and_load_maps_match_scikit_fem(name):
    mesh = MESHES[name]
    assert relative(p1.strain_operator(mesh), strain_map(stiffness_basis(mesh))) < 1e-13
    maps, points = p1.cell_load_map(mesh, 4)
    maps0, points0 = quadrature_load_map(Basis(mesh, vector_element(mesh.dim()), intorder=4))
    for m, m0 in zip(maps, maps0):
        assert relative(m, m0) < 1e-13
    np.testing.assert_allclose(points, points0, rtol=0, atol=1e-14)
