"""The memory term: the Prony recursion against the direct rectangle-rule
sum, the general kernel against the Prony series, and a uniform-strain
viscoelastic column against the closed-form solution of its Volterra
equation (first order in k).
"""

import numpy as np
import pytest
from conftest import prony, relative_max, run, scene_dict
from scipy.integrate import quad

from adhesive_contact import compile_expression
from adhesive_contact.scheme.memory import FunctionMemory, PronyMemory


def uniform(memory, k, us):
    """The histories (a_λ, a_μ) (or None) of steps n = 1..len(us) of k with
    the persistent ``memory`` (started after level 0), u_n = us[n − 1]."""
    out = []
    for u in us:
        h = memory.decayed(k)
        out.append(memory.fields(h))
        memory = memory.after(h, u, k)
    return out


def prony_memory(lam, mu, tau, ndofs, trapezoid=False, u0=None):
    lam, mu, tau = (np.atleast_1d(np.asarray(v, dtype=float)) for v in (lam, mu, tau))
    return PronyMemory(lam, mu, tau, trapezoid, np.zeros((tau.size, ndofs)),
                       None if not trapezoid else u0)

# --------------------------------------------------------------------------
# The history sums
# --------------------------------------------------------------------------

def direct_history(k, taus, us, n):
    """h_n^m = k Σ_{j=1}^{n−1} e^{−(t_n − t_j)/τ_m} u_j, summed directly (O(n))."""
    return np.array([k * sum(np.exp(-(n - j) * k / tau) * us[j - 1] for j in range(1, n))
                     if n > 1 else np.zeros_like(us[0]) for tau in taus])


def test_prony_recursion_equals_direct_sum(rng):
    lam, mu, tau = np.array([120.0, 30.0]), np.array([80.0, 45.0]), np.array([0.3, 2.0])
    k, steps, ndofs = 0.02, 50, 40
    us = rng.standard_normal((steps, ndofs))
    mem = prony_memory(lam, mu, tau, ndofs)
    np.testing.assert_allclose(mem.instantaneous(k), (k * lam.sum(), k * mu.sum()), rtol=1e-15)
    histories = uniform(mem, k, us)
    for n in range(1, steps + 1):
        h = direct_history(k, tau, us, n)
        a_lam, a_mu = histories[n - 1]
        ref_lam, ref_mu = lam @ h, mu @ h
        if n == 1:
            assert np.abs(a_lam).max() == 0.0 and np.abs(a_mu).max() == 0.0
        else:
            # Tolerance: both are sums of ≤ 50 terms of size ~k|u|; the
            # recursion multiplies by e^{−k/τ} n times, so round-off grows
            # like n ε_mach ≈ 1e-14 relative: 1e-12 leaves a margin of 100.
            assert relative_max(a_lam, ref_lam) < 1e-12
            assert relative_max(a_mu, ref_mu) < 1e-12


def test_function_kernel_equals_single_prony_term(rng):
    """r(t) = e^{−t/0.3} with C_0 = (λ, μ) is the Prony series of one term."""
    lam, mu, tau = 70.0, 35.0, 0.3
    k, steps, ndofs = 0.02, 50, 30
    us = rng.standard_normal((steps, ndofs))
    prony = prony_memory([lam], [mu], [tau], ndofs)
    func = FunctionMemory(compile_expression("exp(-t/0.3)"), lam, mu, False, 0.0)
    np.testing.assert_allclose(func.instantaneous(k), prony.instantaneous(k), rtol=1e-15)
    for n, (hp, hf) in enumerate(zip(uniform(prony, k, us), uniform(func, k, us)), start=1):
        if hf is None:      # no history yet (n = 1)
            assert n == 1 and np.abs(hp[0]).max() == 0.0
        else:
            # Tolerance: round-off of two 50-term sums (see above).
            assert relative_max(hf[0], hp[0]) < 1e-12
            assert relative_max(hf[1], hp[1]) < 1e-12


# --------------------------------------------------------------------------
# A viscoelastic column in uniform uniaxial strain
# --------------------------------------------------------------------------
#
# [0, 4] x [0, 1], clamped left, traction (s0, 0) on the right, ν = 0 in the
# material and in the memory tensor. With ν = 0 (λ = 0, μ = E/2) the field
# u = (ε(t) x, 0) has σ = E ε e_x⊗e_x + memory: zero traction on top and
# bottom, u = 0 on the left, σ e_x = (s0, 0) on the right iff
#
#     E ε(t) + ∫_0^t E_m e^{−(t−s)/τ} ε(s) ds = s0.
#
# Differentiating with I(t) = ∫_0^t e^{−(t−s)/τ} ε(s) ds, I' = ε − I/τ and
# E_m I = s0 − E ε gives ε' = −a ε + s0/(E τ), ε(0) = s0/E, a = 1/τ + E_m/E:
#
#     ε(t) = (s0/E) [1/(τa) + (1 − 1/(τa)) e^{−a t}].
#
# The field is linear, so it is in V^h and the P1 solution is exactly
# u_n = (ε_n x, 0) with ε_n the solution of the discrete Volterra equation
# (right rectangle rule) E ε_n + k Σ_{j=1}^{n} E_m e^{−(t_n−t_j)/τ} ε_j = s0,
# ε_0 = s0/E: the only error is the O(k) of the time discretisation.

E0, EM, TAU, S0, T_END = 1000.0, 500.0, 0.5, 10.0, 2.0
A = 1.0 / TAU + EM / E0


def exact_strain(t):
    return S0 / E0 * (1.0 / (TAU * A) + (1.0 - 1.0 / (TAU * A)) * np.exp(-A * t))


def column_scene(steps, kernel="prony"):
    memory = (prony((EM, 0.0, TAU)) if kernel == "prony" else
              {"kernel": "function", "r": f"exp(-t/{TAU!r})", "E": EM, "nu": 0.0})
    return scene_dict({
        "mesh.size": [4.0, 1.0], "mesh.cells": [8, 2],
        "boundary": {"dirichlet": ["left"]}, "material": {"E": E0, "nu": 0.0},
        "memory": memory, "loads.traction.right": [repr(S0), "0"],
        "time": {"T": T_END, "steps": steps}})


def column_strain(problem, sol):
    """ε_n from the nodal field, after checking it is uniaxial: u_y = 0 and
    u_x = ε_n x at every node (to round-off)."""
    x = problem.mesh.p[0]
    ux, uy = sol.u[:, :, 0], sol.u[:, :, 1]
    right = np.isclose(x, 4.0)
    eps = ux[:, right].mean(axis=1) / 4.0
    scale = np.abs(ux).max()
    # Tolerance: round-off of the sparse solves, ε_mach κ(K) ~ 1e-14.
    assert np.abs(uy).max() <= 1e-12 * scale
    assert np.abs(ux - eps[:, None] * x[None, :]).max() <= 1e-12 * scale
    return eps


def test_closed_form_solves_the_volterra_equation():
    """Check the formula above by quadrature (independent of the derivation)."""
    for t in (0.0, 0.3, 1.0, 2.0):
        integral, _ = quad(lambda s: EM * np.exp(-(t - s) / TAU) * exact_strain(s), 0.0, t,
                           epsabs=1e-14, epsrel=1e-13)
        assert abs(E0 * exact_strain(t) + integral - S0) < 1e-10 * S0


def discrete_volterra(steps):
    """ε_n of the right rectangle rule, solved here scalar by scalar."""
    k = T_END / steps
    eps = np.empty(steps + 1)
    eps[0] = S0 / E0
    for n in range(1, steps + 1):
        hist = k * sum(EM * np.exp(-(n - j) * k / TAU) * eps[j] for j in range(1, n))
        eps[n] = (S0 - hist) / (E0 + k * EM)
    return eps


@pytest.fixture(scope="module")
def column_runs():
    return {N: run(column_scene(N)) for N in (20, 40, 80)}


def test_column_first_order_in_k(column_runs):
    errors = {}
    for N, (problem, sol) in column_runs.items():
        eps = column_strain(problem, sol)
        assert eps[0] == pytest.approx(S0 / E0, rel=1e-12)   # u_0: elastic, no memory
        # the FE strains are the scalar scheme's (the field is in V^h)
        np.testing.assert_allclose(eps, discrete_volterra(N), rtol=1e-11)
        # and the stress is uniaxial: σ_xx = s0, σ_xy = σ_yy = 0 in every cell
        np.testing.assert_allclose(sol.stress[:, :, 0, 0], S0, rtol=1e-10)
        assert np.abs(sol.stress[:, :, 1, :]).max() <= 1e-10 * S0
        errors[N] = np.abs(eps - exact_strain(sol.t)).max()
    orders = [np.log2(errors[20] / errors[40]), np.log2(errors[40] / errors[80])]
    for p in orders:
        assert 0.9 <= p <= 1.1
    # Error constant. The right rectangle rule errs by (k/2)[f(t) − f(0)] +
    # O(k²) for f(s) = E_m e^{−(t−s)/τ} ε(s), so e = ε_n − ε(t_n) solves
    # e + (E_m/E) ∫ e^{−(t−s)/τ} e = ψ + O(k²) with
    # |ψ| ≤ (k/2)(E_m/E) max|ε(t) − e^{−t/τ} ε(0)| ≤ (k/2)(E_m/E)(s0/E),
    # since s0/(Eτa) ≤ ε ≤ s0/E. The resolvent of κ e^{−t/τ} (κ = E_m/E) is
    # κ e^{−(1/τ+κ)t}, of integral ≤ 1, so |e| ≤ 2|ψ|: C = (E_m/E)(s0/E).
    C = EM / E0 * S0 / E0
    for N, err in errors.items():
        assert err <= C * (T_END / N)


def test_function_kernel_column_matches_prony(column_runs):
    problem, sol = column_runs[40]
    problem_f, sol_f = run(column_scene(40, kernel="function"))
    # Tolerance: same equations, different summation order of the history
    # (recursion vs direct sum): round-off only.
    assert relative_max(sol_f.u, sol.u) < 1e-12
    assert relative_max(sol_f.stress, sol.stress) < 1e-12
