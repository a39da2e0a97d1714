"""The memory term: the right rectangle rule for ∫_0^t R(t−s) ε(u(s)) ds.

At step n the scheme (4.1) needs k Σ_{j=1}^{n} R(t_n − t_j) ε(u_j). The
j = n term k R(0) ε(u_n) joins the step matrix; the rest, the history, is
known. Because ε is linear, the history of an isotropic kernel is the
strain of a displacement-like field, so it is stored as two nodal vectors
(a_λ, a_μ) whose force is K_λ a_λ + K_μ a_μ and whose stress is
tr ε(a_λ) I + 2 ε(a_μ) (see :mod:`adhesive_contact.fem.assembly`).

- Prony series R(t) = Σ_m e^{−t/τ_m} C_m (docs/model.md §4): with
  h_n^m = k Σ_{j<n} e^{−(t_n−t_j)/τ_m} u_j one has h_1^m = 0 and
  h_n^m = e^{−k/τ_m} (h_{n−1}^m + k u_{n−1}) exactly: O(1) per step.
- A relaxation modulus G(t) = C_∞ + Σ_i e^{−t/τ_i} C_i is the Prony series
  R = G' with C_m = −C_i/τ_i (the instantaneous G(0) is the elastic tensor).
- A scalar kernel R(t) = r(t) C_0: the history k Σ_{j<n} r(t_n − t_j) u_j
  is summed directly, O(n) per step.

With ``trapezoid=True`` (``time.scheme = "second-order"``) the rule is the
trapezoidal one, k [½ R(t_n) ε(u_0) + Σ_{j=1}^{n−1} R(t_n − t_j) ε(u_j)
+ ½ R(0) ε(u_n)]: the j = n weight k/2 joins the step matrix (A + (k/2) R(0)),
u_0 enters the history with weight k/2 (for Prony h_1^m = e^{−k/τ_m} (k/2) u_0,
then the same recursion), second order in k for a smooth strain.

Each object keeps the state of one run: ``begin(k, ndofs)``, then per step
``history(n)`` before solving for u_n and ``advance(n, u_n)`` after (n ≥ 0;
the rectangle rule ignores u_0).
"""

import numpy as np


class NoMemory:
    """No memory: R ≡ 0."""

    active = False

    def instantaneous(self, k):
        """(λ, μ) of k R(0), the tensor that joins the step matrix."""
        return 0.0, 0.0

    def begin(self, k, ndofs):
        pass

    def history(self, n):
        """(a_λ, a_μ) of the history at step n, or None when it is zero."""
        return None

    def advance(self, n, u):
        pass


class PronyMemory:
    """R(t) = Σ_m e^{−t/τ_m} C_m with C_m = (λ_m, μ_m); exact recursion."""

    active = True

    def __init__(self, lam, mu, tau, trapezoid=False):
        self.lam = np.asarray(lam, dtype=float)
        self.mu = np.asarray(mu, dtype=float)
        self.tau = np.asarray(tau, dtype=float)
        self.trapezoid = trapezoid

    def instantaneous(self, k):
        w = 0.5 * k if self.trapezoid else k   # the weight of j = n
        return w * self.lam.sum(), w * self.mu.sum()

    def begin(self, k, ndofs):
        self.k = k
        self.decay = np.exp(-k / self.tau)
        self.h = np.zeros((self.tau.size, ndofs))  # h_1^m = 0

    def history(self, n):
        """(a_λ, a_μ) = (Σ_m λ_m h_n^m, Σ_m μ_m h_n^m)."""
        return self.lam @ self.h, self.mu @ self.h

    def advance(self, n, u):
        """h_{n+1}^m = e^{−k/τ_m} (h_n^m + w_n k u_n), w_0 = ½ (trapezoid) or 0."""
        if n == 0:
            if not self.trapezoid:
                return
            self.h += (0.5 * self.k) * u[None, :]
        else:
            self.h += self.k * u[None, :]
        self.h *= self.decay[:, None]


class FunctionMemory:
    """R(t) = r(t) C_0 with C_0 = (λ_0, μ_0); the history summed directly."""

    active = True

    def __init__(self, r, lam, mu, trapezoid=False):
        self.r = r
        self.lam = lam
        self.mu = mu
        self.trapezoid = trapezoid

    def _r(self, t):
        t = np.atleast_1d(np.asarray(t, dtype=float))
        return self.r(t, t=t)

    def instantaneous(self, k):
        r0 = float(self._r(0.0)[0])
        w = 0.5 * k if self.trapezoid else k   # the weight of j = n
        return w * r0 * self.lam, w * r0 * self.mu

    def begin(self, k, ndofs):
        self.k = k
        self.u = []  # u_1, u_2, ...
        self.u0 = None   # u_0 (trapezoid only)

    def history(self, n):
        a = None
        if n > 1:
            lags = self.k * (n - np.arange(1, n))  # t_n − t_j, j = 1..n−1
            a = self.k * (self._r(lags) @ np.asarray(self.u))
        if self.u0 is not None:   # the trapezoid's ½ k r(t_n) u_0
            end = (0.5 * self.k * float(self._r(n * self.k)[0])) * self.u0
            a = end if a is None else a + end
        if a is None:
            return None
        return self.lam * a, self.mu * a

    def advance(self, n, u):
        if n == 0:
            if self.trapezoid:
                self.u0 = u.copy()
            return
        self.u.append(u.copy())


def make_memory(spec, trapezoid=False):
    """The memory object of a scene's MemorySpec (None: no memory); the
    trapezoidal rule with ``trapezoid``, else the right rectangle rule."""
    if spec is None:
        return NoMemory()
    if spec.kernel in ("prony", "relaxation"):   # relaxation: C_m = −C_i/τ_i
        terms = spec.prony_terms
        return PronyMemory([t.tensor.lam for t in terms], [t.tensor.mu for t in terms],
                           [t.tau for t in terms], trapezoid)
    return FunctionMemory(spec.function, spec.tensor.lam, spec.tensor.mu, trapezoid)


def start_memory(problem):
    """A fresh memory history for one run of ``problem`` (the rule of its
    ``time.scheme``): a Problem is never changed by a run."""
    return make_memory(problem.options.memory, problem.options.second_order)
