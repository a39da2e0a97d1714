"""The bulk operators by both paths (docs/architecture.md, "The bulk
operators: kernels and forms"): the vectorised P1 kernels and scikit-fem's
assembly of the forms of fem/forms.py give every operator to round-off,
on structured and gmsh meshes in 2D and 3D; the forms against what nobody
here wrote (scikit-fem's own linear elasticity, closed-form integrals, P2
on a quadratic field); the automatic choice; and committed scenes solved
both ways.

Round-off bound 1e-13 of the largest entry: an entry of either path sums
the same few products per cell over at most a few tens of cells, in
another order (the kernels by cofactors and bincount, scikit-fem by its
mapping's inverse and a sparse sum), a few tens of ulps.
"""

from pathlib import Path

import numpy as np
import pytest
from skfem import ElementTriP2, MeshTet, MeshTri, MeshTri2, asm
from skfem.models.elasticity import linear_elasticity

from adhesive_contact import build_problem, load_scene, solve
from adhesive_contact.expressions import compile_expression
from adhesive_contact.fem import forms
from adhesive_contact.fem.assembly import Assembly, FormLoad, LoadMap, choose_path, vector_of
from adhesive_contact.fem.meshes import read_mesh_file

ROOT = Path(__file__).resolve().parents[1]
ROUND_OFF = 1e-13


def structured_2d():
    return MeshTri.init_tensor(np.linspace(0.0, 2.0, 13), np.linspace(0.0, 1.0, 7)).with_defaults()


def structured_3d():
    return MeshTet.init_tensor(*[np.linspace(0.0, 1.0, 5)] * 3).with_defaults()


MESHES = {
    "rectangle": structured_2d,
    "box": structured_3d,
    "half_disc.msh": lambda: read_mesh_file(ROOT / "studies/meshes/half_disc.msh", 2),
    "cylinder_foot.msh": lambda: read_mesh_file(ROOT / "studies/meshes/cylinder_foot.msh", 3),
}


@pytest.fixture(scope="module", params=sorted(MESHES))
def both(request):
    """(mesh, the kernels' Assembly, the forms' Assembly)."""
    mesh = MESHES[request.param]()
    return mesh, Assembly(mesh), Assembly(mesh, path="forms")


def relative(a, b):
    a, b = (x.toarray() if hasattr(x, "toarray") else np.asarray(x) for x in (a, b))
    return np.abs(a - b).max() / np.abs(b).max()


def field(texts):
    return vector_of([compile_expression(t) for t in texts])


def test_auto_takes_the_kernels_on_p1_simplices(both):
    mesh, kernels, forms_path = both
    assert kernels.record["path"] == "kernels" and "P1 kernels" in kernels.record["reason"]
    assert forms_path.record == {"path": "forms", "reason": "the forms were asked for "
                                 f"(P1 on {type(mesh).__name__})."}


def test_the_forms_path_uses_no_kernel(monkeypatch):
    """The forms path calls none of the P1 kernels (else the comparisons
    here would compare the kernels with themselves)."""
    import adhesive_contact.fem.assembly as module

    def refuse(*args, **kwargs):
        raise AssertionError("a kernel was called on the forms path")

    for name in ("gradients", "stiffness_parts", "strain_operator", "CellLoad", "SurfaceLoad",
                 "quadrature_load_map"):
        monkeypatch.setattr(module, name, refuse)
    mesh = structured_2d()
    assembly = Assembly(mesh, path="forms")
    loads = LoadMap(mesh, field(["x", "y"]), [(mesh.boundaries["left"], field(["1", "t"]))],
                    assembly=assembly)
    assert all(isinstance(load, FormLoad) for _, load in loads.parts)
    assert np.isfinite(loads(0.5)).all()
    # u = x, ε = I in every cell
    np.testing.assert_allclose(assembly.cell_strain(mesh.p.T.ravel()),
                               np.broadcast_to(np.eye(2), (mesh.t.shape[1], 2, 2)), atol=1e-13)


def test_stiffness_parts_and_matrix(both):
    """K_λ, K_μ and λ K_λ + μ K_μ: the same pattern (so a linear backend
    orders and sizes both alike) and the same values to round-off."""
    mesh, kernels, forms_path = both
    for name in ("K_lam", "K_mu"):
        k, f = getattr(kernels, name).tocsr(), getattr(forms_path, name)
        assert relative(k, f) < ROUND_OFF, name
        assert k.nnz == f.nnz
    k, f = kernels.stiffness(576.9, 384.6), forms_path.stiffness(576.9, 384.6)
    assert np.array_equal(k.indptr, f.indptr) and np.array_equal(k.indices, f.indices)
    assert relative(k, f) < ROUND_OFF
    assert kernels.ndofs == forms_path.ndofs
    assert np.array_equal(kernels.nodal_dofs, forms_path.nodal_dofs)


def test_strain_stress_and_force(both, rng):
    mesh, kernels, forms_path = both
    u, a, b = rng.standard_normal((3, kernels.ndofs))
    assert relative(kernels.strain, forms_path.strain) < ROUND_OFF
    assert relative(kernels.cell_strain(u), forms_path.cell_strain(u)) < ROUND_OFF
    (sk, zk), (sf, zf) = kernels.cell_stress(a, b), forms_path.cell_stress(a, b)
    assert relative(sk, sf) < ROUND_OFF and relative(zk, zf) < ROUND_OFF
    assert relative(kernels.force(a, b), forms_path.force(a, b)) < ROUND_OFF


@pytest.mark.parametrize("body", [["x*y - t", "sin(3*x) + y", "x*z"], ["t", "-40*t", "2"]])
def test_body_and_surface_loads(both, body):
    """⟨f(t), v⟩ of a body force varying in space (evaluated at every
    quadrature point), or constant in space (the kernels spread it by
    ∫ φ_i, the forms evaluate it everywhere), and a traction on one side."""
    mesh, kernels, forms_path = both
    d = mesh.dim()
    side = sorted(mesh.boundaries)[0]
    surface = [(mesh.boundaries[side], field(["x*t", "1 + y", "y*z"][:d]))]
    at = 0.7
    k = LoadMap(mesh, field(body[:d]), surface, assembly=kernels)(at)
    f = LoadMap(mesh, field(body[:d]), surface, assembly=forms_path)(at)
    assert relative(k, f) < ROUND_OFF
    # each part alone, so that a large one does not hide a small one
    for part in range(2):
        k_part, f_part = (load_map.parts[part][1] for load_map in (
            LoadMap(mesh, field(body[:d]), surface, assembly=kernels),
            LoadMap(mesh, field(body[:d]), surface, assembly=forms_path)))
        np.testing.assert_allclose(k_part.points, f_part.points, rtol=0, atol=1e-14)
        values = np.random.default_rng(part).standard_normal(k_part.points.shape)
        assert relative(k_part(values), f_part(values)) < ROUND_OFF


# ---------------------------------------------------------------- the forms alone


def test_the_forms_stiffness_is_scikit_fems_linear_elasticity():
    """λ K_λ + μ K_μ from the forms against scikit-fem's own
    models.elasticity.linear_elasticity, and elasticity(isotropic_stress)."""
    for mesh in (structured_2d(), structured_3d()):
        assembly = Assembly(mesh, path="forms")
        lam, mu = 576.9, 384.6
        reference = asm(linear_elasticity(lam, mu), assembly.basis)
        assert relative(assembly.stiffness(lam, mu), reference) < ROUND_OFF
        ours = asm(forms.elasticity(forms.isotropic_stress(lam, mu)), assembly.basis)
        assert relative(ours, reference) < ROUND_OFF


def test_an_anisotropic_tensor_as_a_form():
    """elasticity(C) of a general symmetric, positive tensor (Voigt 6 × 6):
    the energy of u = G x is |Ω| C ε : ε with ε = sym G exactly, and an
    infinitesimal rotation u = W x (W skew) has no force."""
    mesh = structured_3d()
    rng = np.random.default_rng(3)
    M = rng.standard_normal((6, 6))
    C = M @ M.T + 6.0 * np.eye(6)
    voigt = [(0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1)]

    def stress(strain):
        e = np.stack([strain[i, j] * (1.0 if i == j else 2.0) for i, j in voigt])
        s = np.einsum("ab,b...->a...", C, e)
        out = np.empty_like(strain)
        for a, (i, j) in enumerate(voigt):
            out[i, j] = out[j, i] = s[a]
        return out

    assembly = Assembly(mesh, path="forms")
    K = asm(forms.elasticity(stress), assembly.basis)
    G = rng.standard_normal((3, 3))
    eps = 0.5 * (G + G.T)
    u = (G @ mesh.p).T.ravel()                       # interleaved d·node + c
    e = np.array([eps[i, j] * (1.0 if i == j else 2.0) for i, j in voigt])
    exact = 1.0 * (e @ C @ e)                         # |Ω| = 1
    assert u @ K @ u == pytest.approx(exact, rel=1e-12)
    W = G - G.T
    assert np.abs(K @ (W @ mesh.p).T.ravel()).max() < 1e-12 * abs(K).max()


def test_p2_plugs_in_as_a_form():
    """P2 on the unit square by the forms (the kernels do not apply): for
    u = (x², x y), exact in P2, ∫ (div u)² = 3 and 2 ∫ ε : ε = 11/3
    (div u = 3x, ε = [[2x, y/2], [y/2, x]]), the strain's cell means are ε
    at the centroids (ε is linear), and the load of f = (1 + x, y) sums to
    ∫ f = (3/2, 1/2) over each component's dofs."""
    mesh = MeshTri.init_sqsymmetric().refined(2)
    assembly = Assembly(mesh, ElementTriP2())
    assert assembly.path == "forms" and "ElementTriP2" in assembly.reason
    basis = assembly.basis
    x, component = basis.doflocs, np.arange(basis.N) % 2   # Lagrange dofs, interleaved
    u = np.where(component == 0, x[0] ** 2, x[0] * x[1])
    assert np.array_equal(basis.nodal_dofs[1] % 2, np.ones(mesh.p.shape[1]))
    assert u @ assembly.K_lam @ u == pytest.approx(3.0, rel=1e-12)
    assert u @ assembly.K_mu @ u == pytest.approx(11.0 / 3.0, rel=1e-12)
    c = mesh.p[:, mesh.t].mean(axis=1)
    expected = np.stack([np.stack([2 * c[0], c[1] / 2]), np.stack([c[1] / 2, c[0]])])
    np.testing.assert_allclose(assembly.cell_strain(u), expected.transpose(2, 0, 1),
                               rtol=0, atol=1e-12)
    load = LoadMap(mesh, field(["1 + x", "y"]), [], assembly=assembly)(0.0)
    assert load.size == assembly.ndofs
    x_dofs = np.concatenate([basis.nodal_dofs[0], basis.facet_dofs[0]])
    assert load[x_dofs].sum() == pytest.approx(1.5, rel=1e-13)
    assert load.sum() == pytest.approx(2.0, rel=1e-13)


# ---------------------------------------------------------------- the choice


def test_the_choice_of_path():
    tri, tet = MeshTri(), MeshTet()
    assert choose_path(tri)[0] == choose_path(tet)[0] == "kernels"
    assert choose_path(tri, asked="forms")[0] == "forms"
    path, reason = choose_path(tri, ElementTriP2())
    assert path == "forms" and "do not apply" in reason
    path, reason = choose_path(MeshTri2.init_circle(), None)   # curved cells
    assert path == "forms" and "MeshTri2" in reason
    with pytest.raises(ValueError, match="'kernels' holds only for P1 on straight-sided"):
        choose_path(tri, ElementTriP2(), asked="kernels")
    with pytest.raises(ValueError, match="allowed are 'auto', 'kernels', 'forms'"):
        choose_path(tri, asked="fast")


# ---------------------------------------------------------------- whole runs


@pytest.mark.parametrize("name", ["block", "debonding", "cylinder_foot"])
def test_a_committed_scene_gives_the_same_solution_by_the_forms(name):
    """A committed scene (memory and a body force varying in x; glue,
    friction, memory and a traction; a 3D gmsh foot on a foundation) solved
    with the kernels and with the forms: the same Newton iterations, and u,
    β and the contact forces to 1e-10 of their largest values. The
    matrices differ by round-off (above); the step solves amplify it by the
    step's conditioning, and debonding by its growth over the steps: at
    most 1e-11 was measured on the seven committed scenes."""
    scene = load_scene(ROOT / "studies/scenes" / f"{name}.toml")
    runs = []
    for bulk in ("auto", "forms"):
        problem = build_problem(scene, bulk=bulk)
        assert problem.assembly.path == ("kernels" if bulk == "auto" else "forms")
        assert all(isinstance(load, FormLoad) == (bulk == "forms")
                   for _, load in problem.loads.parts)
        runs.append(solve(problem))
    kernels, by_forms = runs
    assert kernels.success and by_forms.success
    assert np.array_equal(kernels.iterations, by_forms.iterations)
    for quantity in ("u", "beta", "contact_force"):
        a, b = getattr(kernels, quantity), getattr(by_forms, quantity)
        assert np.abs(a - b).max(initial=0.0) <= 1e-10 * np.abs(a).max(initial=0.0), quantity
