"""The vectorised P1 kernels against scikit-fem's forms on distorted 2D and
3D meshes: the same matrices up to round-off (relative 1e-13: both sum the
same few terms per entry in a different order)."""

import numpy as np
import pytest
from conftest import scene_dict
from skfem import Basis, BilinearForm, MeshTet, MeshTri, asm
from skfem.helpers import ddot, div, sym_grad

from adhesive_contact import build_problem, scene_from_dict
from adhesive_contact.fem import p1
from adhesive_contact.fem.assembly import (
    LoadMap,
    quadrature_load_map,
    stiffness_basis,
    strain_map,
    vector_element,
    vector_of,
)
from adhesive_contact.expressions import compile_expression


@BilinearForm
def divergence_product(u, v, w):
    """∫ div u div v: the λ part of the isotropic stiffness (scikit-fem's form)."""
    return div(u) * div(v)


@BilinearForm
def strain_product(u, v, w):
    """∫ 2 ε(u) : ε(v): the μ part of the isotropic stiffness (scikit-fem's form)."""
    return 2.0 * ddot(sym_grad(u), sym_grad(v))


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
    # the rows b ≤ c of scikit-fem's strain map, whose rows are all (b, c)
    d = mesh.dim()
    pairs, full = p1.symmetric_pairs(d)
    rows = np.array([b * d + c for b, c in pairs])
    rows = (d * d * np.arange(mesh.t.shape[1])[:, None] + rows).ravel()
    reference = strain_map(stiffness_basis(mesh))
    assert relative(p1.strain_operator(mesh), reference[rows]) < 1e-13
    assert [pairs[k] for k in full] == [(min(b, c), max(b, c)) for b in range(d)
                                        for c in range(d)]
    load = p1.CellLoad(mesh, 4)
    maps0, points0 = quadrature_load_map(Basis(mesh, vector_element(mesh.dim()), intorder=4))
    np.testing.assert_allclose(load.points, points0, rtol=0, atol=1e-14)
    # the contraction against scikit-fem's sparse maps, on arbitrary values
    values = np.random.default_rng(0).standard_normal(load.points.shape)
    expected = sum(m0 @ v for m0, v in zip(maps0, values))
    assert np.abs(load(values) - expected).max() <= 1e-13 * np.abs(expected).max()
    # a field constant in space: f_c ∫ φ_i, the same as evaluated everywhere
    f = np.arange(1.0, mesh.dim() + 1.0)
    everywhere = load(np.broadcast_to(f[:, None], load.points.shape))
    assert np.abs(load.uniform(f) - everywhere).max() <= 1e-13 * np.abs(everywhere).max()
    # ∫ φ_i sums to |Ω|
    assert load.mass.sum() == pytest.approx(p1.gradients(mesh)[1].sum(), rel=1e-13)


@pytest.mark.parametrize("name", sorted(MESHES))
def test_a_body_force_constant_in_space_skips_the_points(name, monkeypatch):
    """A body force that uses t only is evaluated at one point and spread by
    ∫ φ_i: the load of the same field evaluated at every quadrature point
    (the same expression plus 0·x, which uses x), to round-off; and the
    cells' points are never evaluated."""
    mesh = MESHES[name]
    d = mesh.dim()
    texts = ["3*t", "-40*t", "sin(t)"][:d]
    field = vector_of([compile_expression(e) for e in texts])
    spatial = vector_of([compile_expression(f"{e} + 0*x") for e in texts])
    assert not field.depends_on_space and spatial.depends_on_space
    expected = LoadMap(mesh, spatial, [])(0.7)
    evaluated = []
    call = vector_of.__call__
    monkeypatch.setattr(vector_of, "__call__",
                        lambda self, x, *a, **k: evaluated.append(np.size(x)) or call(
                            self, x, *a, **k))
    loads = LoadMap(mesh, field, [])
    got = loads(0.7)
    assert evaluated == [1]
    assert np.abs(got - expected).max() <= 1e-13 * np.abs(expected).max()
    assert "points" not in vars(loads.parts[0][1])   # never made


@pytest.mark.parametrize("body, made", [(["0", "-10*t"], False), (["0", "-10*t*x"], True)])
def test_a_scene_makes_the_cells_points_only_for_a_body_force_varying_in_space(body, made):
    """build_problem checks the loads finite: a body force constant in space
    at one point, one that uses x at every quadrature point."""
    problem = build_problem(scene_from_dict(scene_dict({"loads.body": body})))
    (field, load), = problem.loads.parts
    assert ("points" in vars(load)) == made
