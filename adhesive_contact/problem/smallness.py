"""The smallness conditions of docs/model.md §3, estimated per scene:

    existence and uniqueness   m_A > max{√3 c_1τ, m_τ} c_e²‖γ‖² + m_ν c_e²‖γ‖²,
    the error estimate         m_A > (m_τ + m_ν) c_e²‖γ‖²,
    convexity of a step        m_A > m_c c_e²‖γ‖²,

m_A is the strong monotonicity constant of the isotropic elasticity,
(C ε, ε) ≥ m_A |ε|² with m_A = min(2μ, d λ + 2μ) (the deviatoric and the
spherical eigenvalues of C). c_e‖γ‖ is the best constant in
‖v‖_{L²(Γ_C)} ≤ c_e‖γ‖ ‖ε(v)‖_{L²(Ω)} on V, estimated by the largest
eigenvalue of the generalised problem

    ∫_{Γ_C} u·v = λ ∫_Ω ε(u):ε(v)      (v ∈ V^h, on the mesh of the run),

so c_e²‖γ‖² ≈ λ_max. (A discrete maximum over a subspace: a lower bound of
the continuous constant that converges from below as the mesh is refined,
about 17 % from a coarse mesh to four refinements in one measured case; on
the mesh of the run it is the exact constant of the discrete problem,
which is what the convexity of a step needs.) Above ``MAX_TRACE_DOFS``
free dofs the eigenproblem is solved on the coarsest mesh of the scene
instead, and the record says so (``trace_lower_estimate``: a lower
estimate also of the run mesh's constant, so the conditions are then
optimistic). m_ν, m_τ and c_1τ are the constants of the scene's laws.
The condition is
sufficient, not necessary: convex laws give a unique discrete solution
whatever it says: the step energy of docs/scheme.md ('What a step solves') is strictly convex as
soon as m_A > m_c c_e²‖γ‖², m_c the nonconvexity of the friction
(α (a − b) for slip weakening, 0 for every other law of §6), which is
reported too.
"""

import math
from dataclasses import replace
from functools import lru_cache

import numpy as np
import scipy.linalg as la
import scipy.sparse as sp
from scipy.sparse.linalg import eigsh, splu
from skfem import BilinearForm, FacetBasis, asm
from skfem.helpers import dot

from ..fem.assembly import Assembly, vector_element
from ..fem.meshes import build_mesh


@BilinearForm
def boundary_mass(u, v, w):
    """∫_{Γ_C} u · v."""
    return dot(u, v)


#: above this many free dofs the trace constant comes from the unrefined mesh
MAX_TRACE_DOFS = 20000


def trace_mesh_refine(scene):
    """The refinement level the trace constant is computed on: the run's,
    unless its dofs (estimated from the unrefined mesh: ×2^d per
    refinement) exceed :data:`MAX_TRACE_DOFS` (then 0)."""
    refine = scene.mesh.refine
    if not refine:
        return 0
    coarse = build_mesh(replace(scene.mesh, refine=0))
    ndofs = scene.dim * coarse.p.shape[1] * (2 ** scene.dim) ** refine
    return refine if ndofs <= MAX_TRACE_DOFS else 0


def trace_mesh_spec(scene, refine):
    """The mesh the trace constant is computed on: the scene's refined
    ``refine`` times; a built-in mesh whose unrefined grid alone has more
    than :data:`MAX_TRACE_DOFS` dofs gets proportionally fewer cells (the
    eigenproblem of a 1e6-dof grid took minutes): a lower estimate."""
    spec = replace(scene.mesh, refine=refine)
    if refine or spec.domain not in ("rectangle", "box"):
        return spec
    dofs = scene.dim * math.prod(c + 1 for c in spec.cells)
    if dofs <= MAX_TRACE_DOFS:
        return spec
    factor = math.ceil((dofs / MAX_TRACE_DOFS) ** (1.0 / scene.dim))
    return replace(spec, cells=tuple(max(1, c // factor) for c in spec.cells))


def trace_constant_squared(scene, refine=None):
    """λ_max of ∫_{Γ_C} u·v = λ ∫_Ω ε(u):ε(v) on the scene's mesh refined
    ``refine`` times (default: :func:`trace_mesh_refine`; see
    :func:`trace_mesh_spec`); kept per mesh and sides (the variants of a
    sweep share it)."""
    refine = trace_mesh_refine(scene) if refine is None else refine
    # a side that holds some components only is taken as clamped: c_e is
    # then a little smaller than with those components free
    return _trace_constant(trace_mesh_spec(scene, refine), tuple(scene.held_sides),
                           tuple(scene.contact_sides))


@lru_cache(maxsize=64)
def _trace_constant(mesh_spec, dirichlet, contact_sides):
    mesh = build_mesh(mesh_spec)
    assembly = Assembly(mesh)
    d = mesh.dim()
    clamped_facets = np.concatenate([mesh.boundaries[s] for s in dirichlet])
    clamped = np.unique(assembly.nodal_dofs[:, np.unique(mesh.facets[:, clamped_facets])])
    free = np.setdiff1d(np.arange(assembly.ndofs), clamped)
    facets = np.concatenate([mesh.boundaries[s] for s in contact_sides])
    fb = FacetBasis(mesh, vector_element(d), facets=facets, intorder=2)
    M = asm(boundary_mass, fb).tocsr()[free][:, free]
    E = (0.5 * assembly.K_mu).tocsr()[free][:, free]   # ∫ ε(u):ε(v)
    if free.size <= 300:
        vals = la.eigh(M.toarray(), E.toarray(), eigvals_only=True,
                       subset_by_index=[free.size - 1, free.size - 1])
        return float(vals[-1])
    lu = splu(sp.csc_matrix(E))
    vals = eigsh(M, k=1, M=E, Minv=sp.linalg.LinearOperator(E.shape, lu.solve),
                 which="LA", return_eigenvectors=False)
    return float(vals[0])


def smallness(scene, normal_law, friction, held_by_contact=()):
    """The terms of the conditions as a JSON-able dict: ``holds`` (the error
    estimate's), ``existence_holds``, ``step_energy_convex``, their right-hand
    sides, and the mesh the trace constant comes from.

    With rigid motions that only the contact terms hold (``held_by_contact``,
    in words) ‖ε(v)‖ is no norm on V and c_e‖γ‖ is infinite: the conditions
    do not hold, their right-hand sides and the trace constant are None,
    ``held_by_contact`` lists the motions, and a step's energy is convex
    when the friction is (m_c = 0: S is positive semidefinite, docs/model.md
    'A body held by contact')."""
    lam, mu = scene.material.lam, scene.material.mu
    m_A = min(2.0 * mu, scene.dim * lam + 2.0 * mu)
    m_nu = float(normal_law.lipschitz)
    m_tau = 0.0 if friction is None else float(friction.m_tau)
    c_1 = 0.0 if friction is None else float(friction.c_1)
    m_c = 0.0 if friction is None else float(friction.nonconvexity)
    if held_by_contact:
        return {"m_A": m_A, "m_nu": m_nu, "m_tau": m_tau, "trace_constant_squared": None,
                "rhs": None, "holds": False, "c_1tau": c_1, "existence_rhs": None,
                "existence_holds": False, "nonconvexity": m_c, "convexity_rhs": None,
                "step_energy_convex": bool(m_c == 0.0), "trace_refine": None,
                "trace_lower_estimate": False, "held_by_contact": list(held_by_contact)}
    refine = trace_mesh_refine(scene) if scene.contact_sides else 0
    ce2 = trace_constant_squared(scene, refine) if scene.contact_sides else 0.0
    rhs = (m_tau + m_nu) * ce2
    existence = (max(np.sqrt(3.0) * c_1, m_tau) + m_nu) * ce2
    return {"m_A": m_A, "m_nu": m_nu, "m_tau": m_tau, "trace_constant_squared": ce2,
            "rhs": rhs, "holds": bool(m_A > rhs),
            "c_1tau": c_1, "existence_rhs": existence, "existence_holds": bool(m_A > existence),
            "nonconvexity": m_c, "convexity_rhs": m_c * ce2,
            "step_energy_convex": bool(m_A > m_c * ce2),
            "trace_refine": refine,
            "trace_lower_estimate": bool(refine < scene.mesh.refine
                                         or trace_mesh_spec(scene, refine) != replace(
                                             scene.mesh, refine=refine))}
