"""What a run builds once per mesh and step size.

The system is written in the nodal frames of Γ_C, ũ = Rᵀ u
(:meth:`~adhesive_contact.fem.contact_boundary.ContactBoundary.rotation`), and
restricted to the free dofs; the held dofs (at a contact node ũ = ±u
there, the sign of R's diagonal; elsewhere not rotated) enter through the
coupling block a_FD, built once per step matrix. Two step matrices serve the whole run
(:mod:`adhesive_contact.scheme.condensed`):

- a_n = A + k R(0) for n ≥ 1 (the j = n term of the right rectangle rule
  joins the stiffness), formed Schur complement;
- A alone at t = 0 (no memory yet). With memory it serves one step, so it
  is not factorised when A + k R(0) is close enough to it: with
  D = a_n − A, the t = 0 problem is solved by the proximal iteration

      u⁽ⁱ⁺¹⁾ = argmin ½ uᵀ a_n u − (b + D u⁽ⁱ⁾)ᵀ u + Φ(u_C),

  whose fixed points are the solutions of the t = 0 problem (a_n u − D u =
  A u) and which contracts the linear part by ρ(a_n⁻¹ D) ≤
  max(|Δμ|/(μ + Δμ), |Δκ|/(κ + Δκ)) (κ = λ + 2μ/d the bulk modulus, Δ the
  tensor of k R(0)): each iteration is one step solve with the stored
  factorisation (:func:`adhesive_contact.scheme.state.step_solve`), and
  about log(1e-13)/log ρ of them are needed. Past ρ = :data:`PROXIMAL_UP_TO`
  A is factorised and its Schur complement applied, not formed,
  preconditioned by that of a_n.
"""

import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..linear_solvers import choose, make_linear_solver
from .condensed import CondensedOperator, DenseSchur, PartialCondensation
from .full_system import FullSystemOperator
from .memory import step_tensor

#: the step methods that iterate on all free dofs with AMG (scheme/full_system.py).
#: The others get a Schur complement formed by one AMG-CG solve per contact
#: unknown: "optimizer" since L-BFGS-B has no preconditioner for a_n;
#: "newton-plain" since its full steps, clipped at the wall, leave the
#: interior behind the contact unknowns (the line search of "newton" mends
#: that; without it the iterates can cycle where the condensed ones do not);
#: "penalty" since its penalty is scaled by the diagonal of S
FULL_SYSTEM = ("newton",)

#: the largest contraction bound for which t = 0 iterates on a_n's
#: factorisation: ρ = 0.3 takes about 25 solve pairs, what a factorisation
#: costs in 2D (measured: 33 at 1e5 dofs, 28 at 1e6; about 130 in 3D); a
#: relaxation kernel with k R(0) a tenth of the elastic tensor has ρ ≈ 0.1
PROXIMAL_UP_TO = 0.3


@dataclass
class StepOperators:
    """The condensed step matrices and the frame rotation of a run."""

    rotation: object             # sparse R (ndofs, ndofs), or None without Γ_C
    free: np.ndarray             # the free dofs
    initial: CondensedOperator   # A, for t = 0
    step: CondensedOperator      # A + k R(0), for n ≥ 1
    tensors: tuple               # (λ, μ) of A and of A + k R(0)
    support: tuple               # per tensor (a_FD (nF, nD), a_D· (nD, ndofs)), built once
    held_sign: np.ndarray        # (nD,) ũ_D = held_sign g_D (±1 at a contact node, else 1)
    factor_seconds: float
    schur_seconds: float
    shift: object = None         # sparse D = a_n − A on the free dofs, when t = 0 iterates
    contraction: float = 0.0     # the bound on ρ(a_n⁻¹ D) of the module doc

    @property
    def linear(self):
        """The linear backend of the run and why: {"method", "reason"}, and
        with the step method on all free dofs (:mod:`.full_system`) the CG
        iterations of its Newton systems so far, "cg_iterations"."""
        solver = self.step.solver
        record = {"method": solver.name, "reason": solver.reason}
        if self.within is not None:
            record["newton_systems"] = ("on all free dofs, by CG preconditioned with the "
                                        "hierarchy updated by the contact terms")
            record["cg_iterations"] = sum(op.S.iterations for op in {self.initial, self.step})
        return record

    @classmethod
    def build(cls, problem, k, initial=True):
        """Factorise and condense the step matrices of ``problem`` for the
        step k: A + w R(0), w the rule's weight of u_n (k, or k/2 for the
        trapezoid, :func:`~.memory.step_tensor`); without ``initial`` the
        t = 0 operator is not set up (a run's other step sizes:
        ``at(True)`` is then the step matrix)."""
        t0 = time.perf_counter()
        factory = OperatorFactory(problem)
        options = problem.options
        material = options.material
        elastic = (material.lam, material.mu)
        dlam, dmu = step_tensor(options.memory, options.second_order, k)
        stepped = (material.lam + dlam, material.mu + dmu)
        step = factory.operator(*stepped)
        start, shift, rho = initial_operator(factory, step, elastic, (dlam, dmu), initial)
        schur = start.schur_seconds + (step.schur_seconds if step is not start else 0.0)
        return cls(rotation=factory.R, free=factory.free, initial=start, step=step,
                   tensors=(elastic, stepped),
                   support=(factory.support[elastic], factory.support[stepped]),
                   held_sign=factory.sign, factor_seconds=time.perf_counter() - t0,
                   schur_seconds=schur, shift=shift, contraction=rho)

    @property
    def within(self):
        """(positions, size) of the contact unknowns within the step
        unknowns when those are all free dofs (:mod:`.full_system`), else
        None."""
        if isinstance(self.step, FullSystemOperator):
            return self.step.unknowns, self.free.size
        return None

    def at(self, initial):
        """The condensed step matrix of level 0 (``initial``: A, the t = 0
        problem without memory) or of a step."""
        return self.initial if initial else self.step

    def tensor(self, initial):
        """(λ, μ) of the step matrix of level 0 (``initial``) or of a step."""
        return self.tensors[0] if initial else self.tensors[1]

    def lift(self, initial, g):
        """a_FD g_D: the force of the held values g (nD,) on the free dofs of
        level 0 (``initial``) or of a step."""
        return self.support[0 if initial else 1][0] @ g

    def reaction(self, initial, u_frame, f, contact=None):
        """(a_n u)_D − f_D − F_D of a level (``initial``: level 0) on the held
        dofs, from the whole nodal-frame ũ (ndofs,) (the rows of a_n R at the held dofs), the
        load f_D on the held dofs (the memory history subtracted) and the
        contact laws' force F_D (nD,) along the held components of the
        contact nodes (None: none): the force the support alone exerts on
        the body, what a load cell in the grip reads."""
        r = self.support[0 if initial else 1][1] @ u_frame - f
        return r if contact is None else r - contact

    def held_frames(self, g):
        """ũ_D: the held values g_D (nD,) as components of ũ."""
        return self.held_sign * g

    def to_frames(self, f):
        """A load vector (ndofs,) in nodal frames, restricted to the free dofs."""
        if self.rotation is not None:
            f = self.rotation.T @ f
        return f[self.free]

    def from_frames(self, u_frame):
        """Cartesian components u = R ũ of a nodal-frame vector (ndofs,)."""
        return self.rotation @ u_frame if self.rotation is not None else u_frame


def backend_of(problem):
    """(method, reason): the linear backend of ``problem``'s ``solver.linear``,
    ``"auto"`` resolved by :func:`~adhesive_contact.linear_solvers.choose`."""
    assembly, free = problem.assembly, problem.free
    method = problem.options.solver.linear
    if method != "auto":
        return method, f"method {method!r} was asked for."
    nnz = int(assembly.K_mu.nnz * free.size / max(assembly.ndofs, 1))   # pro rata
    return choose(free.size, nnz, problem.dim, contact_unknowns=_newton_unknowns(problem))


class OperatorFactory:
    """Builds the step operators of one problem (a step matrix of a tensor
    (λ, μ) in the nodal frames, on the free dofs, condensed onto the
    contact unknowns or, with AMG, on all free dofs) and keeps the coupling
    of each tensor to the held dofs (``support``: (λ, μ) -> (a_FD, a_D·))."""

    def __init__(self, problem):
        self.problem = problem
        assembly, self.free = problem.assembly, problem.free
        self.R = (problem.boundary.rotation(assembly.ndofs) if problem.boundary is not None
                  else None)
        self.contact = problem.contact_positions
        self.method, self.reason = backend_of(problem)
        self.fixed = problem.prescribed.fixed
        # ũ_D = s g_D: R is ±1 on its diagonal at the held dofs (a held
        # component of a contact node is ±u_h there, ContactBoundary.rotation)
        self.sign = (self.R.diagonal()[self.fixed] if self.R is not None
                     else np.ones(self.fixed.size))
        self.support = {}
        # with AMG the step method iterates on all free dofs (a Schur complement
        # would cost one CG solve per contact unknown), if it can (FULL_SYSTEM)
        self.unreduced = (self.method == "amg" and self.contact.size > 0
                          and problem.options.solver.method in FULL_SYSTEM)

    def factorise(self, A_II, interior):
        """The linear solver of A_II (the rigid body modes of AMG in Cartesian
        components: the few rotated dofs at Γ_C only weaken its
        near-nullspace there)."""
        problem = self.problem
        solver = make_linear_solver(A_II, self.method, dim=problem.dim, points=problem.mesh.p,
                                    dofs=self.free[interior],
                                    tol=problem.options.solver.linear_tol)
        solver.reason = self.reason
        return solver

    def frames(self, lam, mu):
        """The stiffness of (λ, μ) in the nodal frames, Rᵀ A R."""
        A = self.problem.assembly.stiffness(lam, mu)
        return (self.R.T @ A @ self.R).tocsr() if self.R is not None else A

    def coupled(self, lam, mu):
        """The matrix of (λ, μ) in frames, its coupling and held rows kept:
        s·(rows of Rᵀ a R at the held dofs) = rows of a R, (a u)_D from ũ,
        and a_FD s g_D = (those rows)_F ᵀ g_D, the force of the held values."""
        A = self.frames(lam, mu)
        rows = A[self.fixed]
        if np.any(self.sign != 1.0):
            rows = (sp.diags(self.sign) @ rows).tocsr()
        self.support[(lam, mu)] = (rows[:, self.free].T.tocsr(), rows)
        return A

    def operator(self, lam, mu, nearby=None):
        """The operator of (λ, μ) on the free dofs; ``nearby`` is what the
        step matrix lends it to precondition with (its Schur complement, or
        with AMG its hierarchy), or None to set up its own."""
        problem, contact, free = self.problem, self.contact, self.free
        A = self.coupled(lam, mu)[free][:, free]
        if self.unreduced:
            return FullSystemOperator(A, contact, factorise=self.factorise, solver=nearby)
        # a body held by contact: S is singular along the free rigid motions,
        # and a partial factorisation (PARDISO's) stops at its zero pivot.
        # δ I on the contact block changes S by exactly δ I and nothing else
        # (a_II, and so reduce and expand, do not see it): factorise A + δ I_C
        # and take δ I back off S (docs/scheme.md, 'A body held by contact')
        delta = (float(A.diagonal()[contact].max())
                 if problem.held_by_contact and contact.size else 0.0)
        if delta:
            A = (A + sp.coo_matrix((np.full(contact.size, delta), (contact, contact)),
                                   shape=A.shape)).tocsr()
        if self.method == "pardiso" and contact.size:   # S and the solve halves in one
            operator = PartialCondensation(A, contact)
            operator.solver.reason = self.reason
        else:
            operator = CondensedOperator(A, contact, factorise=self.factorise,
                                         approximation=nearby)
        if delta:
            unshift(operator, delta)
        return operator


def initial_operator(factory, step, elastic, shift, wanted=True):
    """How level 0 (A alone, no memory yet) is solved, given the step
    operator ``step`` of A + D (D the tensor ``shift`` of w R(0)):
    (operator, proximal shift D or None, its contraction bound ρ).

    Without memory, or when not ``wanted`` (a run's other step sizes), the
    step operator itself; with AMG, A's own operator preconditioned by the
    step's hierarchy; for ρ ≤ PROXIMAL_UP_TO the proximal iteration on the
    step's factors (module docstring); else A's own operator, with the
    step's Schur complement lent to precondition it."""
    if not wanted:
        factory.coupled(*elastic)
        return step, None, 0.0
    if tuple(shift) == (0.0, 0.0):
        return step, None, 0.0
    rho = contraction(elastic, shift, factory.problem.dim)
    if factory.unreduced:   # A at t = 0, preconditioned by a_n's hierarchy
        return factory.operator(*elastic, nearby=step.solver), None, rho
    if rho <= PROXIMAL_UP_TO:   # t = 0 by the proximal iteration on a_n's factors
        factory.coupled(*elastic)
        return step, factory.frames(*shift)[factory.free][:, factory.free], rho
    # with PARDISO the t = 0 operator forms S as cheaply as it applies it
    nearby = None if isinstance(step, PartialCondensation) else step.S.matrix
    return factory.operator(*elastic, nearby=nearby), None, rho


def unshift(operator, delta):
    """S − δ I in place of the S of a condensed ``operator`` whose contact
    block was shifted by δ I (formed: the dense matrix; applied: its A_CC)."""
    S = operator.S
    if isinstance(S, DenseSchur):
        operator.S = DenseSchur(S.matrix - delta * np.eye(S.shape[0]))
    else:
        S.A_CC = (S.A_CC - delta * sp.eye(S.shape[0], format="csr")).tocsr()


def contraction(tensor, shift, dim):
    """max(|Δμ|/(μ + Δμ), |Δκ|/(κ + Δκ)), κ = λ + 2μ/d: a bound on the
    spectral radius of (A + D)⁻¹ D for the stiffnesses A of ``tensor`` and D
    of ``shift`` (isotropic (λ, μ) pairs, A + D positive definite), since
    both split into the same deviatoric and volumetric parts."""
    (lam, mu), (dlam, dmu) = tensor, shift
    kappa, dkappa = lam + 2.0 * mu / dim, dlam + 2.0 * dmu / dim
    return max(abs(dmu) / (mu + dmu), abs(dkappa) / (kappa + dkappa))


def _newton_unknowns(problem):
    """The contact unknowns of a step, for the backend choice: 0 for the step
    methods not in FULL_SYSTEM, which need the Schur complement whatever the
    backend."""
    if problem.options.solver.method not in FULL_SYSTEM:
        return 0
    return int(problem.contact_positions.size)
