"""The uniqueness (smallness) condition of MODEL.md §2, estimated per scene.

    m_A > (m_τ + m_ν) c_e² ‖γ‖²

m_A is the strong monotonicity constant of the isotropic elasticity,
(C ε, ε) ≥ m_A |ε|² with m_A = min(2μ, d λ + 2μ) (the deviatoric and the
spherical eigenvalues of C). c_e‖γ‖ is the best constant in
‖v‖_{L²(Γ_C)} ≤ c_e‖γ‖ ‖ε(v)‖_{L²(Ω)} on V, estimated by the largest
eigenvalue of the generalised problem

    ∫_{Γ_C} u·v = λ ∫_Ω ε(u):ε(v)      (v ∈ V^h, on the unrefined mesh),

so c_e²‖γ‖² ≈ λ_max. (A discrete maximum over a subspace: a lower bound of
the continuous constant that converges from below as the mesh is refined.)
m_ν and m_τ are the constants of the scene's laws. The condition is
sufficient, not necessary: convex laws give a unique discrete solution
whatever it says: the step energy of MODEL.md §5 is strictly convex as
soon as m_A > m_c c_e²‖γ‖², m_c the nonconvexity of the friction
(α (a − b) for slip weakening, 0 for every other law of §6), which is
reported too.
"""

from dataclasses import replace
from functools import lru_cache

import numpy as np
import scipy.linalg as la
import scipy.sparse as sp
from scipy.sparse.linalg import eigsh, splu
from skfem import BilinearForm, FacetBasis, asm
from skfem.helpers import dot

from .assembly import Assembly, vector_element
from .meshes import build_mesh


@BilinearForm
def boundary_mass(u, v, w):
    """∫_{Γ_C} u · v."""
    return dot(u, v)


def trace_constant_squared(scene):
    """λ_max of ∫_{Γ_C} u·v = λ ∫_Ω ε(u):ε(v) on the scene's unrefined mesh
    (kept per mesh and sides: the variants of a sweep share it)."""
    # a side that holds some components only is taken as clamped: c_e is
    # then a little smaller than with those components free
    return _trace_constant(replace(scene.mesh, refine=0), tuple(scene.held_sides),
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


def smallness(scene, normal_law, friction):
    """The terms of the condition as a JSON-able dict."""
    lam, mu = scene.material.lam, scene.material.mu
    m_A = min(2.0 * mu, scene.dim * lam + 2.0 * mu)
    m_nu = float(normal_law.lipschitz)
    m_tau = 0.0 if friction is None else float(friction.m_tau)
    ce2 = trace_constant_squared(scene) if scene.contact_sides else 0.0
    rhs = (m_tau + m_nu) * ce2
    m_c = 0.0 if friction is None else float(friction.nonconvexity)
    return {"m_A": m_A, "m_nu": m_nu, "m_tau": m_tau, "trace_constant_squared": ce2,
            "rhs": rhs, "holds": bool(m_A > rhs),
            "nonconvexity": m_c, "step_energy_convex": bool(m_A > m_c * ce2)}
