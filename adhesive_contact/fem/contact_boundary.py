"""Γ_C: the contact facets, their nodes, frames, quadrature and P0 fields.

This module owns everything the contact laws see. Every vertex of Γ_C is a
contact node; its displacement is written in a local orthonormal frame,

    u_a = R_a z_a,   R_a = [ν_a, τ_a (, τ'_a)],

so that z_{a,0} = u_ν(x_a) and the wall u_ν ≤ g of K^h (docs/scheme.md) is a
bound on one coordinate. ν_a is the length-weighted average of the outward
normals of the facets of Γ_C around node a, or a given normal field
(``normal_field``): with ``[contact.foundation]`` the foundation's normal
at the node's closest point (:mod:`.foundation`), so that u_ν, the wall
and the normal traction are measured along it.

The contact unknowns are the frame components the boundary does not hold.
A component held by a side (``boundary.dirichlet`` or
``[boundary.displacement]``) is no unknown, but the contact laws read it
at its prescribed value:

- a node with every component held (a clamped vertex) keeps its frame R_a;
  its frame components are R_aᵀ g_D;
- a node with some components held gets the frame nearest to R_a in which
  each held Cartesian component is a frame component (:func:`held_frames`):
  on a flat side meeting a held side this is R_a itself, the held
  component being u_ν or a u_τ; elsewhere ν_a is replaced by its
  projection off the held axes, or by the held axis it is closest to,
  whichever is nearer to ν_a.

Their force along a held component has no equation: it is part of the
reaction of the held dof (docs/outputs.md).

The system is written in ũ = Rᵀ u (:meth:`ContactBoundary.rotation`).
At a node with some components held, its frame components sit at the
positions ``frame_dofs`` among the node's dofs chosen so that each held
component keeps its own dof (ũ = ±u there): the held dofs of ũ are those
of u, up to a sign, and a clamped node is not rotated at all.

Contact integrals ∫_{Γ_C} φ(β, u_ν, u_τ) are replaced by a quadrature
Σ_q w_q φ(β_{f(q)}, (N z)_q, (T z)_q) over points q of the contact facets,
with β the P0 value of the facet f(q) holding q:

- ``nodal`` (the default, docs/scenes.md): the trapezoid rule on each facet, its
  points being the facet's vertices (weights |f|/d each) and u_ν, u_τ being
  the nodal components z_a; the terms then split node by node;
- ``gauss``: a Gauss rule of the given exactness on each facet, with u the
  P1 interpolant and ν, τ the facet's own normal and tangents (those of
  the normal field at the point, when one is given).

N and T act on all nc·d frame components, held ones included.
"""

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from skfem.quadrature import get_quadrature
from skfem.refdom import RefLine, RefTri


def facet_normals(mesh, facets):
    """Outward unit normals (d, nf) and measures |f| (nf,) of boundary facets."""
    p = mesh.p
    nodes = mesh.facets[:, facets]
    if mesh.dim() == 2:
        edge = p[:, nodes[1]] - p[:, nodes[0]]
        normal = np.array([edge[1], -edge[0]])
        measure = np.linalg.norm(normal, axis=0)
    else:
        normal = np.cross(p[:, nodes[1]] - p[:, nodes[0]],
                          p[:, nodes[2]] - p[:, nodes[0]], axis=0)
        measure = 0.5 * np.linalg.norm(normal, axis=0)
    normal = normal / np.linalg.norm(normal, axis=0)
    # orient away from the centroid of the adjacent element
    element = mesh.f2t[0, facets]
    centroid = p[:, mesh.t[:, element]].mean(axis=1)
    outward = np.sum(normal * (p[:, nodes[0]] - centroid), axis=0) > 0
    return np.where(outward, normal, -normal), measure


def tangent_frame(normal):
    """Orthonormal frames (n, d, d) with columns [ν, τ (, τ')] for normals (d, n)."""
    d, n = normal.shape
    frame = np.empty((n, d, d))
    frame[:, :, 0] = normal.T
    if d == 2:
        frame[:, :, 1] = np.stack([-normal[1], normal[0]], axis=1)
        return frame
    # τ: ν × e, with e the axis least aligned with ν; τ' = ν × τ
    axis = np.zeros((3, n))
    axis[np.argmin(np.abs(normal), axis=0), np.arange(n)] = 1.0
    t1 = np.cross(normal, axis, axis=0)
    t1 /= np.linalg.norm(t1, axis=0)
    frame[:, :, 1] = t1.T
    frame[:, :, 2] = np.cross(normal, t1, axis=0).T
    return frame


def reference_facet_rule(dim, quadrature, order):
    """Points (nq, d) as P1 shape values on the reference facet and weights
    (nq,) that sum to 1 (a rule for the facet mean)."""
    if quadrature == "nodal":
        return np.eye(dim), np.full(dim, 1.0 / dim)
    X, W = get_quadrature(RefLine if dim == 2 else RefTri, order)
    shapes = np.vstack([1.0 - X.sum(axis=0), X]).T
    return shapes, W / W.sum()


def facet_points(mesh, facet_nodes, quadrature="gauss", order=4):
    """Points (d, nf, nq) of a facet rule on the facets with vertices
    ``facet_nodes`` (d, nf), and its weights (nq,) for the facet mean."""
    shapes, weights = reference_facet_rule(mesh.dim(), quadrature, order)
    return np.einsum("qv,dvf->dfq", shapes, mesh.p[:, facet_nodes]), weights


@dataclass
class ContactBoundary:
    """Γ_C of a mesh, with its contact unknowns and its quadrature.

    Attributes
    ----------
    facets : (nf,) mesh facet indices of Γ_C
    facet_nodes : (d, nf) their vertices
    measure : (nf,) facet measures |f|
    nodes : (nc,) contact nodes (every vertex of Γ_C)
    frame : (nc, d, d) the local frames R_a
    dofs : (nc, d) global dofs of the contact nodes (Cartesian components)
    weights : (nq,) quadrature weights w_q on Γ_C
    facet_of_point : (nq,) the facet holding each quadrature point
    points : (d, nq) the quadrature points
    normal_trace : (nq, nc·d) sparse N, z -> u_ν at the points
    tangential_trace : list of d-1 sparse (nq, nc·d), z -> u_τ components
    node_weights : (nc,) lumped nodal weights ∫ φ_a over Γ_C
    point_node : (nq,) contact node read by each point of the nodal rule
        (−1 for every point of a Gauss rule)
    held_axes : (nc, d) bool, the Cartesian components the boundary holds
    held : (nc, d) bool, the frame components held (those of ``held_axes``;
        all of a clamped node's)
    frame_dofs : (nc, d) the dof of ũ holding frame component c of node a
        (``dofs`` but at a node with some components held)
    rotated : (nc,) bool, the nodes R rotates (all but the clamped ones)
    held_positions : (nh,) positions within the held dofs (the
        ``fixed`` of the build) of the held Cartesian components of the
        contact nodes, node-major
    """

    dim: int
    facets: np.ndarray
    facet_nodes: np.ndarray
    measure: np.ndarray
    nodes: np.ndarray
    frame: np.ndarray
    dofs: np.ndarray
    weights: np.ndarray
    facet_of_point: np.ndarray
    points: np.ndarray
    normal_trace: sp.csr_matrix
    tangential_trace: list
    node_weights: np.ndarray
    point_node: np.ndarray
    held_axes: np.ndarray
    held: np.ndarray
    frame_dofs: np.ndarray
    rotated: np.ndarray
    held_positions: np.ndarray

    def rotation(self, ndofs):
        """Sparse R (ndofs × ndofs): u = R ũ with ũ the nodal-frame components
        at the rotated contact nodes (at their ``frame_dofs``) and the
        Cartesian ones elsewhere (R orthogonal; ±1 on the diagonal at a
        held dof of a contact node, 1 at the other held dofs)."""
        d = self.dim
        dofs, frame_dofs = self.dofs[self.rotated], self.frame_dofs[self.rotated]
        n = dofs.shape[0]
        other = np.setdiff1d(np.arange(ndofs), dofs.ravel())
        rows = np.broadcast_to(dofs[:, :, None], (n, d, d))   # (a, i, c): R[dof_ai, frame_dof_ac]
        cols = np.broadcast_to(frame_dofs[:, None, :], (n, d, d))
        return sp.csr_matrix((np.concatenate([self.frame[self.rotated].ravel(),
                                              np.ones(other.size)]),
                              (np.concatenate([rows.ravel(), other]),
                               np.concatenate([cols.ravel(), other]))), shape=(ndofs, ndofs))

    def unknowns(self, components):
        """Indices (node-major, nc·d) of the given frame components of every
        node, but the held ones."""
        comps = np.asarray(components)
        index = (np.arange(self.nodes.size)[:, None] * self.dim + comps[None, :]).ravel()
        return index[~self.held.ravel()[index]]

    @property
    def has_held(self):
        """True when some component of a contact node is held."""
        return bool(self.held.any())

    def frame_components(self, u):
        """The nodal-frame components (nc·d,) of the contact nodes of a
        Cartesian displacement u (ndofs,): z_a = R_aᵀ u_a."""
        return np.einsum("aic,ai->ac", self.frame, u[self.dofs]).ravel()

    def held_values(self, prescribed):
        """The frame components (nc·d,) of the held values g_D (the
        prescribed values at the held dofs, ``fixed`` order): R_aᵀ g_a at
        the held components, 0 at the free ones (which, R_a being aligned
        with the held axes, the held values do not enter)."""
        g = np.zeros(self.held_axes.shape)
        g[self.held_axes] = prescribed[self.held_positions]
        return np.where(self.held, np.einsum("aic,ai->ac", self.frame, g), 0.0).ravel()

    def held_forces(self, frame_force, size):
        """The transpose of :meth:`held_values`: frame components (nc·d,) of
        nodal forces, read at the held components, as forces on the held
        dofs (``size`` of them, ``fixed`` order; 0 at the held dofs off
        Γ_C): R_a F_a at each held Cartesian component."""
        F = np.where(self.held, np.asarray(frame_force).reshape(self.held.shape), 0.0)
        out = np.zeros(size)
        out[self.held_positions] = np.einsum("aic,ac->ai", self.frame, F)[self.held_axes]
        return out

    def at_points(self, facet_values):
        """A P0 field (nf,) read at the quadrature points (nq,)."""
        return facet_values[self.facet_of_point]

    def facet_mean(self, point_values):
        """P_B: the facet means (nf,) of values (nq,) given at the points."""
        return np.bincount(self.facet_of_point, self.weights * point_values,
                           minlength=self.facets.size) / self.measure


def build_contact_boundary(mesh, contact_facets, held_dofs=(), quadrature="nodal", order=4,
                           normal_field=None):
    """Assemble :class:`ContactBoundary` for the given facets of ``mesh``;
    ``held_dofs`` (sorted) are the dofs the boundary holds (interleaved,
    d·a + c); ``normal_field``, a function of points (d, n) returning unit
    normals (d, n), gives ν at the nodes (and at the points of a Gauss
    rule) instead of the averaged facet normals."""
    d = mesh.dim()
    facets = np.asarray(contact_facets, dtype=np.int64)
    held_dofs = np.asarray(held_dofs, dtype=np.int64)
    facet_nodes = mesh.facets[:, facets]
    normal_f, measure = facet_normals(mesh, facets)
    nodes = np.unique(facet_nodes)
    local = np.full(mesh.p.shape[1], -1)
    local[nodes] = np.arange(nodes.size)

    # averaged nodal normals (weighted by |f|)
    acc = np.zeros((d, mesh.p.shape[1]))
    for i in range(d):
        np.add.at(acc.T, facet_nodes[i], (normal_f * measure).T)
    nodal_normal = acc[:, nodes] / np.linalg.norm(acc[:, nodes], axis=0)
    if normal_field is not None:
        nodal_normal = np.asarray(normal_field(mesh.p[:, nodes]), dtype=float)
    dofs = np.stack([d * nodes + c for c in range(d)], axis=1)  # interleaved dofs
    held_axes = np.isin(dofs, held_dofs)
    frame, held, frame_dofs = held_frames(tangent_frame(nodal_normal), held_axes, dofs)

    shapes, ref_weights = reference_facet_rule(d, quadrature, order)
    points, _ = facet_points(mesh, facet_nodes, quadrature, order)
    nq_ref = ref_weights.size
    nf = facets.size
    weights = (measure[:, None] * ref_weights[None, :]).ravel()
    facet_of_point = np.repeat(np.arange(nf), nq_ref)
    points = points.reshape(d, -1)

    # nodal: point (f, v) reads node facet_nodes[v, f] in its own frame;
    # gauss: the point reads the P1 interpolant in the facet's frame
    if quadrature == "gauss":
        directions = (np.repeat(tangent_frame(normal_f), nq_ref, axis=0)  # (nq, d, d)
                      if normal_field is None else tangent_frame(normal_field(points)))

    nz = nodes.size * d
    traces = []
    for comp in range(d):
        rows, cols, vals = [], [], []
        for v in range(d):  # facet vertices
            node = local[facet_nodes[v]]  # (nf,)
            keep = node >= 0
            phi = np.broadcast_to(shapes[:, v], (nf, nq_ref))  # (nf, nq_ref)
            q = np.arange(nf * nq_ref).reshape(nf, nq_ref)
            if quadrature == "nodal":
                # only the vertex's own point reads it, in the nodal frame
                sel = phi[keep] > 0.5
                rows.append(q[keep][sel])
                cols.append(np.broadcast_to((node[keep] * d + comp)[:, None],
                                            (keep.sum(), nq_ref))[sel])
                vals.append(np.ones(sel.sum()))
            else:
                # (direction_q · R_a e_c) φ_a(x_q) for every c
                for c in range(d):
                    proj = np.einsum("fqi,fi->fq",
                                     directions[:, :, comp].reshape(nf, nq_ref, d)[keep],
                                     frame[node[keep], :, c])
                    rows.append(q[keep].ravel())
                    cols.append(np.broadcast_to((node[keep] * d + c)[:, None],
                                                (keep.sum(), nq_ref)).ravel())
                    vals.append((proj * phi[keep]).ravel())
        traces.append(sp.csr_matrix((np.concatenate(vals),
                                     (np.concatenate(rows), np.concatenate(cols))),
                                    shape=(nf * nq_ref, nz)))

    node_weights = np.zeros(mesh.p.shape[1])
    for v in range(d):
        np.add.at(node_weights, facet_nodes[v], measure / d)
    return ContactBoundary(
        dim=d, facets=facets, facet_nodes=facet_nodes, measure=measure, nodes=nodes,
        frame=frame, dofs=dofs, weights=weights, facet_of_point=facet_of_point,
        points=points, normal_trace=traces[0], tangential_trace=traces[1:],
        node_weights=node_weights[nodes],
        point_node=(local[facet_nodes.T].ravel() if quadrature == "nodal"
                    else np.full(nf * nq_ref, -1)),
        held_axes=held_axes, held=held, frame_dofs=frame_dofs,
        rotated=~held_axes.all(axis=1),
        held_positions=np.searchsorted(held_dofs, dofs[held_axes]))


def held_frames(frame, held_axes, dofs):
    """The frames of the contact nodes with their held components.

    Parameters
    ----------
    frame : (nc, d, d) the frames of the averaged normals
    held_axes : (nc, d) bool, the held Cartesian components
    dofs : (nc, d) the nodes' dofs

    Returns ``(frame, held, frame_dofs)`` (the attributes of
    :class:`ContactBoundary`). A clamped node (every component held)
    keeps its frame. A node with some components held gets the frame
    nearest to its own in which each held axis e_h is a frame vector: ν_a
    projected off the held axes (the held components then tangential), or
    ±e_h for the held axis h with the largest |ν_a · e_h| (the held
    component u_h is then ∓u_ν), whichever is closer to ν_a; its frame
    component along e_h is held and placed at the dof of u_h, its free
    components at the node's other dofs (in order).
    """
    nc, d = held_axes.shape
    frame = frame.copy()
    held = np.broadcast_to(held_axes.all(axis=1)[:, None], (nc, d)).copy()
    frame_dofs = dofs.copy()
    partial = np.flatnonzero(held_axes.any(axis=1) & ~held_axes.all(axis=1))
    if partial.size == 0:
        return frame, held, frame_dofs
    rows = np.arange(partial.size)
    H = held_axes[partial]                          # (np, d)
    nu = frame[partial, :, 0]                       # (np, d)
    off = np.where(H, 0.0, nu)                      # ν off the held axes
    off_norm = np.linalg.norm(off, axis=1)
    along = np.where(H, np.abs(nu), -1.0)
    axis = np.argmax(along, axis=1)                 # the held axis nearest to ν
    use_axis = along[rows, axis] > off_norm
    normal = np.where(use_axis[:, None],
                      np.eye(d)[axis] * np.sign(nu[rows, axis])[:, None],
                      off / np.where(off_norm > 0, off_norm, 1.0)[:, None])
    new = tangent_frame(normal.T)                   # (np, d, d)
    if d == 3:
        # ν off a single held axis e_h need not be an axis: τ = e_h, τ' = ν × e_h
        # (where tangent_frame did not already give e_h)
        single = ~use_axis & (H.sum(axis=1) == 1)
        h = np.argmax(H, axis=1)
        missing = single & (np.abs(new[rows, h, 1:]).max(axis=1) < 1.0 - 1e-12)
        if missing.any():
            e = np.eye(d)[h[missing]]
            new[missing, :, 1] = e
            new[missing, :, 2] = np.cross(normal[missing], e)
    component = np.argmax(np.abs(new), axis=2)      # (np, d): the frame component along e_i
    a, h = np.nonzero(H)
    c = component[a, h]
    assert np.all(np.abs(new[a, h, c]) > 1.0 - 1e-9), "a held axis is not a frame vector"
    # exactly ±e_h (round-off of the cross products), the other columns renormalised
    sign = np.sign(new[a, h, c])
    new[a, h, :] = 0.0
    new[a, :, c] = 0.0
    new[a, h, c] = sign
    new /= np.linalg.norm(new, axis=1, keepdims=True)
    frame[partial] = new
    held[partial] = False
    held[partial[a], c] = True
    # each held component keeps the dof of its axis; the free ones take the rest in order
    axis_of = np.full((partial.size, d), -1)
    axis_of[a, c] = h
    free_comps = np.argsort(held[partial], axis=1, kind="stable")   # free components first
    free_axes = np.argsort(H, axis=1, kind="stable")                # free axes first
    nfree = (~H).sum(axis=1)
    for j in range(d):
        take = j < nfree
        axis_of[rows[take], free_comps[take, j]] = free_axes[take, j]
    frame_dofs[partial] = dofs[partial[:, None], axis_of]
    return frame, held, frame_dofs
