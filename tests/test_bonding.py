"""The bonding field β (docs/scheme.md, §6): the Frémond law integrated by
explicit Euler (4.2),

    β_n = β_{n−1} + k P_B F(u_{n−1,ν}, u_{n−1,τ}, β_{n−1}),
    F(r, ξ, β) = −(β (γ_ν R_ν(r)² + γ_τ |R_τ(ξ)|²) − ε_a)_+,

with P_B the facet mean: with the nodal rule, the mean of the values at the
facet's two vertices (trapezoid rule, weights |f|/2).

- the debonding study scene, coarsened: β ∈ [0, 1], non-increasing, each
  update equal to (4.2) recomputed here from the run's u; the strip debonds
  at its pulled end only, and the separation there grows;
- a frozen displacement (u independent of β and of t): β_n = (1 − k Q_f)^n β_0
  exactly, and first-order convergence to β_0 e^{−Q_f t};
- the threshold ε_a: no change where every point's stretch β Q is below it;
- P_B of β_0: facet means.

The reference quantities are computed here from the solution's Cartesian u
at the facet vertices (u_ν = −u_y, u_τ = u_x on the bottom side, ν = (0, −1)),
with this file's own R_ν, R_τ and F.
"""

import tomllib
from pathlib import Path

import numpy as np
import pytest
from conftest import law, reference_mesh, run, same_mesh, scene_dict

from adhesive_contact import build_problem, scene_from_dict, solve

SCENES = Path(__file__).resolve().parents[1] / "studies" / "scenes"


def R_nu(r, L):
    """Separation capped at L: min(max(−r, 0), L)."""
    return np.minimum(np.maximum(-r, 0.0), L)


def R_tau(xi, L):
    """ξ truncated to |ξ| ≤ L (scalar ξ in 2D)."""
    return np.clip(xi, -L, L)


def bottom_facets(problem, size, cells):
    """Vertices (2, nf) of the library's contact facets, in the library's
    order, checked against the bottom edges of our own mesh: consecutive
    bottom vertices sorted by x."""
    mesh = reference_mesh(size, cells)
    same_mesh(problem, mesh)
    nodes = np.flatnonzero(np.isclose(mesh.p[1], 0.0))
    nodes = nodes[np.argsort(mesh.p[0, nodes])]
    ours = {frozenset(e) for e in zip(nodes[:-1], nodes[1:])}
    fn = problem.boundary.facet_nodes
    assert fn.shape[1] == len(ours)
    assert {frozenset(e) for e in fn.T} == ours
    return fn, mesh


# --------------------------------------------------------------------------
# The debonding study scene, coarsened
# --------------------------------------------------------------------------

COARSE_CELLS, COARSE_STEPS = [40, 4], 16


@pytest.fixture(scope="module")
def debonding():
    data = tomllib.loads((SCENES / "debonding.toml").read_text())
    data["mesh"]["cells"] = COARSE_CELLS
    data["time"]["steps"] = COARSE_STEPS
    problem = build_problem(scene_from_dict(data))
    return data, problem, solve(problem)


def test_debonding_euler_bound_and_no_warning(debonding):
    data, problem, _ = debonding
    b = data["contact"]["bonding"]
    k = data["time"]["T"] / data["time"]["steps"]
    # the explicit Euler bound k (γ_ν + γ_τ) L² ≤ 1, from the TOML values
    assert k * (b["gamma_nu"] + b["gamma_tau"]) * b["L"] ** 2 <= 1.0
    assert not any("explicit Euler" in w for w in problem.warnings())


def test_debonding_beta_in_unit_interval_and_nonincreasing(debonding):
    _, _, sol = debonding
    beta = sol.beta
    assert np.all(beta >= 0.0) and np.all(beta <= 1.0)
    assert np.all(np.diff(beta, axis=0) <= 0.0)
    np.testing.assert_array_equal(beta[0], 1.0)      # β_0 = 1


def test_debonding_updates_are_explicit_euler(debonding):
    """Each β_n is (4.2) recomputed from u_{n−1} (both the normal and the
    tangential stretch act: γ_τ > 0 and the strip slides)."""
    data, problem, sol = debonding
    b = data["contact"]["bonding"]
    gn, gt, eps, L = b["gamma_nu"], b["gamma_tau"], b["eps_a"], b["L"]
    fn, _ = bottom_facets(problem, data["mesh"]["size"], COARSE_CELLS)
    k = data["time"]["T"] / data["time"]["steps"]
    for n in range(1, sol.steps + 1):
        u = sol.u[n - 1]
        beta = sol.beta[n - 1]
        F = [-np.maximum(np.clip(beta, 0, 1) * (gn * R_nu(-u[v, 1], L) ** 2
                                                 + gt * R_tau(u[v, 0], L) ** 2) - eps, 0.0)
             for v in fn]
        expected = beta + k * 0.5 * (F[0] + F[1])
        # Tolerance: round-off of a few operations on O(1) numbers.
        np.testing.assert_allclose(sol.beta[n], expected, rtol=0, atol=1e-14)
    # the update really acted, with both stretches (γ_τ |R_τ|² is not zero)
    assert sol.beta[-1].min() < 0.01
    assert np.abs(sol.frame_displacement[:, :, 1]).max() > 0


def test_strip_pulled_off_debonds_at_its_end(debonding):
    data, problem, sol = debonding
    fn, mesh = bottom_facets(problem, data["mesh"]["size"], COARSE_CELLS)
    x_mid = mesh.p[0, fn].mean(axis=0)
    beta = sol.beta[-1]
    # the traction pulls the right end (x = 4) up and right: debonded there
    # (measured β ≤ 1.3e-3 for x_mid > 3.7), bonded far away (measured
    # β ≥ 0.99998 for x_mid < 2, ≥ 0.9993 up to 2.5)
    assert np.all(beta[x_mid > 3.7] < 1e-2)
    assert np.all(beta[x_mid < 2.0] > 0.999)
    # the separation −u_ν = u_y at the pulled end grows in time
    bnd = problem.boundary
    end = np.argmax(problem.mesh.p[0, bnd.nodes])
    assert np.isclose(problem.mesh.p[0, bnd.nodes[end]], data["mesh"]["size"][0])
    separation = -sol.frame_displacement[:, end, 0]
    np.testing.assert_array_equal(separation, sol.u[:, bnd.nodes[end], 1])
    assert separation[0] == 0.0                     # no load at t = 0
    assert np.all(np.diff(separation) > 0)
    # far beyond the glue's reach L (measured 0.22 = 22 L)
    assert separation[-1] > 10 * data["contact"]["bonding"]["L"]


# --------------------------------------------------------------------------
# A frozen displacement
# --------------------------------------------------------------------------
#
# [0, 2] x [0, 0.5], 16 x 4 cells, left clamped, bottom = Γ_C, a constant
# upward traction on the right end: a cantilever lifted off its foundation,
# u_ν = −u_y < 0 on Γ_C (0 at the clamp, ~0.025 at x = 2). The normal law is
# plain compliance, which does not use β and does not act in separation;
# no friction, no memory, constant loads: u_n is the same for every n and
# does not depend on β. With γ_τ = 0, ε_a = 0 and 0 ≤ β ≤ 1,
#
#     P_B F = −β_f Q_f,   Q_f = ½ γ_ν (R_ν(u_ν,a)² + R_ν(u_ν,b)²)
#
# on the facet f = [a, b], so explicit Euler gives β_n = (1 − k Q_f)^n β_0
# exactly and the exact solution is β_0 e^{−Q_f t}. L = 0.01 caps the
# separation on the outer part of the strip (|u_ν| > L) but not near the
# clamp; γ_ν L² = 2.5, so Q_f ∈ [0, 2.5] and the Euler bound holds for N ≥ 3.

FROZEN_SIZE, FROZEN_CELLS = (2.0, 0.5), (16, 4)
GAMMA, LF = 25000.0, 0.01


def frozen(steps, eps_a=0.0, beta0="1 - 0.2*x"):
    return scene_dict({
        "mesh.size": list(FROZEN_SIZE), "mesh.cells": list(FROZEN_CELLS),
        "boundary.dirichlet": ["left"], "loads.traction.right": ["0", "0.2"],
        "contact.normal": law("compliance", c=10000.0),
        "contact.bonding": law("fremond", beta0=beta0, gamma_nu=GAMMA, gamma_tau=0.0,
                               eps_a=eps_a, L=LF),
        "time.steps": steps})


def stretch_at_vertices(problem, sol):
    """γ_ν R_ν(u_ν)² at the two vertices of each facet (2, nf), from u_0,
    after checking that u_n = u_0 for every n, and the facet midpoints."""
    fn, mesh = bottom_facets(problem, FROZEN_SIZE, FROZEN_CELLS)
    u = sol.u[0]
    # Tolerance: u_n solves the same problem for every n (warm started at
    # u_{n−1}, 0 iterations): equal to round-off.
    assert np.abs(sol.u - u).max() <= 1e-13 * np.abs(u).max()
    r = -u[fn, 1]                                   # u_ν = −u_y, (2, nf)
    return GAMMA * R_nu(r, LF) ** 2, mesh.p[0, fn].mean(axis=0)


@pytest.fixture(scope="module")
def frozen_runs():
    return {N: run(frozen(N)) for N in (10, 20, 40)}


def test_frozen_displacement_regimes(frozen_runs):
    problem, sol = frozen_runs[10]
    # (the smallness warning is expected: c = 1e4 is far outside the
    # sufficient condition; the step energy is convex all the same)
    assert not any("explicit Euler" in w for w in problem.warnings())
    r = sol.normal_displacement[0]
    # separated everywhere off the clamp; both within and beyond the cap L
    assert np.all(r <= 0) and (r[r < 0] > -LF).any() and (r < -LF).any()


def test_explicit_euler_is_exact_geometric_decay(frozen_runs):
    """β_n = (1 − k Q_f)^n β_0 on each facet, to round-off."""
    for N, (problem, sol) in frozen_runs.items():
        Qv, x_mid = stretch_at_vertices(problem, sol)
        Q = Qv.mean(axis=0)
        beta0 = 1 - 0.2 * x_mid
        k = 1.0 / N
        n = np.arange(N + 1)[:, None]
        expected = (1 - k * Q) ** n * beta0
        # Tolerance: N ≤ 40 updates, each a few roundings (≲ 4 ε relative),
        # against a power: ≲ 40·4·1.1e-16 ≈ 2e-14 relative (measured
        # ≤ 2.3e-15); 1e-12 leaves a wide margin.
        np.testing.assert_allclose(sol.beta, expected, rtol=1e-12, atol=0)


def test_explicit_euler_first_order(frozen_runs):
    """max_f |β_N − β_0 e^{−Q_f T}| halves when k halves."""
    errors = []
    for N, (problem, sol) in frozen_runs.items():
        Qv, x_mid = stretch_at_vertices(problem, sol)
        exact = (1 - 0.2 * x_mid) * np.exp(-Qv.mean(axis=0) * problem.scene.T)
        errors.append(np.abs(sol.beta[-1] - exact).max())
    errors = np.array(errors)
    orders = np.log2(errors[:-1] / errors[1:])
    print(f"\nEuler errors at T for N = 10, 20, 40: {errors}, observed orders {orders}")
    # Tolerance: the error is k Q² T e^{−QT} β_0 / 2 + O(k²); with kQ ≤ 0.25
    # the O(k²) part shifts the observed order by a few 0.01.
    assert np.all((orders >= 0.9) & (orders <= 1.1))
    assert errors[0] > 1e-3                      # a real error, not round-off


def test_threshold_eps_a_freezes_weakly_stretched_facets():
    """With ε_a > 0, F = 0 at a point where β Q_q ≤ ε_a: a facet whose two
    points are both below keeps β exactly; the others follow (4.2)."""
    N = 10
    eps_a = 0.8
    problem, sol = run(frozen(N, eps_a=eps_a))
    Qv, _ = stretch_at_vertices(problem, sol)
    k = 1.0 / N
    counts = []
    for n in range(1, N + 1):
        prev = sol.beta[n - 1]
        frozen_f = (prev * Qv <= eps_a).all(axis=0)
        counts.append(frozen_f.sum())
        # exactly unchanged where F = 0 at both points
        np.testing.assert_array_equal(sol.beta[n][frozen_f], prev[frozen_f])
        # decreasing by k · mean_q (β Q_q − ε_a)_+ elsewhere
        drop = k * np.maximum(prev * Qv - eps_a, 0.0).mean(axis=0)
        np.testing.assert_allclose(sol.beta[n][~frozen_f], (prev - drop)[~frozen_f],
                                   rtol=0, atol=1e-15)
        assert np.all(sol.beta[n][~frozen_f] < prev[~frozen_f])
    # both kinds of facets occur throughout
    assert min(counts) > 0 and max(counts) < Qv.shape[1]


def test_beta0_projected_to_facet_means():
    """β_0^h = P_B β_0: the facet mean, which for a linear β_0 is its value
    at the midpoint, and for a quadratic one is not."""
    problem, sol = run(frozen(1, beta0="0.5 + 0.25*x"))
    _, mesh = bottom_facets(problem, FROZEN_SIZE, FROZEN_CELLS)
    fn = problem.boundary.facet_nodes
    x0, x1 = mesh.p[0, fn]
    mid = 0.5 * (x0 + x1)
    # Tolerance: a Gauss rule on O(1) values, round-off only.
    np.testing.assert_allclose(problem.beta0, 0.5 + 0.25 * mid, rtol=0, atol=1e-15)
    np.testing.assert_array_equal(sol.beta[0], problem.beta0)

    quadratic = build_problem(scene_from_dict(frozen(1, beta0="x*x/4")))
    mean = (x1 ** 3 - x0 ** 3) / (12 * (x1 - x0))   # (1/|f|) ∫_f x²/4
    np.testing.assert_allclose(quadratic.beta0, mean, rtol=0, atol=1e-15)
    assert np.abs(quadratic.beta0 - mid ** 2 / 4).min() > 1e-4   # not the midpoint value
