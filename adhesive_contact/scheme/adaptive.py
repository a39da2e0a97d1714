"""The step controller of adaptive time steps (``[time.adaptive]``,
docs/scheme.md, "Adaptive time steps").

Steps are quantised: h = k_max 2^{−j}, j = j_0..J, k_max = T/N, k_min =
k_max 2^{−J}, so that every level lies on the grid t_m = m k_min and the
step matrices A + h R(0) (and A + 2h R(0) of the doubled step) are
factorised once per j that the run uses (:mod:`.controllers.step_doubling`).
Positions are counted in units of k_min (integers: no drift of t).

The local error of a pair of half steps h is estimated by step doubling,
from the one step 2h over the same interval (Richardson, scheme of order p),

    err = ‖y_{2×h} − y_{2h}‖ / (2^p − 1),   ‖y‖ = ‖u‖_2 / U + ‖β‖_{rms}

with U the largest ‖u_n‖_2 so far (a relative displacement) and the rms of
β weighted by the facet measures. What is controlled is the pair's time
lag ℓ = 2h err / Δ (its error over its rate of change), Δ = ‖y_{t+2h} −
y_t‖ the pair's change in the same norm floored at ``rate_floor`` 2h/T (a
quiet stretch counts as changing at that rate): the pair is accepted when

    q = ℓ / (tol T_ℓ) = err 2h / (tol T_ℓ max(Δ, rate_floor 2h/T)) ≤ 1,   T_ℓ = T/64,

or when h = k_min already. An error made early in a debonding is carried
to the end as a lag of the front (the error of a lag grows with the
front's speed: studies/convergence/adaptive), and the lags of the pairs add
up; with ℓ = a h^{p+1} the fewest steps (∫ dt/h) for a given sum
(∫ a h^p dt) make a h^{p+1} the same for every pair (Lagrange), so the lag
per pair, not per unit time, is what the grid spreads evenly. T_ℓ = T/64
makes q at 2h = T/64 the relative change err/(tol Δ). The next half step
(after a rejection, the retried one) is

    h_new = h · min(growth, max(shrink, safety · q^{−1/(p+1)}))

rounded down to the quantised set, capped at the explicit Euler bound of
the bonding law (2h ≤ k_E, the doubled step included) and at what is left
of [0, T]. With err ∝ h^{p+1} and Δ ∝ h, q ∝ h^{p+1}: the exponent
1/(p+1) makes q ≈ safety^{p+1} (the memory's criterion, per unit time, q ∝
h^p: exponent 1/p).
"""

import math
from dataclasses import dataclass

import numpy as np

from ..scene import relaxation_step_definite


@dataclass
class StepSizes:
    """The quantised half steps h_j = k_max 2^{−j}, j = ``first``..``halvings``,
    and the grid of units k_min = k_max 2^{−halvings} that [0, T] spans
    (``units`` of them)."""

    k_max: float
    halvings: int
    units: int
    first: int = 0      # the largest allowed half step is k_max 2^{-first}

    @classmethod
    def of(cls, options, stable_step=math.inf):
        """The step sizes of an adaptive run of ``options`` (the
        :class:`~.options.SchemeOptions`, or a Scene: the same attributes)
        with the explicit Euler bound ``stable_step`` on every step (the
        doubled one included); with a relaxation kernel the doubled step 2h
        also keeps the step tensor C_∞ + Σ_i (1 − 2h/τ_i) C_i positive
        definite (the scene's check holds k_max to it)."""
        adaptive = options.adaptive
        k_max = options.k
        memory = options.memory if (options.memory is not None
                                    and options.memory.kernel == "relaxation") else None

        def allowed(k):
            return k <= stable_step and (
                memory is None or relaxation_step_definite(memory, options.dim, k))
        first = 0
        while first < adaptive.halvings and not allowed(2.0 * k_max * 2.0 ** -first):
            first += 1
        return cls(k_max, adaptive.halvings, options.steps * 2 ** adaptive.halvings, first)

    def size(self, j):
        """h_j = k_max 2^{−j}: exact, a power of two times k_max."""
        return self.k_max * 2.0 ** -j

    def span(self, j):
        """h_j in units of k_min."""
        return 2 ** (self.halvings - j)

    def index(self, target, at):
        """The j of the largest quantised half step ≤ ``target`` whose pair
        starts on its own grid (``at`` a multiple of 2h_j in units) and fits
        in what is left after unit ``at``, within [first, halvings].

        Aligned so, a pair never straddles the boundary of a larger one: a
        step grows once the run reaches a multiple of the larger pair, and
        the run lands on T (``units``, a multiple of every 2h_j below k_max)
        with the step it has instead of halving down to k_min to fill what
        is left."""
        if target >= self.k_max:
            j = self.first
        else:
            j = max(self.first, int(math.ceil(math.log2(self.k_max / target) - 1e-12)))
        j = min(j, self.halvings)
        while j < self.halvings and (2 * self.span(j) > self.units - at
                                     or at % (2 * self.span(j))):
            j += 1
        return j


def memory_time(options):
    """The time scale τ of the memory's error control: the shortest
    relaxation time of a Prony or relaxation kernel, T for a general
    kernel, ∞ without memory (no control)."""
    if options.memory is None:
        return math.inf
    tau = options.memory.shortest_relaxation_time
    return options.T if tau is None else tau


@dataclass
class Controller:
    """Accepts or rejects a pair of half steps and picks the next half step.

    ``tol``, ``rate_floor``, ``growth``, ``shrink``, ``safety`` of [time.adaptive], ``order``
    p of the scheme (1 the paper's, 2 the second-order one), ``T`` the final
    time. Counts ``accepted``, ``rejected`` and ``forced`` pairs (accepted
    at k_min with q > 1)."""

    sizes: StepSizes
    tol: float
    T: float
    order: int = 1
    rate_floor: float = 1e-3
    growth: float = 2.0
    shrink: float = 0.25
    safety: float = 0.9
    memory_time: float = math.inf
    accepted: int = 0
    rejected: int = 0
    forced: int = 0

    @classmethod
    def of(cls, options, stable_step=math.inf):
        """The controller of an adaptive run of ``options`` (as
        :meth:`StepSizes.of`)."""
        a = options.adaptive
        return cls(StepSizes.of(options, stable_step), a.tol, options.T,
                   2 if options.scheme == "second-order" else 1, a.rate_floor, a.growth,
                   a.shrink, a.safety, memory_time(options))

    #: T_ℓ = T/LAG_SPAN: the lag a pair may make is tol T_ℓ
    LAG_SPAN = 64

    def ratios(self, err, j, change=0.0, memory=0.0):
        """(q_ℓ, q_H): the lag's q_ℓ = err 2h_j / (tol T_ℓ max(Δ, rate_floor
        2h_j/T)), Δ = ``change`` of the pair, and the memory's q_H = err_H τ
        / (tol 2h_j), err_H = ``memory`` its estimate and τ =
        ``memory_time`` (the kernel's shortest relaxation time)."""
        h2 = 2.0 * self.sizes.size(j)
        lag = err * h2 * self.LAG_SPAN / (
            self.tol * self.T * max(change, self.rate_floor * h2 / self.T))
        held = memory * self.memory_time / (self.tol * h2) if memory > 0.0 else 0.0
        return lag, held

    def ratio(self, err, j, change=0.0, memory=0.0):
        """q = max(q_ℓ, q_H) of :meth:`ratios`: the pair passes at q ≤ 1."""
        return max(self.ratios(err, j, change, memory))

    def factor(self, lag, held=0.0):
        """min(growth, max(shrink, safety min(q_ℓ^{−1/(p+1)}, q_H^{−1/p}))):
        q_ℓ ∝ h^{p+1}, q_H ∝ h^p."""
        shares = [q ** (-1.0 / e) for q, e in ((lag, self.order + 1), (held, self.order))
                  if q > 0.0]
        if not shares:
            return self.growth
        return min(self.growth, max(self.shrink, self.safety * min(shares)))

    def judge(self, err, j, at, change=0.0, memory=0.0):
        """(accept, next j) for a pair of half steps h_j starting at unit
        ``at`` with estimated error ``err`` and change Δ = ``change``; the
        next j is that of the pair after it (accepted: from ``at + 2
        span(j)``) or of the retry."""
        lag, held = self.ratios(err, j, change, memory)
        q = max(lag, held)
        finite = math.isfinite(q)
        accept = (finite and q <= 1.0) or j == self.sizes.halvings
        target = self.sizes.size(j) * (self.factor(lag, held) if finite else self.shrink)
        if accept:
            self.accepted += 1
            self.forced += not (finite and q <= 1.0)
            return True, self.sizes.index(target, at + 2 * self.sizes.span(j))
        self.rejected += 1
        return False, max(j + 1, self.sizes.index(target, at))

    def failed(self, j, at):
        """The retry after a trial whose step solve failed: (can retry, next j)."""
        if j >= self.sizes.halvings:
            return False, j
        self.rejected += 1
        return True, max(j + 1, self.sizes.index(self.sizes.size(j) * self.shrink, at))


@dataclass
class PairNorm:
    """‖(u, β)‖ = ‖u‖_2 / U + (Σ_f |f| β_f² / |Γ_C|)^½ of the estimate,
    U the largest ‖u_n‖_2 of the run so far (:meth:`scale` keeps it), and
    the memory's part of it (:meth:`memory`)."""

    measure: np.ndarray   # (nf,) facet measures, or empty
    shear: float = 1.0    # μ of the elastic tensor C
    largest: float = 0.0

    def scale(self, u):
        self.largest = max(self.largest, float(np.linalg.norm(u)))

    def __call__(self, du, dbeta, order=1):
        # order=1: the norm itself (the pair's change Δ)
        """The Richardson estimate of the pair's error from the differences
        of the doubled step to the pair: (‖du‖/U + rms dβ) / (2^p − 1)."""
        eu = float(np.linalg.norm(du)) / self.largest if self.largest > 0 else 0.0
        eb = 0.0
        if self.measure.size:
            eb = math.sqrt(float(self.measure @ (dbeta * dbeta)) / float(self.measure.sum()))
        return (eu + eb) / (2 ** order - 1)

    def memory(self, dhistory, order=1):
        """The Richardson estimate of the memory's error, ‖Δa_μ‖_2 / (μ U) /
        (2^p − 1), from the difference ``dhistory`` of a_μ = Σ_m μ_m H^m
        between the doubled step and the pair (0 for None: no memory). H^m
        is the rule's history ∫_0^{t_n} e^{−(t_n−s)/τ_m} u(s) ds (the kernel's
        tensors μ_m, μ that of C): the memory's stress as the displacement
        whose elastic stress it is. It is not part of the pair's norm: a
        body held still while its stress relaxes (u fixed) has its error all
        here."""
        if dhistory is None or self.largest <= 0:
            return 0.0
        return float(np.linalg.norm(dhistory)) / (self.shear * self.largest) / (2 ** order - 1)
