"""Prescribed displacements: the dofs the boundary holds and their values.

A side listed in ``boundary.dirichlet`` holds every component at 0; a side
of ``[boundary.displacement]`` holds the components it gives an
expression for, u_c = g_c(x, t), and leaves the "free" ones. The held dofs
D are fixed in every step; the rest F are the unknowns. With the step
matrix a_n split into blocks, the step solves

    a_FF u_F = f_F − a_FD g_D(t_n)          (the data lifted, no penalty)

and the support exerts the reaction r_D = a_DF u_F + a_DD g_D − f_D on the
body (including the memory history in f).

A dof held by several sides (a corner node) must get the same value from
each; its reaction is split equally between them, so that the side
reactions add up to the total. A vertex of Γ_C with held components stays
a contact node (:mod:`.contact_boundary`): the contact laws read its held
components at g_D and act along its free ones as at any contact node;
their force along a held dof is part of r_D, as the support's is.

:func:`rigid_modes` gives the rigid motions whose restriction to the held
dofs :func:`adhesive_contact.problem.checks.check_rigid_motions` reads.
"""

import numpy as np
import scipy.sparse as sp

from ..expressions import compile_expression, coordinates
from .meshes import named_facets

_ZERO = compile_expression("0")


class PrescribedDisplacement:
    """The held dofs of a problem and g_D(t) on them.

    Attributes
    ----------
    fixed : (nD,) int, sorted
        The held dofs (interleaved numbering, d·a + c).
    sides : tuple of str
        The held sides, Dirichlet first.
    dim : int
    """

    def __init__(self, fixed, sides, dim, groups, shares, side_dofs=None, entries=(),
                 count=None):
        self.fixed = fixed
        self.sides = sides
        self.dim = dim
        self._side_dofs = side_dofs or {}   # side -> {component: held dofs}
        # (positions within fixed, expression, coordinates (d, m)) of the nonzero data
        self._groups = groups
        self._shares = shares.tocsr()   # (nsides·d, nD): reaction share of each side
        # (side index, component, dofs, expression, key) of every held component, and
        # how many sides hold each dof of ``fixed``: what the checks of the scene read
        self.entries = tuple(entries)
        self.count = np.zeros(fixed.size) if count is None else count

    @property
    def is_zero(self):
        """True when every held value is 0 at every t (clamped sides only)."""
        return not self._groups

    def values(self, t):
        """g_D(t) at the held dofs (nD,)."""
        g = np.zeros(self.fixed.size)
        for positions, expr, x in self._groups:
            g[positions] = expr(*coordinates(x), t=t)
        return g

    def side_dofs(self, side):
        """{component: the dofs of ``side`` held in that component}."""
        return self._side_dofs[side]

    def side_reactions(self, nodal):
        """Σ per side and component of the nodal reactions ``nodal`` (..., nD):
        (..., nsides, d), a dof held by several sides shared equally."""
        nodal = np.asarray(nodal, dtype=float)
        out = nodal @ self._shares.T
        return out.reshape(*nodal.shape[:-1], len(self.sides), self.dim)


def prescribed_displacement(scene, mesh):
    """The :class:`PrescribedDisplacement` of a scene on ``mesh`` (checked by
    :func:`adhesive_contact.problem.checks.check_prescribed`)."""
    d = mesh.dim()
    sides = scene.held_sides
    rows = []   # (side index, component, dofs, expression, key)
    for s, side in enumerate(sides):
        if side in scene.dirichlet:
            entries, key = (_ZERO,) * d, f"boundary.dirichlet[{scene.dirichlet.index(side)}]"
            facets = named_facets(mesh, [side], "boundary.dirichlet", indexed=False)
        else:
            entries, key = scene.displacement[side], f"boundary.displacement.{side}"
            facets = named_facets(mesh, [side], "boundary.displacement", indexed=False)
        nodes = np.unique(mesh.facets[:, facets])
        for c, expr in enumerate(entries):
            if expr is not None:
                rows.append((s, c, d * nodes + c, expr, f"{key}[{c}]"
                             if side not in scene.dirichlet else key))
    all_dofs = np.concatenate([r[2] for r in rows]) if rows else np.zeros(0, np.int64)
    fixed = np.unique(all_dofs)
    count = np.zeros(fixed.size)
    share_rows, share_cols = [], []
    groups = []
    for s, c, dofs, expr, key in rows:
        pos = np.searchsorted(fixed, dofs)
        np.add.at(count, pos, 1.0)
        share_rows.append(np.full(pos.size, s * d + c))
        share_cols.append(pos)
        if not (expr.is_constant and float(expr(0.0)) == 0.0):
            groups.append((pos, expr, mesh.p[:, dofs // d]))
    if rows:
        cols = np.concatenate(share_cols)
        shares = sp.coo_matrix((1.0 / count[cols], (np.concatenate(share_rows), cols)),
                               shape=(len(sides) * d, fixed.size))
    else:
        shares = sp.coo_matrix((0, 0))
    side_dofs = {side: {} for side in sides}
    for s, c, dofs, expr, key in rows:
        side_dofs[sides[s]][c] = dofs
    return PrescribedDisplacement(fixed, sides, d, groups, shares, side_dofs, rows, count)


def rigid_modes(points):
    """The rigid motions at ``points`` (d, m): (m·d, 3) in 2D (x and y
    translations, the rotation), (m·d, 6) in 3D, dofs interleaved; the
    rotations about the centroid, scaled by the points' extent."""
    d, m = points.shape
    x = points - points.mean(axis=1, keepdims=True)
    x = x / max(np.abs(x).max(), 1e-300)
    modes = []
    for c in range(d):
        v = np.zeros((m, d))
        v[:, c] = 1.0
        modes.append(v.ravel())
    axes = [(0, 1)] if d == 2 else [(1, 2), (2, 0), (0, 1)]
    for i, j in axes:                      # rotation in the (i, j) plane
        v = np.zeros((m, d))
        v[:, i], v[:, j] = -x[j], x[i]
        modes.append(v.ravel())
    return np.stack(modes, axis=1)


