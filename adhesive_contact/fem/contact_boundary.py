"""Γ_C: the contact facets, their nodes, frames, quadrature and P0 fields.

This module owns everything the contact laws see. The contact unknowns are
the displacements of the contact nodes (the nodes of Γ_C that are not
clamped) written in a local orthonormal frame per node,

    u_a = R_a z_a,   R_a = [ν_a, τ_a (, τ'_a)],

so that z_{a,0} = u_ν(x_a) and the wall u_ν ≤ g of K^h (docs/scheme.md) is a
bound on one coordinate. ν_a is the length-weighted average of the outward
normals of the facets around node a.

Contact integrals ∫_{Γ_C} φ(β, u_ν, u_τ) are replaced by a quadrature
Σ_q w_q φ(β_{f(q)}, (N z)_q, (T z)_q) over points q of the contact facets,
with β the P0 value of the facet f(q) holding q:

- ``nodal`` (the default, docs/scenes.md): the trapezoid rule on each facet, its
  points being the facet's vertices (weights |f|/d each) and u_ν, u_τ being
  the nodal components z_a; the terms then split node by node;
- ``gauss``: a Gauss rule of the given exactness on each facet, with u the
  P1 interpolant and ν, τ the facet's own normal and tangents.
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
    nodes : (nc,) contact nodes (vertices of Γ_C not on Γ_D)
    frame : (nc, d, d) the local frames R_a
    dofs : (nc, d) global dofs of the contact nodes (Cartesian components)
    weights : (nq,) quadrature weights w_q on Γ_C
    facet_of_point : (nq,) the facet holding each quadrature point
    points : (d, nq) the quadrature points
    normal_trace : (nq, nz) sparse N, z -> u_ν at the points
    tangential_trace : list of d-1 sparse (nq, nz), z -> u_τ components
    node_weights : (nc,) lumped nodal weights ∫ φ_a over Γ_C
    point_node : (nq,) contact node read by each point of the nodal rule
        (−1 for a clamped vertex, and for every point of a Gauss rule)
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

    def rotation(self, ndofs):
        """Sparse R (ndofs × ndofs): u = R ũ with ũ the nodal-frame components
        at the contact nodes and the Cartesian ones elsewhere (R orthogonal)."""
        nc, d = self.nodes.size, self.dim
        other = np.setdiff1d(np.arange(ndofs), self.dofs.ravel())
        rows = np.broadcast_to(self.dofs[:, :, None], (nc, d, d))  # (a, i, c): R[dof_ai, dof_ac]
        cols = np.broadcast_to(self.dofs[:, None, :], (nc, d, d))
        return sp.csr_matrix((np.concatenate([self.frame.ravel(), np.ones(other.size)]),
                              (np.concatenate([rows.ravel(), other]),
                               np.concatenate([cols.ravel(), other]))), shape=(ndofs, ndofs))

    def unknowns(self, components):
        """Indices (node-major, nc·d) of the given frame components of every node."""
        comps = np.asarray(components)
        return (np.arange(self.nodes.size)[:, None] * self.dim + comps[None, :]).ravel()

    def at_points(self, facet_values):
        """A P0 field (nf,) read at the quadrature points (nq,)."""
        return facet_values[self.facet_of_point]

    def facet_mean(self, point_values):
        """P_B: the facet means (nf,) of values (nq,) given at the points."""
        return np.bincount(self.facet_of_point, self.weights * point_values,
                           minlength=self.facets.size) / self.measure


def build_contact_boundary(mesh, contact_facets, clamped_nodes, quadrature="nodal", order=4):
    """Assemble :class:`ContactBoundary` for the given facets of ``mesh``."""
    d = mesh.dim()
    facets = np.asarray(contact_facets, dtype=np.int64)
    facet_nodes = mesh.facets[:, facets]
    normal_f, measure = facet_normals(mesh, facets)
    nodes = np.setdiff1d(np.unique(facet_nodes), clamped_nodes)
    local = np.full(mesh.p.shape[1], -1)
    local[nodes] = np.arange(nodes.size)

    # averaged nodal normals (weighted by |f|)
    acc = np.zeros((d, mesh.p.shape[1]))
    for i in range(d):
        np.add.at(acc.T, facet_nodes[i], (normal_f * measure).T)
    nodal_normal = acc[:, nodes] / np.linalg.norm(acc[:, nodes], axis=0)
    frame = tangent_frame(nodal_normal)
    dofs = np.stack([d * nodes + c for c in range(d)], axis=1)  # interleaved dofs

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
        directions = np.repeat(tangent_frame(normal_f), nq_ref, axis=0)  # (nq, d, d)

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
                    else np.full(nf * nq_ref, -1)))
