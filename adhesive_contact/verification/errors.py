"""Errors of docs/verification.md and the nested prolongation they use.

Errors are measured as in the estimates: e_u(t_n) = ‖ε(u(t_n) − u_n^h)‖_{L²(Ω)},
e_β(t_n) = ‖β(t_n) − β_n^h‖_{L²(Γ_C)}, E_n = e_u + e_β, and each reported as
its maximum over the common time grid.

Against a finer discrete reference, coarse solutions are carried to the
fine mesh exactly: meshes of one scene at refine r and r + 1 are nested
(``refined()`` keeps the coarse vertices first and adds one per coarse edge,
in edge order), so P1 prolongation is the identity on old vertices and the
mean of the two ends on each new one, and a fine contact facet inherits
the P0 value of the coarse facet it refines (in 2D and 3D; for a file
mesh the new vertices are chord midpoints: a curved side is not
re-projected, so the levels approximate the coarse mesh's polygon). The fine strain is constant per
fine cell, so the error integral is exact with one point.

Against an exact solution, ε(u*) is integrated with a cell rule of
exactness 4 and β* with a facet rule of exactness 6 — both well above
what a first-order rate can see.
"""

from dataclasses import replace

import numpy as np
import scipy.sparse as sp
from skfem import Basis
from skfem.quadrature import get_quadrature

from ..fem.assembly import vector_element
from ..fem.contact_boundary import facet_points
from ..expressions import coordinates
from ..fem.meshes import build_mesh, refinement_parents


def _one_level(coarse, fine):
    """Prolongation (n_fine × n_coarse) between meshes one refinement apart."""
    nc, nf = coarse.p.shape[1], fine.p.shape[1]
    edges = coarse.facets if coarse.dim() == 2 else coarse.edges
    if nf != nc + edges.shape[1]:
        raise ValueError("meshes are not one uniform refinement apart")
    new = np.arange(nc, nf)
    rows = np.concatenate([np.arange(nc), new, new])
    cols = np.concatenate([np.arange(nc), edges[0], edges[1]])
    vals = np.concatenate([np.ones(nc), np.full(2 * new.size, 0.5)])
    P = sp.csr_matrix((vals, (rows, cols)), shape=(nf, nc))
    if not np.allclose(P @ coarse.p.T, fine.p.T, rtol=0, atol=1e-12 * np.abs(coarse.p).max()):
        raise ValueError("meshes are not nested")
    return P


def nested_meshes(mesh_spec, levels):
    """The meshes of ``mesh_spec`` refined 0..levels more times."""
    return [build_mesh(replace(mesh_spec, refine=mesh_spec.refine + r))
            for r in range(levels + 1)]


def prolongation(meshes):
    """P1 prolongation from meshes[0] to meshes[-1] (points × points)."""
    P = sp.identity(meshes[0].p.shape[1], format="csr")
    for coarse, fine in zip(meshes[:-1], meshes[1:]):
        P = _one_level(coarse, fine) @ P
    return P.tocsr()


def facet_parents(meshes, coarse_facets, fine_facets):
    """For each fine contact facet, its position in ``coarse_facets``.

    A fine boundary facet lies in one coarse facet: the one spanned by the
    coarse vertices its vertices come from
    (:func:`~adhesive_contact.fem.meshes.refinement_parents`), in 2D and 3D.
    """
    parent = np.asarray(fine_facets)
    for coarse, fine in zip(meshes[-2::-1], meshes[:0:-1]):
        parent = refinement_parents(coarse, fine, parent)
        if np.any(parent < 0):
            raise ValueError("a fine contact facet lies in no coarse facet: meshes not nested")
    position = np.full(meshes[0].facets.shape[1], -1)
    position[coarse_facets] = np.arange(len(coarse_facets))
    out = position[parent]
    if np.any(out < 0):
        raise ValueError("a fine contact facet does not lie on a coarse contact facet")
    return out


def strain_error_fine(mesh, strain_map, du):
    """‖ε(du)‖_{L²(Ω)} for a P1 field du on ``mesh`` (exact: ε is constant per cell)."""
    d = mesh.dim()
    eps = (strain_map @ du).reshape(-1, d, d)
    vol = cell_volumes(mesh)
    return float(np.sqrt(np.sum(vol * np.sum(eps * eps, axis=(1, 2)))))


def cell_volumes(mesh):
    p = mesh.p[:, mesh.t]
    d = mesh.dim()
    J = np.stack([p[:, i + 1] - p[:, 0] for i in range(d)], axis=1)  # (d, d, ncells)
    return np.abs(np.linalg.det(J.transpose(2, 0, 1))) / (2.0 if d == 2 else 6.0)


class ExactErrors:
    """Errors against an exact solution on one mesh: fixed quadrature points."""

    def __init__(self, problem, strain, beta, cell_order=4, facet_order=6):
        mesh = problem.mesh
        d = mesh.dim()
        elem = vector_element(d)
        basis = Basis(mesh, elem, quadrature=get_quadrature(elem.refdom, cell_order))
        self.x = np.asarray(basis.global_coordinates())           # (d, ncells, nq)
        self.dx = np.asarray(basis.dx)                              # (ncells, nq)
        self.strain_of = strain                                     # (x..., t) -> (d, d, ...)
        self.assembly = problem.assembly
        self.boundary = problem.boundary
        self.beta_of = beta
        if problem.boundary is not None and beta is not None:
            pts, weights = facet_points(mesh, problem.boundary.facet_nodes, "gauss",
                                        facet_order)
            self.facet_x = pts                                      # (d, nf, nq)
            self.facet_w = problem.boundary.measure[:, None] * weights[None, :]

    def strain(self, u, t):
        """‖ε(u*(t)) − ε(u_h)‖_{L²(Ω)} with u a dof vector."""
        eh = self.assembly.cell_strain(u)                           # (ncells, d, d)
        ex = self.strain_of(*coordinates(self.x), t=t)              # (d, d, ncells, nq)
        diff = ex - eh.transpose(1, 2, 0)[:, :, :, None]
        return float(np.sqrt(np.sum(self.dx * np.sum(diff * diff, axis=(0, 1)))))

    def bonding(self, beta_h, t):
        """‖β*(t) − β_h‖_{L²(Γ_C)} with β_h per contact facet."""
        if self.boundary is None or self.beta_of is None:
            return 0.0
        diff = self.beta_of(*coordinates(self.facet_x), t=t) - beta_h[:, None]
        return float(np.sqrt(np.sum(self.facet_w * diff * diff)))
