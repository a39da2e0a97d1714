"""Reaction forces of the supports, per held side.

The scheme records, per level, the nodal reaction
r_D = (a_n u_n)_D − f_D − F_D at each held dof
(:mod:`adhesive_contact.fem.dirichlet`): the force the support alone
exerts on the body, with f the load minus the memory history's force and
F_D the contact laws' force at a held vertex of Γ_C (in the contact force,
docs/conventions.md). The held dofs are never rotated, so r_D is in global components.
A side's reaction is the sum of the nodal reactions of its held
components; a dof held by several sides (a corner) is shared equally
between them, so the sides add up to the total support force. Components
a side leaves free carry no reaction of that side.

Equilibrium of the discrete problem: Σ_sides R_side + Σ_a F_a (contact)
+ ∫ f = 0 (the memory history's force is self-equilibrated: it is the
force of a stress).
"""

import numpy as np


def reaction_sides(problem):
    """The names of the held sides, in the order of :func:`side_reactions`."""
    return tuple(problem.prescribed.sides)


def side_reactions(problem, nodal):
    """The reaction of each held side from the nodal reactions ``nodal``
    (..., nD) of one or more levels: (..., nsides, d), global components."""
    return problem.prescribed.side_reactions(nodal)


def reactions(solution):
    """The reaction of each held side at every level (M+1, nsides, d),
    global components; the sides are :func:`reaction_sides`."""
    return side_reactions(solution.problem, solution.reaction)


def prescribed_history(solution, side):
    """The mean prescribed displacement of ``side`` per level (M+1, d):
    the mean of g_D over the side's held dofs for each held component, NaN
    for a component the side leaves free (for load–displacement curves)."""
    problem = solution.problem
    held = problem.prescribed
    d = problem.dim
    out = np.full((solution.t.size, d), np.nan)
    for c, dofs in held.side_dofs(side).items():
        positions = np.searchsorted(held.fixed, dofs)
        out[:, c] = [held.values(t)[positions].mean() for t in solution.t]
    return out


def side_displacements(solution, sides):
    """{side: (M+1, d)} the mean nodal displacement of each of ``sides``
    at every level, reading u one level at a time (it may be on disk); a
    solution read back from a folder whose fields are kept at some levels
    only gives its recorded columns ``displacement_<side>_<c>``
    (:mod:`.level_scalars`), NaN for a component it did not record."""
    from ..fem.meshes import named_facets

    problem = solution.problem
    recorded = getattr(solution, "scalars", None)
    if recorded is not None:
        return {side: np.stack([recorded.get(f"displacement_{side}_{'xyz'[c]}",
                                             (None, np.full(solution.t.size, np.nan)))[1]
                                for c in range(problem.dim)], axis=1) for side in sides}
    mesh = problem.mesh
    nodes = {side: np.unique(mesh.facets[:, named_facets(mesh, [side], "side", indexed=False)])
             for side in sides}
    out = {side: np.zeros((solution.t.size, problem.dim)) for side in sides}
    for n in range(solution.t.size):
        u = np.asarray(solution.u[n])
        for side in sides:
            out[side][n] = u[nodes[side]].mean(axis=0)
    return out


def side_mean_displacement(solution, side):
    """The mean nodal displacement of a side per level (M+1, d)
    (:func:`side_displacements`)."""
    return side_displacements(solution, [side])[side]


def applied_traction(problem, side, times):
    """The total force ∫_side f_N(x, t) ds of a loaded side's traction at
    ``times`` (len(times), d), by a Gauss rule of order 4 on its facets."""
    from skfem import ElementTetP1, ElementTriP1, FacetBasis

    from ..expressions import coordinates
    from ..fem.meshes import named_facets

    mesh, d = problem.mesh, problem.dim
    facets = named_facets(mesh, [side], "loads.traction", indexed=False)
    basis = FacetBasis(mesh, ElementTriP1() if d == 2 else ElementTetP1(), facets=facets,
                       intorder=4)
    x = np.asarray(basis.global_coordinates())                  # (d, nfacets, nq)
    weights = np.asarray(basis.dx)                              # (nfacets, nq)
    exprs = problem.scene.traction[side]
    out = np.zeros((len(times), d))
    for i, t in enumerate(times):
        for c, expr in enumerate(exprs):
            out[i, c] = np.sum(np.broadcast_to(expr(*coordinates(x), t=t), weights.shape)
                               * weights)
    return out
