"""The accuracy guides of the time step k (docs/scheme.md, "Accuracy guides
of the time step"): what a scene's k costs in accuracy, from its numbers
alone, before a run. :mod:`.warnings` says so when a guide is exceeded.

**The memory.** Under a strain ε held from t = 0 the memory's part of the
stress is ∫_0^t R(s) ds ε. For a Prony term R = e^{−t/τ} C_m the paper's
right rectangle rule gives, at every level n (c = k/τ),

    k Σ_{j=1}^{n} e^{−(t_n − t_j)/τ} = τ (1 − e^{−t_n/τ}) · c/(1 − e^{−c}),

and the trapezoidal rule of ``time.scheme = "second-order"``

    k [½ e^{−t_n/τ} + Σ_{j=1}^{n−1} e^{−(t_n − t_j)/τ} + ½] = τ (1 − e^{−t_n/τ}) · (c/2) coth(c/2):

the exact τ (1 − e^{−t_n/τ}) times 1 + e(c), e(c) = c/(1 − e^{−c}) − 1 ≈ c/2
or (c/2) coth(c/2) − 1 ≈ c²/12 (:func:`quadrature_excess`). The stress of
the held strain at T is then off by

    δ = |Σ_m τ_m C_m (1 − e^{−T/τ_m}) e(c_m)| / |C + Σ_m τ_m C_m (1 − e^{−T/τ_m})|

(for a relaxation modulus τ_m C_m = −C_i: the solid relaxes too far), the
larger of its shear (μ) and bulk (κ = λ + 2μ/d) parts: the worst held
strain. Numerator and denominator move apart with t, so T is the worst
level. For a standard linear solid with E_1 = E_∞ and T ≫ τ, δ = e(c):
27 % at k/τ = 0.5, 5.1 % at 0.1, 1 % at 0.02 for the paper's rule; 2.1 %,
0.083 % and 0.0033 % for the trapezoid (studies/stability/time_accuracy.py
measures them; tests/test_accuracy_guides.py holds a run to δ to 1e-9). A
``function`` kernel r(t) C_0 gets the same δ with the rules' sums of r
against ∫ r by a 4-point Gauss rule on each step, at every level.

The guide is δ ≤ :data:`MEMORY_GUIDE` = 5 %: a time error below the space
error of the committed scenes' meshes (the peel's peak force moves 3.7 %
when its mesh is refined once, studies/README.md), and the error of the
paper's rule at k/τ ≈ 0.1 for that solid (0.78 for the trapezoid).

**The bonding law's time scale.** The Frémond law's rate is at most
(γ_ν + γ_τ) L² per unit time, so 1/((γ_ν + γ_τ) L²) (the explicit Euler
bound, :meth:`~adhesive_contact.laws.bonding.Fremond.stable_step`) is the
shortest time the glue takes to debond. (4.2) finds β_n from the
displacement of level n − 1 whatever the integrator, so a step longer than
that lets the debonding front lag: the 'implicit', 'exponential' and
'midpoint' integrators keep β in [0, 1] at any k, but not the front in
place (:data:`~adhesive_contact.laws.bonding.BEYOND_TIME_SCALE`, measured
on studies/scenes/peel.toml). The guide is k ≤ that time scale.
"""

import numpy as np

#: the largest relative error δ of the stress of a strain held from t = 0
#: that the memory's quadrature may make before a run warns (module docstring)
MEMORY_GUIDE = 0.05
#: Gauss–Legendre points per step for the exact memory integral of a
#: ``function`` kernel
GAUSS_POINTS = 4


def quadrature_excess(c, scheme):
    """e(c): the scheme's quadrature of ∫_0^{t_n} e^{−s/τ} ds over the
    integral, minus 1, at every level, c = k/τ > 0: c/(1 − e^{−c}) − 1
    (right rectangle, ``"paper"``) or (c/2) coth(c/2) − 1 (trapezoid,
    ``"second-order"``)."""
    c = np.asarray(c, dtype=float)
    if scheme == "second-order":
        return 0.5 * c / np.tanh(0.5 * c) - 1.0
    return c / -np.expm1(-c) - 1.0


def _modes(tensor, dim):
    """(μ, κ) of an isotropic tensor, κ = λ + 2μ/d."""
    return np.array([tensor.mu, tensor.lam + 2.0 * tensor.mu / dim])


def _prony_error(scene, k, scheme):
    """δ at T of a Prony or relaxation kernel (module docstring)."""
    C = _modes(scene.material, scene.dim)
    exact, excess = C.copy(), np.zeros(2)
    for term in scene.memory.prony_terms:
        held = term.tau * (-np.expm1(-scene.T / term.tau)) * _modes(term.tensor, scene.dim)
        exact += held
        excess += held * quadrature_excess(k / term.tau, scheme)
    return float(np.max(np.abs(excess) / np.abs(exact)))


def _function_error(scene, k, scheme):
    """δ, worst level, of a ``function`` kernel r(t) C_0: the rule's sum of
    r over the 4-point Gauss integral of r, cumulated over the steps."""
    memory = scene.memory
    steps = int(round(scene.T / k))
    t = k * np.arange(steps + 1)
    r = memory.function(t, t=t)                                  # r(t_i), i = 0..N
    x, w = np.polynomial.legendre.leggauss(GAUSS_POINTS)
    points = (t[:-1, None] + 0.5 * k * (1.0 + x[None, :])).ravel()
    exact = np.concatenate([[0.0], np.cumsum(
        0.5 * k * (memory.function(points, t=points).reshape(steps, -1) @ w))])
    rule = k * np.concatenate([[0.0], np.cumsum(r[:-1])])       # k Σ_{i<n} r(t_i)
    if scheme == "second-order":                                 # the trapezoid's ends
        rule = rule + 0.5 * k * (r - r[0])
        rule[0] = 0.0
    C, C0 = _modes(scene.material, scene.dim), _modes(memory.tensor, scene.dim)
    with np.errstate(all="ignore"):
        delta = (np.abs(rule - exact)[:, None] * np.abs(C0)
                 / np.abs(C[None, :] + exact[:, None] * C0))
    delta = delta[np.isfinite(delta)]
    return float(delta.max()) if delta.size else 0.0


def memory_error(scene, k=None, scheme=None):
    """δ: how far the memory's quadrature at step ``k`` (the scene's by
    default) with ``scheme`` puts the stress of a strain held from t = 0,
    relative to it, at the worst level; None without memory."""
    if scene.memory is None:
        return None
    k = scene.k if k is None else k
    scheme = scene.scheme if scheme is None else scheme
    if scene.memory.kernel == "function":
        return _function_error(scene, k, scheme)
    return _prony_error(scene, k, scheme)


def steps_for_memory(scene, scheme=None, guide=MEMORY_GUIDE):
    """The fewest time steps N (k = T/N) whose :func:`memory_error` is at
    most ``guide`` (δ grows with k: bisection on N)."""
    def error(steps):
        return memory_error(scene, scene.T / steps, scheme)
    lo, hi = 1, max(1, scene.steps)
    while error(hi) > guide:
        lo, hi = hi, 2 * hi
        if hi > 2 ** 40:
            return None
    if error(lo) <= guide:
        return lo
    while hi - lo > 1:   # error(lo) > guide ≥ error(hi)
        mid = (lo + hi) // 2
        lo, hi = (lo, mid) if error(mid) <= guide else (mid, hi)
    return hi


def shortest_relaxation_time(scene):
    """min τ_m of a Prony or relaxation kernel, None otherwise."""
    return None if scene.memory is None else scene.memory.shortest_relaxation_time


def bonding_time_scale(problem):
    """1/((γ_ν + γ_τ) L²) of a rate bonding law, None without one (or for
    a rate-independent law, which has no rate)."""
    law = problem.bonding
    if law is None or getattr(law, "rate_independent", False):
        return None
    return law.stable_step()


def steps_for_time_scale(problem):
    """The fewest time steps with k ≤ :func:`bonding_time_scale`."""
    return int(np.ceil(problem.scene.T / bonding_time_scale(problem) * (1.0 - 1e-12)))


__all__ = ["MEMORY_GUIDE", "quadrature_excess", "memory_error", "steps_for_memory",
           "shortest_relaxation_time", "bonding_time_scale", "steps_for_time_scale"]
