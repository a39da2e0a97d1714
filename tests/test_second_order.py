"""The second-order scheme (time.scheme = "second-order", docs/scheme.md):

- the trapezoidal memory: the Prony recursion and the general kernel's sum
  against the trapezoidal sum written out here, both against the closed
  form ∫_0^t e^{−(t−s)/τ} s ds (second order), and a viscoelastic column
  against the closed-form solution of its Volterra equation (second order
  in k, where the paper's rule is first order), and a standard linear
  solid relaxing at a held strain against the trapezoid's closed form (2.1 %
  too far at k/τ = 0.5, the paper's 27 %);
- the exponential midpoint integrator at frozen displacement: second order
  against a closed form and a high-order Runge–Kutta solution, exact for
  the Frémond law's linear rate, and β in [0, 1] far beyond the explicit
  bound;
- the scene key: default "paper", bit-identical with and without it, and
  the committed h-study record of scene (a) reproduced by the paper's scheme;
  a first-order integrator named with the second-order scheme refused;
- a small k-study on scene (a) (glue held while slipping, no set change):
  rate ≥ 1.9 for E, where the paper's scheme gives about 1.
"""

import json
import tomllib
from pathlib import Path

import numpy as np
import pytest
from conftest import (SLS_E_1, SLS_E_INF, SLS_STRAIN, assert_refused, held_strain_run, prony,
                      run, scene_dict, solve_scene)
from scipy.integrate import solve_ivp

from adhesive_contact import SceneError, build_problem, scene_from_dict, solve
from adhesive_contact.laws import Fremond
from adhesive_contact.bonding import FacetRate, advance
from adhesive_contact.scheme.memory import FunctionMemory
from test_scheme_memory import prony_memory, uniform
from adhesive_contact import compile_expression
from adhesive_contact.studies.levels import run_level, run_reference

ROOT = Path(__file__).resolve().parents[1]
SCENE_A = ROOT / "studies" / "convergence" / "a_separated_slipping.toml"


def rates(errors):
    errors = np.asarray(errors)
    return np.log2(errors[:-1] / errors[1:])


# --------------------------------------------------------------------------
# The trapezoidal memory
# --------------------------------------------------------------------------

def trapezoidal_sum(k, kernel, us, n):
    """k [½ r(t_n) u_0 + Σ_{j=1}^{n−1} r(t_n − t_j) u_j], written out (u_n's
    ½ k r(0) is in the step matrix)."""
    out = 0.5 * k * kernel(n * k) * us[0]
    for j in range(1, n):
        out = out + k * kernel((n - j) * k) * us[j]
    return out


def test_trapezoidal_prony_recursion_equals_the_trapezoidal_sum(rng):
    lam, mu, tau = np.array([120.0, 30.0]), np.array([80.0, 45.0]), np.array([0.3, 2.0])
    k, steps, ndofs = 0.02, 50, 40
    us = rng.standard_normal((steps + 1, ndofs))   # u_0 .. u_N
    mem = prony_memory(lam, mu, tau, ndofs, trapezoid=True, u0=us[0])
    # the j = n weight is k/2
    np.testing.assert_allclose(mem.instantaneous(k), (0.5 * k * lam.sum(), 0.5 * k * mu.sum()),
                               rtol=1e-15)
    histories = uniform(mem, k, us[1:])
    for n in range(1, steps + 1):
        h = np.array([trapezoidal_sum(k, lambda t, tau=t_: np.exp(-t / tau), us, n)
                      for t_ in tau])
        a_lam, a_mu = histories[n - 1]
        # Tolerance: sums of ≤ 50 terms of size ~k|u|, round-off ~n ε_mach (as
        # tests/test_scheme_memory.py): 1e-12 leaves a margin of 100
        scale = np.abs(lam @ h).max()
        assert np.abs(a_lam - lam @ h).max() < 1e-12 * scale
        assert np.abs(a_mu - mu @ h).max() < 1e-12 * np.abs(mu @ h).max()


def test_trapezoidal_general_kernel_equals_the_trapezoidal_sum(rng):
    lam, mu, k, steps, ndofs = 70.0, 35.0, 0.05, 30, 12
    us = rng.standard_normal((steps + 1, ndofs))
    func = FunctionMemory(compile_expression("1/(1 + t)**2"), lam, mu, True, 0.0, (0.0,),
                          (0.0,), (us[0].copy(),))
    np.testing.assert_allclose(func.instantaneous(k), (0.5 * k * lam, 0.5 * k * mu), rtol=1e-15)
    histories = uniform(func, k, us[1:])
    for n in range(1, steps + 1):
        ref = trapezoidal_sum(k, lambda t: 1.0 / (1.0 + t) ** 2, us, n)
        a_lam, a_mu = histories[n - 1]
        assert np.abs(a_lam - lam * ref).max() < 1e-12 * np.abs(lam * ref).max()
        assert np.abs(a_mu - mu * ref).max() < 1e-12 * np.abs(mu * ref).max()


def test_trapezoidal_memory_is_second_order_for_a_closed_form_integral():
    """∫_0^1 e^{−(1−s)/τ} s ds = τ − τ² (1 − e^{−1/τ}) for u(s) = s: the
    history plus the step matrix's ½ k u_n, second order (rates 2 ± 0.05 on
    halving k from 1/10); the rectangle rule first order."""
    tau = 0.3
    exact = tau - tau ** 2 * (1.0 - np.exp(-1.0 / tau))
    errs = {True: [], False: []}
    for trapezoid in (True, False):
        for N in (10, 20, 40, 80):
            k = 1.0 / N
            mem = prony_memory([1.0], [0.0], [tau], 1, trapezoid, np.array([0.0]))
            a_lam, _ = uniform(mem, k, [np.array([n * k]) for n in range(1, N + 1)])[-1]
            value = a_lam[0] + mem.instantaneous(k)[0] * 1.0   # + w R(0) u(1)
            errs[trapezoid].append(abs(value - exact))
    assert np.all(np.abs(rates(errs[True]) - 2.0) < 0.05)
    assert np.all(np.abs(rates(errs[False]) - 1.0) < 0.1)


# A viscoelastic column in uniform uniaxial strain (tests/test_scheme_memory.py):
# E ε(t) + ∫_0^t E_m e^{−(t−s)/τ} ε(s) ds = s0, ε(t) = (s0/E)[1/(τa) + (1 − 1/(τa))
# e^{−at}], a = 1/τ + E_m/E; the field is in V^h, so the time error is the only one.
E0, EM, TAU, S0, T_END = 1000.0, 500.0, 0.5, 10.0, 2.0
A = 1.0 / TAU + EM / E0


def exact_strain(t):
    return S0 / E0 * (1.0 / (TAU * A) + (1.0 - 1.0 / (TAU * A)) * np.exp(-A * t))


def column_strain_error(steps, scheme, kernel="prony"):
    memory = (prony((EM, 0.0, TAU)) if kernel == "prony" else
              {"kernel": "function", "r": f"exp(-t/{TAU!r})", "E": EM, "nu": 0.0})
    problem, sol = run(scene_dict({
        "mesh.size": [4.0, 1.0], "mesh.cells": [8, 2],
        "boundary": {"dirichlet": ["left"]}, "material": {"E": E0, "nu": 0.0},
        "memory": memory, "loads.traction.right": [repr(S0), "0"],
        "time": {"T": T_END, "steps": steps, "scheme": scheme}}))
    x = problem.mesh.p[0]
    eps = sol.u[:, np.isclose(x, 4.0), 0].mean(axis=1) / 4.0
    # σ_xx = s0 in every cell: the stress adds the same (k/2) R(0) the step used
    np.testing.assert_allclose(sol.stress[:, :, 0, 0], S0, rtol=1e-10)
    return np.abs(eps - exact_strain(sol.t)).max()


@pytest.mark.parametrize("kernel", ["prony", "function"])
def test_column_second_order_in_k(kernel):
    second = [column_strain_error(N, "second-order", kernel) for N in (20, 40, 80)]
    paper = [column_strain_error(N, "paper", kernel) for N in (20, 40, 80)]
    # the trapezoidal rule's error is C k² + O(k⁴) for this smooth ε: rate 2 ± 0.05
    assert np.all(np.abs(rates(second) - 2.0) < 0.05)
    assert np.all(np.abs(rates(paper) - 1.0) < 0.1)
    assert second[-1] < 0.05 * paper[-1]


# --------------------------------------------------------------------------
# The exponential midpoint integrator at frozen displacement
# --------------------------------------------------------------------------

class Quadratic:
    """f(β) = −c β² with ∂f/∂β = −2 c β: β(t) = β_0 / (1 + c β_0 t)."""

    def __init__(self, c):
        self.c = c

    def __call__(self, beta):
        return -self.c * beta ** 2, -2.0 * self.c * beta


class Saturating:
    """f(β) = −s β / (1 + β) + e (1 − β)²: nonlinear, with a root in (0, 1)."""

    def __init__(self, s, e):
        self.s, self.e = s, e

    def __call__(self, beta):
        f = -self.s * beta / (1.0 + beta) + self.e * (1.0 - beta) ** 2
        return f, -self.s / (1.0 + beta) ** 2 - 2.0 * self.e * (1.0 - beta)


def integrate(name, rate, T, N, beta0=1.0):
    beta = np.array([beta0])
    for _ in range(N):
        beta = advance(name, rate, beta, T / N)
    return beta[0]


def test_midpoint_second_order_against_the_closed_form():
    c, T = 3.0, 1.0
    exact = 1.0 / (1.0 + c * T)
    errs = [abs(integrate("midpoint", Quadratic(c), T, N) - exact) for N in (8, 16, 32, 64)]
    assert np.all(rates(errs) >= 1.9)
    euler = [abs(integrate("explicit", Quadratic(c), T, N) - exact) for N in (8, 16, 32, 64)]
    assert np.all(rates(euler) < 1.2)   # the paper's, first order, for contrast


def test_midpoint_second_order_against_a_runge_kutta_solution():
    rate, T = Saturating(4.0, 0.5), 2.0
    out = solve_ivp(lambda t, b: rate(b)[0], (0, T), [1.0], method="DOP853",
                    rtol=1e-13, atol=1e-15)
    reference = out.y[0, -1]
    errs = [abs(integrate("midpoint", rate, T, N) - reference) for N in (8, 16, 32, 64)]
    assert np.all(rates(errs) >= 1.9)
    assert errs[-1] < 1e-4


def fremond_facet(stretch, eps_a):
    """One facet with points of stretches γ_ν R_ν(r)² (γ_ν = 1, L large)."""
    law_ = Fremond(gamma_nu=1.0, gamma_tau=0.0, eps_a=eps_a, L=10.0)
    r = -np.sqrt(np.asarray(stretch, dtype=float))
    return FacetRate(law_, r, None, lambda b: np.repeat(b, r.size),
                     lambda v: np.array([v.mean()]))


def test_midpoint_exact_for_the_linear_fremond_rate():
    """Both points loaded throughout: β' = −Q β + e, β(t) = e/Q + (1 − e/Q) e^{−Qt}."""
    rate = fremond_facet([2.0, 1.0], 0.1)   # Q = 1.5, e = 0.1; β stays above 0.1
    Q, e, T = 1.5, 0.1, 1.0
    exact = e / Q + (1.0 - e / Q) * np.exp(-Q * T)
    assert abs(integrate("midpoint", rate, T, 5) - exact) < 1e-14


@pytest.mark.parametrize("k", [0.1, 1.0, 10.0, 1e3])
def test_midpoint_keeps_beta_in_0_1_beyond_the_explicit_bound(k):
    """Stretch 50: the explicit bound is k ≤ 1/50; a point crosses the
    threshold β s = ε_a (β = 0.006) on the way."""
    rate = fremond_facet([50.0, 5.0], 0.3)
    beta = np.array([1.0])
    for _ in range(20):
        beta = advance("midpoint", rate, beta, k)
        assert 0.0 <= beta[0] <= 1.0
    assert integrate("explicit", rate, 20 * k, 20) < 0.0   # explicit Euler leaves [0, 1]


# --------------------------------------------------------------------------
# The scene key and the paper's scheme unchanged
# --------------------------------------------------------------------------

def scene_a(**time):
    data = tomllib.loads(SCENE_A.read_text())
    data["time"].update(time)
    return data


def test_default_is_the_paper_and_explicit_paper_is_bit_identical():
    data = scene_a(steps=8)
    assert scene_from_dict(data).scheme == "paper"
    default = solve(build_problem(scene_from_dict(data)))
    paper = solve(build_problem(scene_from_dict(scene_a(steps=8, scheme="paper"))))
    assert np.array_equal(default.u, paper.u) and np.array_equal(default.beta, paper.beta)
    second = solve(build_problem(scene_from_dict(scene_a(steps=8, scheme="second-order"))))
    assert second.success and not np.array_equal(second.u, paper.u)


def test_paper_scheme_reproduces_the_committed_h_study_record():
    """Level 0 of studies/convergence/results/a_separated_slipping-h, computed
    before the second-order scheme existed: the same errors against the exact
    solution (to 1e-12 relative, room for another machine's BLAS only)."""
    folder = ROOT / "studies" / "convergence" / "results" / "a_separated_slipping-h"
    record = json.loads((folder / "levels" / "level_00.json").read_text())
    scene = scene_from_dict(scene_a(steps=record["steps"]))
    level = run_level(scene, "h", 0)
    assert level["steps"] == record["steps"] and level["dofs"] == record["dofs"]
    for key in ("err_u", "err_beta", "E"):
        assert level[key] == pytest.approx(record[key], rel=1e-12, abs=0.0)


def test_second_order_refuses_a_first_order_integrator():
    data = scene_a(steps=4, scheme="second-order")
    data["contact"]["bonding"]["integrator"] = "implicit"
    with pytest.raises(SceneError, match="contact.bonding.integrator.*midpoint"):
        scene_from_dict(data)
    data["contact"]["bonding"]["integrator"] = "midpoint"
    assert scene_from_dict(data).contact.integrator == "midpoint"
    del data["contact"]["bonding"]["integrator"]
    assert scene_from_dict(data).contact.integrator == "midpoint"
    assert scene_from_dict(scene_a(steps=4)).contact.integrator == "explicit"


def test_cli_refuses_a_bad_scheme_and_a_first_order_integrator_in_one_line(tmp_path):
    (tmp_path / "a").mkdir(), (tmp_path / "b").mkdir()
    data = scene_a(steps=4, scheme="third-order")
    result, out = solve_scene(tmp_path / "a", data)
    assert_refused(result, out, "time.scheme: must be one of 'paper', 'second-order'")
    data = scene_a(steps=4, scheme="second-order")
    data["contact"]["bonding"]["integrator"] = "exponential"
    result, out = solve_scene(tmp_path / "b", data)
    assert_refused(result, out, "contact.bonding.integrator: time.scheme = \"second-order\"")


# --------------------------------------------------------------------------
# A small k-study: the glue held while slipping (scene (a), no set change)
# --------------------------------------------------------------------------

def k_study(scheme, levels=3):
    """E of levels 4, 8, 16 steps on the 4 x 4 mesh against a reference of
    16 x the finest level's steps (the committed k-studies' set-up)."""
    scene = scene_from_dict(scene_a(steps=4, scheme=scheme))
    reference = run_reference(scene, "k", levels)
    return [run_level(scene, "k", level, reference)["E"] for level in range(levels)]


def test_k_study_second_order_where_the_paper_is_first_order():
    second, paper = k_study("second-order"), k_study("paper")
    assert np.all(rates(second) >= 1.9)
    assert np.all(np.abs(rates(paper) - 1.0) < 0.15)
    # rates 2 and 1: the ratio of the errors halves a level (1.3, 0.6, 0.3 here)
    assert second[-1] < 0.5 * paper[-1]


# --------------------------------------------------------------------------
# Relaxation at a held strain: the trapezoid's closed form
# --------------------------------------------------------------------------
#
# A standard linear solid E(t) = E_∞ + E_1 e^{−t/τ} (ν = 0) stretched at t = 0
# to a strain ε held for ever: σ(t) = E(t) ε. With c = k/τ and u_n = u_0 the
# trapezoidal rule gives σ_n/ε = E_0 − E_1 c [½ e^{−nc} + Σ_{i=1}^{n−1} e^{−ic}
# + ½], which tends to E_∞ − E_1 ((c/2) coth(c/2) − 1): 2.1 % of E_∞ too low
# at k/τ = 0.5 (the paper's rule: E_1 (c/(1 − e^{−c}) − 1), 27 %).

E_INF, E_1, STRAIN = SLS_E_INF, SLS_E_1, SLS_STRAIN


def relaxation_stress(steps, T, scheme):
    sol = held_strain_run(steps, T, scheme)
    return sol.stress[:, :, 0, 0].mean(axis=1)   # uniform: σ_xx in every cell


def test_relaxation_at_a_held_strain_follows_the_trapezoid_closed_form():
    c, steps = 0.5, 40   # k/τ = 0.5 to T = 20 τ
    sigma = relaxation_stress(steps, c * steps, "second-order")
    n = np.arange(1, steps + 1)
    sums = np.array([np.exp(-c * np.arange(1, m)).sum() for m in n])
    closed = (E_INF + E_1) - E_1 * c * (0.5 * np.exp(-n * c) + sums + 0.5)
    # Tolerance: round-off of P1 solves on a uniform field (as test_scheme_memory)
    np.testing.assert_allclose(sigma[1:] / STRAIN, closed, rtol=1e-10)
    limit = E_INF - E_1 * (0.5 * c / np.tanh(0.5 * c) - 1.0)
    assert abs(sigma[-1] / STRAIN - limit) < 1e-6 * E_INF      # e^{−20} of the way left
    assert 0.019 < 1.0 - limit / E_INF < 0.022                 # 2.1 % at k/τ = 0.5
    paper = relaxation_stress(steps, c * steps, "paper")[-1] / STRAIN
    assert 0.26 < 1.0 - paper / E_INF < 0.28                   # 27 %
