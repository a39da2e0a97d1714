"""Integrators of the bonding ODE (contact.bonding.integrator): explicit
Euler (the paper's), backward Euler in β and exponential Euler.

- at frozen displacement, against the exact ODE β' = P_B F(u, β)
  (solved here by a high-order Runge–Kutta method at tolerance 1e-13):
  explicit and implicit Euler are first order (the error halves with k),
  exponential Euler's error over k does not grow as k → 0 and it is exact
  while the rate is linear in β;
- on a scene at frozen displacement: each integrator's closed form
  (1 − kQ)^n, (1 + kQ)^{−n}, e^{−nkQ}, to round-off;
- beyond the explicit bound k (γ_ν + γ_τ) L² ≤ 1: implicit and
  exponential keep β in [0, 1] (explicit Euler stops with InvalidState,
  tests/test_checks.py) and the message names them.
"""

import tomllib
from pathlib import Path

import numpy as np
import pytest
from conftest import law, run, scene_dict
from scipy.integrate import solve_ivp

from adhesive_contact import SceneError, build_problem, scene_from_dict, solve
from adhesive_contact.bonding import INTEGRATORS, FacetRate, advance
from adhesive_contact.studies.levels import with_discretisation
from adhesive_contact.laws import Fremond
from adhesive_contact.laws.bonding import BEYOND_TIME_SCALE

ROOT = Path(__file__).resolve().parents[1]


def one_facet(stretch, eps_a):
    """The facet-wise rate of one facet with two points of the given
    stretches γ_ν R_ν(r)² (γ_ν = 1, r = −√stretch, L large)."""
    law_ = Fremond(gamma_nu=1.0, gamma_tau=0.0, eps_a=eps_a, L=10.0)
    r = -np.sqrt(np.asarray(stretch, dtype=float))
    return FacetRate(law_, r, None, lambda b: np.repeat(b, r.size),
                     lambda v: np.array([v.mean()]))


def exact(rate, T, beta0=1.0):
    out = solve_ivp(lambda t, b: rate(b)[0], (0, T), [beta0], method="DOP853",
                    rtol=1e-13, atol=1e-15, max_step=1e-3)
    return out.y[0, -1]


def errors(name, rate, T, steps):
    reference = exact(rate, T)
    out = []
    for N in steps:
        beta = np.array([1.0])
        for _ in range(N):
            beta = advance(name, rate, beta, T / N)
        out.append(abs(beta[0] - reference))
    return np.array(out)


# a point crosses the threshold β s = ε_a at β = 0.5 while the other stays
# below it from the start: the rate is piecewise linear in β
CROSSING = dict(stretch=[2.0, 0.6], eps_a=0.3)
STEPS = (10, 20, 40, 80, 160)


@pytest.mark.parametrize("name", ["explicit", "implicit"])
def test_euler_methods_are_first_order_at_frozen_displacement(name):
    err = errors(name, one_facet(**CROSSING), 1.5, STEPS)
    # first order: the ratio tends to 2 (measured 1.96–2.04 over these k);
    # [1.8, 2.2] would fail for order 1/2 (1.41) and order 2 (4)
    ratios = err[:-1] / err[1:]
    assert np.all((ratios > 1.8) & (ratios < 2.2)), ratios


def test_exponential_euler_is_first_order_and_exact_for_a_linear_rate():
    err = errors("exponential", one_facet(**CROSSING), 1.5, STEPS)
    k = 1.5 / np.array(STEPS)
    # only the step in which the point crosses the threshold errs, by O(k²)
    # locally: error/k does not grow as k → 0 (measured: it falls 8-fold)
    assert np.all(err / k <= err[0] / k[0]) and err[-1] < err[0] / 10
    # and it is below explicit Euler's at every k (measured ≥ 100× below)
    assert np.all(err < errors("explicit", one_facet(**CROSSING), 1.5, STEPS) / 10)
    # ε_a = 0: the rate −β mean(s) is linear, e^{−k mean(s)} per step is exact
    linear = errors("exponential", one_facet([2.0, 0.6], 0.0), 1.5, (3,))
    assert linear[0] <= 1e-13


@pytest.mark.parametrize("name", sorted(INTEGRATORS))
def test_each_integrator_keeps_beta_in_the_unit_interval_or_says_it_cannot(name):
    """One step with k s = 3 (three times the explicit bound)."""
    rate = one_facet([3.0, 3.0], 0.0)
    beta = advance(name, rate, np.array([1.0]), 1.0)[0]
    expected = {"explicit": 1.0 - 3.0, "implicit": 1.0 / 4.0, "exponential": np.exp(-3.0),
                "midpoint": np.exp(-3.0)}   # both exact for a linear rate
    assert beta == pytest.approx(expected[name], rel=1e-14)


# --------------------------------------------------------------------------
# On a scene: frozen displacement (the strip of tests/test_bonding.py: only
# the normal stretch, ε_a = 0, u independent of β), each integrator's
# closed form per facet with Q_f the facet mean of the stretch.

GAMMA, LF = 25000.0, 0.01


def frozen(steps, integrator):
    return scene_dict({
        "mesh.size": [2.0, 0.5], "mesh.cells": [16, 4],
        "boundary.dirichlet": ["left"], "loads.traction.right": ["0", "0.2"],
        "contact.normal": law("compliance", c=10000.0),
        "contact.bonding": law("fremond", beta0="1 - 0.2*x", gamma_nu=GAMMA,
                               gamma_tau=0.0, eps_a=0.0, L=LF, integrator=integrator),
        "time.steps": steps})


CLOSED_FORMS = {"explicit": lambda kQ, n: (1 - kQ) ** n,
                "implicit": lambda kQ, n: (1 + kQ) ** (-n),
                "exponential": lambda kQ, n: np.exp(-kQ * n)}


@pytest.mark.parametrize("name", sorted(CLOSED_FORMS))
def test_integrators_on_a_scene_at_frozen_displacement(name):
    N = 10
    problem, sol = run(frozen(N, name))
    assert sol.success
    u = sol.normal_displacement
    # u_n solves the same problem for every n (u does not depend on β)
    assert np.abs(u - u[0]).max() <= 1e-13 * np.abs(u[0]).max()
    boundary = problem.boundary
    r = boundary.normal_trace @ np.ravel(sol.frame_displacement[0])
    Q = boundary.facet_mean(GAMMA * np.minimum(np.maximum(-r, 0), LF) ** 2)
    assert Q.max() > 0.5 * GAMMA * LF ** 2                 # the glue is loaded
    n = np.arange(N + 1)[:, None]
    expected = CLOSED_FORMS[name](Q / N, n) * problem.beta0
    # Tolerance: ≤ 10 updates of a few roundings each against a closed form
    # (implicit: the root to 1e-15 of β); measured ≤ 3e-15
    np.testing.assert_allclose(sol.beta, expected, rtol=1e-12, atol=1e-15)


def debonding(steps, integrator):
    text = (ROOT / "studies/scenes/debonding.toml").read_text()
    data = tomllib.loads(text)
    data["contact"]["bonding"]["integrator"] = integrator
    return build_problem(with_discretisation(scene_from_dict(data), steps=steps))


@pytest.mark.parametrize("name", ["implicit", "exponential"])
def test_beyond_the_explicit_bound_beta_stays_in_the_unit_interval(name):
    problem = debonding(6, name)
    assert problem.scene.k > problem.bonding.stable_step()
    sol = solve(problem)
    assert sol.success
    assert np.all((sol.beta >= 0) & (sol.beta <= 1)) and np.all(np.diff(sol.beta, axis=0) <= 0)
    assert sol.beta.min() < 0.5                               # it does debond
    warnings = problem.warnings()
    # not the stability warning of explicit Euler, but, once, the accuracy one
    assert not any("may leave [0, 1]" in w for w in warnings)
    beyond = [w for w in warnings if BEYOND_TIME_SCALE in w]
    assert len(beyond) == 1
    assert beyond[0].startswith("the time step k = 0.1667 is 2.5 times the explicit Euler "
                                "bound 1/((gamma_nu + gamma_tau) L^2) = 0.06667")
    assert "use at least time.steps = 15, or [time.adaptive] tol" in beyond[0]


def test_the_explicit_failure_names_the_other_integrators_and_their_cost():
    sol = solve(debonding(6, "explicit"))
    message = str(sol.failure)
    assert ("Use at least time.steps = 15 or [time.adaptive] tol; contact.bonding.integrator "
            "'implicit', 'exponential' and 'midpoint' keep beta in [0, 1] at any k, but") in message
    assert BEYOND_TIME_SCALE in message
    assert "peak peel force +40 to +43 % at 1.5 times that scale" in message
    # the step solve that gave the invalid state converged; its account is kept
    assert sol.failure.result.success and sol.failure.result.nit >= 1


def test_an_unknown_integrator_is_refused_naming_the_allowed():
    data = frozen(2, "rk4")
    with pytest.raises(SceneError, match=r"^contact\.bonding\.integrator: must be one of "
                                         r"'explicit', 'implicit', 'exponential', 'midpoint', got 'rk4'"):
        scene_from_dict(data)
