"""Everything assembled once per mesh: stiffness parts, load and strain maps.

An isotropic tensor C ε = λ tr(ε) I + 2 μ ε has the stiffness
λ K_λ + μ K_μ with

    K_λ = ∫_Ω div u div v,        K_μ = ∫_Ω 2 ε(u) : ε(v),

so the elastic tensor A, the memory tensors C_m and the step matrix
a_n = A + k R(0) of docs/scheme.md ('What a step solves') are all combinations of two matrices
assembled once. Loads ⟨f(t), v⟩ = (f_0, v)_Ω + (f_N, v)_{Γ_N} are the
load expressions evaluated at fixed quadrature points and contracted with
the test functions' values there (:class:`~adhesive_contact.fem.p1.CellLoad`
in Ω, a fixed sparse map on Γ_N), so a step costs one evaluation and one
contraction; a body force constant in space costs neither.
"""

import numpy as np
import scipy.sparse as sp
from skfem import (
    Basis,
    ElementTetP1,
    ElementTriP1,
    ElementVector,
    FacetBasis,
)
from skfem.quadrature import get_quadrature

from ..expressions import coordinates
from .p1 import CellLoad, gradients, stiffness_parts, strain_operator, symmetric_pairs


def vector_element(dim):
    return ElementVector(ElementTriP1() if dim == 2 else ElementTetP1())


def stiffness_basis(mesh):
    """Vector P1 basis with the one-point rule (exact for P1 stiffness)."""
    elem = vector_element(mesh.dim())
    return Basis(mesh, elem, quadrature=get_quadrature(elem.refdom, 0))


def quadrature_load_map(basis):
    """Sparse maps M_c with ⟨f, v⟩ = Σ_c M_c f_c(x_q) and the points x_q.

    ``basis`` is a vector (cell or facet) basis; column e·nqp + q of M_c
    holds φ_{i,c}(x_{eq}) dx_{eq} for the local dofs i of element e.
    """
    d = basis.mesh.dim()
    ne, nqp = basis.dx.shape
    cols = np.arange(ne * nqp).reshape(ne, nqp)
    maps = []
    for c in range(d):
        rows, vals, cc = [], [], []
        for i in range(basis.element_dofs.shape[0]):
            value = np.asarray(basis.basis[i][0])[c] * basis.dx
            rows.append(np.broadcast_to(basis.element_dofs[i][:, None], (ne, nqp)).ravel())
            cc.append(cols.ravel())
            vals.append(value.ravel())
        m = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cc))),
                          shape=(basis.N, ne * nqp))
        m.eliminate_zeros()
        maps.append(m)
    points = np.asarray(basis.global_coordinates()).reshape(d, -1)
    return maps, points


def strain_map(basis):
    """Sparse B with (B u) reshaped (ncells, d, d) the cell strains ε(u).

    ``basis`` must use a one-point rule (P1 strains are constant per cell).
    """
    d = basis.mesh.dim()
    ne = basis.mesh.t.shape[1]
    rows, cols, vals = [], [], []
    for i in range(basis.element_dofs.shape[0]):
        grad = basis.basis[i][0].grad[..., 0]  # (d, d, ne): ∂_b u_a
        eps = 0.5 * (grad + grad.transpose(1, 0, 2))
        for a in range(d):
            for b in range(d):
                rows.append(np.arange(ne) * d * d + a * d + b)
                cols.append(basis.element_dofs[i])
                vals.append(eps[a, b])
    B = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(ne * d * d, basis.N))
    B.eliminate_zeros()
    return B


class vector_of:
    """A vector field f(x, y, z, t) -> (d, ...) from d scalar expressions
    (a class rather than a closure, so that a Problem pickles)."""

    def __init__(self, expressions):
        self.expressions = tuple(expressions)

    def __call__(self, x, y=None, z=None, t=0.0):
        return np.stack([e(x, y, z, t=t) for e in self.expressions])

    @property
    def depends_on_space(self):
        """True if a component uses x, y or z."""
        return any(e.depends_on_space for e in self.expressions)


def is_zero(expressions):
    return all(e.is_constant and float(e(0.0)) == 0.0 for e in expressions)


#: the exactness of the rules on which LoadMap evaluates loads
LOAD_INTORDER = 4


class SurfaceLoad:
    """⟨f, v⟩ on facets: Σ_c M_c f_c(x_q) with the sparse maps M_c of
    :func:`quadrature_load_map`, at its points ``points``."""

    def __init__(self, basis):
        self.maps, self.points = quadrature_load_map(basis)
        self.anchor = self.points[:, :1]

    def __call__(self, values):
        return sum(m @ v for m, v in zip(self.maps, values))


class LoadMap:
    """t -> ⟨f(t), ·⟩: body forces and surface loads evaluated at fixed points.

    Parameters
    ----------
    mesh : skfem mesh
    body : vector field f_0(x, y, z, t) -> (d, ...), or None
    surface : list of (facets, vector field) pairs (tractions f_N on Γ_N
        sides, and the manufactured load f_C on Γ_C)

    ``parts`` lists (field, load) pairs: ``load`` maps the field's values
    at ``load.points`` (d, nq) to the load vector. A body force whose
    expressions do not use x, y, z (``field.depends_on_space`` False) is evaluated
    at one point and spread by ∫_Ω φ_i (:meth:`CellLoad.uniform`): exact,
    and the cells' points are never made.
    """

    def __init__(self, mesh, body, surface, intorder=None):
        intorder = LOAD_INTORDER if intorder is None else intorder
        d = mesh.dim()
        elem = vector_element(d)
        self.parts = []
        if body is not None:
            self.parts.append((body, CellLoad(mesh, intorder)))
        for facets, field in surface:
            load = SurfaceLoad(FacetBasis(mesh, elem, facets=facets, intorder=intorder))
            self.parts.append((field, load))
        self.ndofs = d * mesh.p.shape[1]

    def __call__(self, t):
        f = np.zeros(self.ndofs)
        for field, load in self.parts:
            if isinstance(load, CellLoad) and not getattr(field, "depends_on_space", True):
                f += load.uniform(field(*coordinates(load.anchor), t=t)[:, 0])
            else:
                f += load(field(*coordinates(load.points), t=t))
        return f


class Assembly:
    """The per-mesh operators of the fully discrete scheme, from the
    vectorised P1 kernels of :mod:`adhesive_contact.fem.p1` (the forms above
    give the same matrices; a test compares them)."""

    def __init__(self, mesh):
        self.mesh = mesh
        self.dim = mesh.dim()
        geometry = gradients(mesh)   # the barycentric gradients, shared
        self.K_lam, self.K_mu = stiffness_parts(mesh, geometry)
        self.strain = strain_operator(mesh, geometry)   # the entries b ≤ c of ε
        self.pairs, self.full = symmetric_pairs(self.dim)
        self.diagonal = [self.pairs.index((a, a)) for a in range(self.dim)]

    @property
    def ndofs(self):
        return self.dim * self.mesh.p.shape[1]

    @property
    def nodal_dofs(self):
        """(d, npoints): the dof of component c at node a, d·a + c (the
        interleaved numbering of scikit-fem's vector elements)."""
        return np.arange(self.ndofs).reshape(-1, self.dim).T

    def stiffness(self, lam, mu):
        """λ K_λ + μ K_μ (CSR), the stiffness of the isotropic tensor (λ, μ):
        the two share their block pattern, so their data are combined and
        converted once."""
        K_lam, K_mu = self.K_lam, self.K_mu
        return sp.bsr_matrix((lam * K_lam.data + mu * K_mu.data, K_lam.indices, K_lam.indptr),
                             shape=K_lam.shape).tocsr()

    def force(self, lam_field, mu_field):
        """K_λ a + K_μ b: the force of the stress tr ε(a) I + 2 ε(b)."""
        return self.K_lam @ lam_field + self.K_mu @ mu_field

    def _strain_entries(self, u):
        """ε(u) per cell at the entries b ≤ c, (ncells, d(d+1)/2)."""
        return (self.strain @ u).reshape(-1, len(self.pairs))

    def cell_strain(self, u):
        """ε(u) per cell, shape (ncells, d, d)."""
        return self._strain_entries(u)[:, self.full].reshape(-1, self.dim, self.dim)

    def cell_stress(self, lam_field, mu_field):
        """σ = tr ε(a) I + 2 ε(b) per cell (ncells, d, d), and tr ε(a) (ncells,):
        in plane strain (ε_zz = 0) the latter is σ_zz."""
        tr = self._strain_entries(lam_field)[:, self.diagonal].sum(axis=1)
        stress = 2.0 * self._strain_entries(mu_field)
        stress[:, self.diagonal] += tr[:, None]
        return stress[:, self.full].reshape(-1, self.dim, self.dim), tr
