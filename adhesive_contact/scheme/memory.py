"""The memory term ∫_0^t R(t−s) ε(u(s)) ds on the levels of a run, whatever
its steps.

With levels t_0 = 0 < t_1 < ... and steps k_j = t_j − t_{j−1} (k_j = T/N
for the paper's uniform grid), the quadrature rules are

- the right rectangle rule (the paper's): ∫_0^{t_n} R(t_n − s) ε(u(s)) ds
  ≈ Σ_{j=1}^{n} k_j R(t_n − t_j) ε(u_j), u_j with the weight of its own
  step; the j = n term k_n R(0) ε(u_n) joins the step matrix A + k_n R(0);
- the trapezoidal rule (``time.scheme = "second-order"``): u_0 with
  weight k_1/2, u_j (0 < j < n) with (k_j + k_{j+1})/2, u_n with k_n/2
  (the step matrix A + (k_n/2) R(0)), second order in k for a smooth
  strain.

Because ε is linear, the history of an isotropic kernel is the strain of
a displacement-like field, so it is kept as two nodal vectors (a_λ, a_μ)
whose force is K_λ a_λ + K_μ a_μ and whose stress is tr ε(a_λ) I + 2 ε(a_μ)
(:mod:`adhesive_contact.fem.assembly`). A relaxation modulus G(t) = C_∞ +
Σ_i e^{−t/τ_i} C_i is the Prony series R = G' with C_m = −C_i/τ_i (the
instantaneous G(0) is the elastic tensor).

For a Prony series R(t) = Σ_m e^{−t/τ_m} C_m the history
h_n^m = Σ_{j<n} w_j^{(n)} e^{−(t_n − t_j)/τ_m} u_j obeys, with the
per-step decay factors e^{−k_n/τ_m},

    h_{n+1}^m = e^{−k_{n+1}/τ_m} (h_n^m + k_n u_n)                  (rectangle)
    h_{n+1}^m = e^{−k_{n+1}/τ_m} (h_n^m + (k_n + k_{n+1})/2 u_n)   (trapezoid)

exactly (h_1^m = 0, resp. e^{−k_1/τ_m} (k_1/2) u_0): O(1) a step whatever
the grid. A scalar kernel R(t) = r(t) C_0 sums Σ_j w_j r(t_{n+1} − t_j) u_j
directly with the weights above, O(n) a step.

The objects are persistent: :meth:`decayed` gives the history of a trial
step k from the last accepted level without changing anything, and
:meth:`after` returns the memory with the trial level accepted, so that a
rejected step (:mod:`.controllers.step_doubling`) leaves no trace. On the
uniform grid the right rectangle rule's Prony recursion is the paper's,
operation for operation; the trapezoid adds the weight k of u_j as two
halves.
"""

from dataclasses import dataclass

import numpy as np


class NoMemory:
    """R ≡ 0."""

    active = False

    def instantaneous(self, k):
        return 0.0, 0.0

    def decayed(self, k):
        return None

    def fields(self, h):
        return None

    def after(self, h, u, k):
        return self


@dataclass(frozen=True)
class PronyMemory:
    """R(t) = Σ_m e^{−t/τ_m} C_m, C_m = (λ_m, μ_m), on a nonuniform grid.

    ``summed`` (m, ndofs) is h_n^m + w u_n with u_n's weight so far (k_n,
    or k_n/2 for the trapezoid, whose other half k_{n+1}/2 is added by the
    next step), ``last`` is u_n (trapezoid only)."""

    lam: np.ndarray
    mu: np.ndarray
    tau: np.ndarray
    trapezoid: bool
    summed: np.ndarray
    last: np.ndarray = None

    active = True

    def instantaneous(self, k):
        """(λ, μ) of w k R(0), w = 1 (rectangle) or ½ (trapezoid)."""
        w = 0.5 * k if self.trapezoid else k
        return w * self.lam.sum(), w * self.mu.sum()

    def decayed(self, k):
        """h_{n+1}^m (m, ndofs) of a step k from the last level."""
        decay = np.exp(-k / self.tau)[:, None]
        if self.trapezoid:
            return decay * (self.summed + (0.5 * k) * self.last[None, :])
        return decay * self.summed

    def fields(self, h):
        """(a_λ, a_μ) = (Σ_m λ_m h^m, Σ_m μ_m h^m)."""
        return self.lam @ h, self.mu @ h

    def after(self, h, u, k):
        """The memory with the level u_{n+1} = ``u`` of step k accepted,
        ``h`` = :meth:`decayed` (k)."""
        w = 0.5 * k if self.trapezoid else k
        return PronyMemory(self.lam, self.mu, self.tau, self.trapezoid, h + w * u[None, :],
                           u if self.trapezoid else None)


@dataclass(frozen=True)
class FunctionMemory:
    """R(t) = r(t) C_0, C_0 = (λ_0, μ_0), summed directly on a nonuniform grid.

    ``times``, ``weights``, ``fields_u``: the levels t_j, their weights so far
    (final but for the last level's, for the trapezoid: its k_n/2) and u_j;
    the rectangle rule keeps no u_0 (weight 0)."""

    r: object
    lam: float
    mu: float
    trapezoid: bool
    now: float
    times: tuple = ()
    weights: tuple = ()
    fields_u: tuple = ()

    active = True

    def _r(self, t):
        t = np.atleast_1d(np.asarray(t, dtype=float))
        return self.r(t, t=t)

    def instantaneous(self, k):
        w = 0.5 * k if self.trapezoid else k
        r0 = float(self._r(0.0)[0])
        return w * r0 * self.lam, w * r0 * self.mu

    def _weights(self, k):
        w = np.array(self.weights, dtype=float)
        if self.trapezoid and w.size:
            w[-1] += 0.5 * k   # u_n's other half, (k_n + k_{n+1})/2
        return w

    def decayed(self, k):
        """Σ_j w_j r(t_{n+1} − t_j) u_j (ndofs,), or None while empty."""
        if not self.times:
            return None
        lags = (self.now + k) - np.asarray(self.times)
        return (self._weights(k) * self._r(lags)) @ np.asarray(self.fields_u)

    def fields(self, h):
        return None if h is None else (self.lam * h, self.mu * h)

    def after(self, h, u, k):
        w = 0.5 * k if self.trapezoid else k
        return FunctionMemory(self.r, self.lam, self.mu, self.trapezoid, self.now + k,
                              self.times + (self.now + k,),
                              tuple(self._weights(k)) + (w,), self.fields_u + (u.copy(),))


def start_memory(spec, trapezoid, u0):
    """The memory of a scene's MemorySpec (None: no memory) after level 0,
    u_0 = ``u0`` (ndofs,), on a nonuniform grid."""
    if spec is None:
        return NoMemory()
    if spec.kernel in ("prony", "relaxation"):   # relaxation: C_m = −C_i/τ_i
        terms = spec.prony_terms
        tau = np.array([t.tau for t in terms], dtype=float)
        return PronyMemory(np.array([t.tensor.lam for t in terms], dtype=float),
                           np.array([t.tensor.mu for t in terms], dtype=float), tau,
                           trapezoid, np.zeros((tau.size, u0.size)),
                           u0.copy() if trapezoid else None)
    memory = FunctionMemory(spec.function, spec.tensor.lam, spec.tensor.mu, trapezoid, 0.0)
    if trapezoid:   # u_0: weight 0 of its own (k_0 = 0), k_1/2 from the first step
        memory = FunctionMemory(memory.r, memory.lam, memory.mu, True, 0.0, (0.0,), (0.0,),
                                (u0.copy(),))
    return memory


def step_tensor(spec, trapezoid, k):
    """(λ, μ) of the tensor w R(0) that joins the step matrix of a step k
    (w = k, or k/2 for the trapezoid), before u_0 is known: (0, 0) without
    memory."""
    return start_memory(spec, trapezoid, np.zeros(1)).instantaneous(k)
