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

Two paths build the same operators (:func:`choose_path`, recorded as
:attr:`Assembly.path`): the vectorised kernels of
:mod:`~adhesive_contact.fem.p1` for P1 on straight-sided triangles and
tetrahedra (every scene), and scikit-fem's assembly of the forms of
:mod:`~adhesive_contact.fem.forms` for any other element or mesh, the
reference the kernels are tested equal to (to round-off).
"""

from math import factorial

import numpy as np
import scipy.sparse as sp
from skfem import (
    Basis,
    ElementTetP0,
    ElementTetP1,
    ElementTriP0,
    ElementTriP1,
    ElementVector,
    FacetBasis,
    asm,
)
from skfem.quadrature import get_quadrature

from ..expressions import coordinates
from . import forms
from .p1 import CellLoad, gradients, stiffness_parts, strain_operator, symmetric_pairs

#: the ways to build the bulk operators: ``auto`` chooses (:func:`choose_path`)
BULK_PATHS = ("auto", "kernels", "forms")


def vector_element(dim):
    return ElementVector(ElementTriP1() if dim == 2 else ElementTetP1())


def stiffness_basis(mesh):
    """Vector P1 basis with the one-point rule (exact for P1 stiffness)."""
    elem = vector_element(mesh.dim())
    return Basis(mesh, elem, quadrature=get_quadrature(elem.refdom, 0))


def choose_path(mesh, element=None, asked="auto"):
    """How the bulk operators of ``element`` (a scalar scikit-fem element,
    None for P1) on ``mesh`` are built: ``(path, reason)``, path "kernels"
    or "forms" and a sentence saying why.

    The kernels of :mod:`~adhesive_contact.fem.p1` hold only for P1 on
    straight-sided triangles or tetrahedra (constant gradients per cell),
    and build the two isotropic parts K_λ, K_μ; ``auto`` takes them there
    and the forms of :mod:`~adhesive_contact.fem.forms` everywhere else.
    ``asked`` = "kernels" where they do not hold is refused (ValueError)."""
    if asked not in BULK_PATHS:
        raise ValueError(f"bulk path {asked!r}: allowed are "
                         + ", ".join(repr(p) for p in BULK_PATHS))
    simplex = {2: (ElementTriP1, "triangles"), 3: (ElementTetP1, "tetrahedra")}.get(mesh.dim())
    kind = type(element).__name__ if element is not None else "P1"
    applies = (simplex is not None and mesh.elem is simplex[0]
               and (element is None or type(element) is simplex[0]))
    if asked == "forms":
        return "forms", f"the forms were asked for ({kind} on {type(mesh).__name__})."
    if applies:
        return "kernels", (f"P1 on straight-sided {simplex[1]}, an isotropic tensor: the "
                           "vectorised P1 kernels.")
    if asked == "kernels":
        raise ValueError(f"bulk path 'kernels' holds only for P1 on straight-sided triangles "
                         f"or tetrahedra, not {kind} on {type(mesh).__name__}; use 'auto' or "
                         "'forms'")
    return "forms", (f"{kind} on {type(mesh).__name__}: the P1 kernels do not apply, "
                     "scikit-fem assembles the forms.")


def exact_rule(refdom, degree):
    """A quadrature rule on ``refdom`` exact for polynomials of ``degree``;
    for degree 0 the one point at the centroid (scikit-fem's lowest rule
    on a triangle has three)."""
    if degree > 0:
        return get_quadrature(refdom, degree)
    return refdom.p.mean(axis=1)[:, None], np.array([1.0 / factorial(refdom.dim())])


def form_basis(mesh, element=None):
    """The vector basis of the forms path: ``element`` (None: P1) in each
    component, with a rule exact for the stiffness of an affine mesh
    (degree 2 (p − 1), the product of two gradients of degree p − 1;
    scikit-fem's default 2 p on a curved mesh)."""
    scalar = element if element is not None else (ElementTriP1() if mesh.dim() == 2
                                                  else ElementTetP1())
    elem = ElementVector(scalar)
    if not mesh.affine:
        return Basis(mesh, elem)
    return Basis(mesh, elem, quadrature=exact_rule(elem.refdom, 2 * (elem.maxdeg - 1)))


def assembled(form, basis):
    """The CSR matrix of a bilinear form on ``basis``: scikit-fem's
    elemental matrices summed, every pair of dofs of a cell kept, zero or
    not (:func:`skfem.asm` drops the zeros), so that the pattern is the
    kernels' and a linear backend orders and sizes both alike."""
    local = form.elemental(basis)
    rows, cols = local.indices
    A = sp.coo_matrix((local.data, (rows, cols)), shape=local.shape).tocsr()
    A.sort_indices()
    return A


def form_strain_operator(basis, pairs):
    """Sparse B (ne·len(pairs), ndofs) from the forms: (B u) reshaped
    (ne, len(pairs)) is the mean of ε(u) over each cell at the entries
    (b, c) of ``pairs``, the L² projection onto P0,

        mean_e ε_bc(u) = |e|⁻¹ (ε_bc(u), q_e)_e,

    q_e the indicator of cell e (:func:`~.forms.strain_entry` over
    :func:`~.forms.cell_measure`); for P1 the constant strain of the cell,
    as :func:`~adhesive_contact.fem.p1.strain_operator`. ``basis`` is a
    vector basis whose rule integrates ε(u) exactly."""
    cells = basis.with_element(ElementTriP0() if basis.mesh.dim() == 2 else ElementTetP0())
    inverse_measure = sp.diags(1.0 / asm(forms.cell_measure, cells).diagonal())
    entries = [inverse_measure @ asm(forms.strain_entry(b, c), basis, cells) for b, c in pairs]
    ne, m = basis.mesh.t.shape[1], len(pairs)
    order = (np.arange(m)[None, :] * ne + np.arange(ne)[:, None]).ravel()   # row (e, k)
    B = sp.vstack(entries, format="csr")[order]
    B.eliminate_zeros()
    B.sort_indices()
    return B


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


class FormLoad:
    """⟨f, v⟩ on a cell or facet basis by the form :data:`~.forms.load`,
    assembled from f at the basis's quadrature points ``points`` (d, ne·nq)
    at each call (the forms path: any element)."""

    def __init__(self, basis):
        self.basis = basis
        self.points = np.asarray(basis.global_coordinates()).reshape(basis.mesh.dim(), -1)
        self.anchor = self.points[:, :1]

    def __call__(self, values):
        d = self.points.shape[0]
        f = np.broadcast_to(np.asarray(values, dtype=float).reshape(d, -1),
                            self.points.shape).reshape(d, *self.basis.dx.shape)
        return asm(forms.load, self.basis, f=f)


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

    ``assembly``: the :class:`Assembly` whose path (and element) the loads
    follow; None, or its path "kernels": :class:`CellLoad` and
    :class:`SurfaceLoad`; "forms": :class:`FormLoad` on both.
    """

    def __init__(self, mesh, body, surface, intorder=None, assembly=None):
        intorder = LOAD_INTORDER if intorder is None else intorder
        d = mesh.dim()
        if assembly is not None and assembly.path == "forms":
            elem = assembly.basis.elem
            cell_load = (FormLoad(Basis(mesh, elem, intorder=intorder))
                         if body is not None else None)
            surface_load = FormLoad
        else:
            elem = vector_element(d)
            cell_load = CellLoad(mesh, intorder) if body is not None else None
            surface_load = SurfaceLoad
        self.parts = []
        if body is not None:
            self.parts.append((body, cell_load))
        for facets, field in surface:
            load = surface_load(FacetBasis(mesh, elem, facets=facets, intorder=intorder))
            self.parts.append((field, load))
        self.ndofs = d * mesh.p.shape[1] if assembly is None else assembly.ndofs

    def __call__(self, t):
        f = np.zeros(self.ndofs)
        for field, load in self.parts:
            if hasattr(load, "uniform") and not getattr(field, "depends_on_space", True):
                f += load.uniform(field(*coordinates(load.anchor), t=t)[:, 0])
            else:
                f += load(field(*coordinates(load.points), t=t))
        return f


class Assembly:
    """The per-mesh operators of the fully discrete scheme: the stiffness
    parts K_λ, K_μ and the strain map, by the path :func:`choose_path`
    takes for ``element`` (a scalar scikit-fem element, None for P1) on
    ``mesh`` (``path``: "auto", "kernels" or "forms"):

    - "kernels": the vectorised P1 kernels of :mod:`adhesive_contact.fem.p1`,
      K_λ and K_μ as block (BSR) matrices on one pattern;
    - "forms": scikit-fem's assembly of :mod:`adhesive_contact.fem.forms`
      (:data:`~.forms.divergence_product`, :data:`~.forms.strain_product`,
      the strain's cell means), on :attr:`basis`.

    Both give the same matrices to round-off (tests/test_forms.py).
    ``path`` and ``reason`` say which was taken and why (:attr:`record`)."""

    def __init__(self, mesh, element=None, path="auto"):
        self.mesh = mesh
        self.dim = mesh.dim()
        self.path, self.reason = choose_path(mesh, element, path)
        self.pairs, self.full = symmetric_pairs(self.dim)
        self.diagonal = [self.pairs.index((a, a)) for a in range(self.dim)]
        if self.path == "kernels":
            self.basis = None
            geometry = gradients(mesh)   # the barycentric gradients, shared
            self.K_lam, self.K_mu = stiffness_parts(mesh, geometry)
            self.strain = strain_operator(mesh, geometry)   # the entries b ≤ c of ε
        else:
            self.basis = form_basis(mesh, element)
            self.K_lam = assembled(forms.divergence_product, self.basis)
            self.K_mu = assembled(forms.strain_product, self.basis)
            assert (np.array_equal(self.K_lam.indptr, self.K_mu.indptr)
                    and np.array_equal(self.K_lam.indices, self.K_mu.indices))
            self.strain = form_strain_operator(self.basis, self.pairs)

    @property
    def record(self):
        """{"path", "reason"}: how the bulk operators were built."""
        return {"path": self.path, "reason": self.reason}

    @property
    def ndofs(self):
        return self.K_lam.shape[0]

    @property
    def nodal_dofs(self):
        """(d, npoints): the dof of component c at node a, d·a + c (the
        interleaved numbering of scikit-fem's vector elements; an element
        with more than the vertex dofs numbers those first)."""
        if self.basis is not None:
            return self.basis.nodal_dofs
        return np.arange(self.ndofs).reshape(-1, self.dim).T

    def stiffness(self, lam, mu):
        """λ K_λ + μ K_μ (CSR), the stiffness of the isotropic tensor (λ, μ):
        the two share their pattern (the kernels' blocks, the forms' every
        pair of dofs of a cell), so their data are combined and converted
        once."""
        K_lam, K_mu = self.K_lam, self.K_mu
        kind = sp.bsr_matrix if self.path == "kernels" else sp.csr_matrix
        return kind((lam * K_lam.data + mu * K_mu.data, K_lam.indices, K_lam.indptr),
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
