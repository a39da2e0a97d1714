"""The bulk terms of the scheme as scikit-fem forms: the reference path.

Each form is the integrand of a term of the weak form (2.2) of
docs/model.md, or of the step (4.1) of docs/scheme.md, as scikit-fem
assembles it on any element and mesh (``u``, ``v`` the trial and test
functions, ``w`` the fields given to :func:`skfem.asm`):

- the elastic term (A ε(u), ε(v))_Ω and the memory's (C_m ε(u), ε(v))_Ω
  of a linear stress map, :func:`elasticity`; for the isotropic tensors of
  the scenes, C ε = λ tr(ε) I + 2 μ ε (1.1), the two parts
  :data:`divergence_product` (K_λ) and :data:`strain_product` (K_μ), of which
  every tensor the scheme meets (A, k R(0), A + k R(0), the C_m) is a
  combination;
- the load ⟨f(t), v⟩ = (f_0, v)_Ω + (f_N, v)_{Γ_N} of (2.2), :data:`load`,
  on a cell basis (the body force) or a facet basis (a traction);
- the cell means of the strain, :func:`strain_entry` over
  :data:`cell_measure` (the L² projection of ε(u) onto P0), which the
  stresses and the strain errors are made of.

:class:`~adhesive_contact.fem.assembly.Assembly` assembles these wherever
the vectorised P1 kernels of :mod:`adhesive_contact.fem.p1` do not apply,
and a test holds the kernels to them.
"""

from skfem import BilinearForm, LinearForm
from skfem.helpers import ddot, div, dot, eye, sym_grad, trace


@BilinearForm
def divergence_product(u, v, w):
    """K_λ: (div u, div v)_Ω, the part of (A ε(u), ε(v))_Ω (2.2) that λ
    multiplies for an isotropic tensor (tr ε(u) = div u)."""
    return div(u) * div(v)


@BilinearForm
def strain_product(u, v, w):
    """K_μ: 2 (ε(u), ε(v))_Ω, the part of (A ε(u), ε(v))_Ω (2.2) that μ
    multiplies for an isotropic tensor."""
    return 2.0 * ddot(sym_grad(u), sym_grad(v))


def isotropic_stress(lam, mu):
    """The isotropic stress map of (1.1), C ε = λ tr(ε) I + 2 μ ε."""

    def stress(strain):
        return lam * eye(trace(strain), strain.shape[0]) + 2.0 * mu * strain

    return stress


def elasticity(stress):
    """The bilinear form (C ε(u), ε(v))_Ω of a linear stress map
    ``stress``: ε ↦ C ε (a function of the strain at the quadrature points,
    shape (d, d, ...)): the elastic term of (2.2) with C = A, a memory
    term with C = C_m. ``elasticity(isotropic_stress(λ, μ))`` is
    λ K_λ + μ K_μ; an anisotropic material is its own ``stress``."""

    @BilinearForm
    def form(u, v, w):
        return ddot(stress(sym_grad(u)), sym_grad(v))

    return form


@LinearForm
def load(v, w):
    """(f, v): on a cell basis the body force (f_0, v)_Ω, on a facet basis
    a traction (f_N, v)_{Γ_N}, the two parts of ⟨f(t), v⟩ in (2.2); ``w.f``
    holds f at the basis's quadrature points, (d, elements, points)."""
    return dot(w.f, v)


def strain_entry(b, c):
    """The mixed form (ε_bc(u), q)_e of a vector field u and a test
    function q piecewise constant on the cells (P0): its row for cell e is
    ∫_e ε_bc(u), |e| times the cell mean of ε_bc = ½ (∂_c u_b + ∂_b u_c)."""

    @BilinearForm
    def form(u, q, w):
        return sym_grad(u)[b, c] * q

    return form


@BilinearForm
def cell_measure(p, q, w):
    """(p, q)_Ω on P0: the diagonal matrix of the cell measures |e|, the
    mass matrix of the L² projection onto P0 (cell means)."""
    return p * q
