"""Shared helpers for the verification tests (elasticity, contact solver,
memory): run a scene through the library, and build the independent
reference quantities (meshes, stiffness, loads) straight from scikit-fem.

Nothing here calls the library's assembly, load map or contact boundary:
the references must not share code with what they check.
"""

import numpy as np
import pytest
from skfem import (
    Basis,
    ElementTriP1,
    ElementVector,
    FacetBasis,
    LinearForm,
    MeshQuad,
    MeshTri,
    asm,
)
from skfem.models.elasticity import lame_parameters, linear_elasticity

from adhesive_contact import build_problem, parse_scene, solve


def run(toml_text):
    """(problem, solution) of a TOML scene."""
    problem = build_problem(parse_scene(toml_text))
    return problem, solve(problem)


def reference_mesh(size, cells, pattern="diagonal"):
    """The structured rectangle mesh, built here with named sides."""
    xs = np.linspace(0.0, size[0], cells[0] + 1)
    ys = np.linspace(0.0, size[1], cells[1] + 1)
    if pattern == "cross":
        mesh = MeshQuad.init_tensor(xs, ys).to_meshtri(style="x")
    else:
        mesh = MeshTri.init_tensor(xs, ys)
    L, H = size
    return mesh.with_boundaries({
        "left": lambda x: np.isclose(x[0], 0.0),
        "right": lambda x: np.isclose(x[0], L),
        "bottom": lambda x: np.isclose(x[1], 0.0),
        "top": lambda x: np.isclose(x[1], H),
    })


def same_mesh(problem, mesh):
    """Assert the library's mesh is ours (same vertices, same order), so that
    nodal vectors can be compared entry by entry."""
    assert problem.mesh.p.shape == mesh.p.shape
    np.testing.assert_allclose(problem.mesh.p, mesh.p, rtol=0, atol=1e-14)


def vector_basis(mesh, intorder=6):
    return Basis(mesh, ElementVector(ElementTriP1()), intorder=intorder)


def stiffness(mesh, E=None, nu=None, lam=None, mu=None):
    """Plane-strain P1 stiffness from scikit-fem's own elasticity model."""
    if lam is None:
        lam, mu = lame_parameters(E, nu)
    return asm(linear_elasticity(lam, mu), vector_basis(mesh, intorder=2)).tocsr()


def load_vector(mesh, body=None, traction=None, intorder=6):
    """⟨f, v⟩ = (f_0, v)_Ω + Σ_sides (f_N, v)_side with f_0 = body(x, y) and
    traction = {side: f(x, y)}, each a callable returning a pair of arrays.
    The rule of order ``intorder`` is exact for the polynomial loads used in
    the tests (degree ≤ 3 times P1)."""
    basis = vector_basis(mesh, intorder)
    f = np.zeros(basis.N)
    if body is not None:
        @LinearForm
        def lf(v, w):
            fx, fy = body(w.x[0], w.x[1])
            return fx * v[0] + fy * v[1]
        f += asm(lf, basis)
    for side, func in (traction or {}).items():
        fb = FacetBasis(mesh, basis.elem, facets=mesh.boundaries[side], intorder=intorder)

        @LinearForm
        def lt(v, w, func=func):
            fx, fy = func(w.x[0], w.x[1])
            return fx * v[0] + fy * v[1]
        f += asm(lt, fb)
    return f


def clamped_dofs(mesh, sides):
    basis = vector_basis(mesh, 2)
    return np.unique(np.concatenate([basis.get_dofs(mesh.boundaries[s]).all() for s in sides]))


def relative_max(a, b):
    """max|a − b| / max|b|."""
    return np.abs(np.asarray(a) - np.asarray(b)).max() / np.abs(np.asarray(b)).max()


@pytest.fixture
def rng():
    return np.random.default_rng(20240611)
