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

:func:`check_rigid_motions` refuses a scene whose held components leave a
rigid motion free (the step matrix would be singular without contact).
"""

import numpy as np
import scipy.sparse as sp

from ..expressions import compile_expression, coordinates
from .meshes import named_facets
from ..scene import SceneError

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

    def __init__(self, fixed, sides, dim, groups, shares, side_dofs=None):
        self.fixed = fixed
        self.sides = sides
        self.dim = dim
        self._side_dofs = side_dofs or {}   # side -> {component: held dofs}
        # (positions within fixed, expression, coordinates (d, m)) of the nonzero data
        self._groups = groups
        self._shares = shares.tocsr()   # (nsides·d, nD): reaction share of each side

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
    """The :class:`PrescribedDisplacement` of a scene on ``mesh``.

    Raises SceneError when two sides hold one dof at different values (at
    some t_n) or when the held components leave a rigid motion free."""
    d = mesh.dim()
    sides = scene.held_sides
    times = scene.k * np.arange(scene.steps + 1)
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
    _check_agreement(rows, fixed, count, mesh, times)
    if scene.exact is not None:
        _check_exact(rows, scene, mesh, times)
    check_rigid_motions(mesh, fixed, sides)
    side_dofs = {side: {} for side in sides}
    for s, c, dofs, expr, key in rows:
        side_dofs[sides[s]][c] = dofs
    return PrescribedDisplacement(fixed, sides, d, groups, shares, side_dofs)


def _check_agreement(rows, fixed, count, mesh, times):
    """Every dof held by several sides gets one value from all of them."""
    shared = count > 1
    if not shared.any():
        return
    d = mesh.dim()
    first = {}
    for s, c, dofs, expr, key in rows:
        pos = np.searchsorted(fixed, dofs)
        keep = shared[pos]
        if not keep.any():
            continue
        x = mesh.p[:, dofs[keep] // d]
        values = np.array([np.broadcast_to(expr(*coordinates(x), t=t), x.shape[1])
                           for t in times])
        for p, column in zip(pos[keep], values.T):
            if p not in first:
                first[p] = (column, key)
                continue
            other, other_key = first[p]
            if np.abs(column - other).max() > 1e-12 * (1.0 + np.abs(other).max()):
                where = ", ".join(f"{v:g}" for v in mesh.p[:, fixed[p] // d])
                raise SceneError(key, f"holds the node ({where}) at another value than "
                                 f"{other_key}; sides that share a node must prescribe "
                                 "the same value there (or leave it \"free\" on one)")


def _check_exact(rows, scene, mesh, times):
    """In a scene with [exact], a held component must equal u* on its side."""
    d = mesh.dim()
    for s, c, dofs, expr, key in rows:
        if scene.held_sides[s] in scene.dirichlet:
            continue
        x = mesh.p[:, dofs // d]
        for t in times:
            given = np.broadcast_to(expr(*coordinates(x), t=t), x.shape[1])
            exact = np.broadcast_to(scene.exact.u[c](*coordinates(x), t=t), x.shape[1])
            if np.abs(given - exact).max() > 1e-10 * (1.0 + np.abs(exact).max()):
                raise SceneError(key, f"must equal exact.u[{c}] on the side in a scene "
                                 f"with [exact] (differs at t = {t:g})")


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


_MOTIONS = {2: ("translation along x", "translation along y", "rotation"),
            3: ("translation along x", "translation along y", "translation along z",
                "rotation about x", "rotation about y", "rotation about z")}


def check_rigid_motions(mesh, fixed, sides):
    """Refuse held dofs ``fixed`` that leave a rigid motion of the body free:
    the rank of the rigid modes restricted to them must be 3 in 2D (two
    translations and the rotation) and 6 in 3D."""
    d = mesh.dim()
    modes = rigid_modes(mesh.p)
    held = modes[fixed]
    nmodes = modes.shape[1]
    if fixed.size:
        _, sv, vt = np.linalg.svd(held, full_matrices=True)
        rank = int((sv > 1e-8 * sv[0]).sum()) if sv.size else 0
    else:
        rank, vt = 0, np.eye(nmodes)
    if rank == nmodes:
        return
    free_modes = vt[rank:]                 # the rigid motions the held dofs leave
    names = [name for k, name in enumerate(_MOTIONS[d])
             if np.abs(free_modes[:, k]).max() > 1e-6]
    raise SceneError("boundary", "the held sides (" + (", ".join(sides) or "none") + ") leave "
                     "the body free to move rigidly (" + ", ".join(names) + "): hold more "
                     "components, e.g. list a side in boundary.dirichlet or give \"0\" for "
                     "the missing component on a side of [boundary.displacement] (a single "
                     "held point does not stop a rotation: hold a component along a side)")
