"""Verification machinery (docs/verification.md): manufactured data, nested
prolongation, errors and rates on small levels."""

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from conftest import law, scene_dict
from skfem import Basis, ElementTriP1

from adhesive_contact import build_problem, parse_scene, scene_from_dict
from adhesive_contact.fem.assembly import stiffness_basis, strain_map
from adhesive_contact.studies.levels import run_level, run_reference
from adhesive_contact.verification.rates import rates
from adhesive_contact.verification.errors import (
    cell_volumes,
    facet_parents,
    nested_meshes,
    prolongation,
    strain_error_fine,
)

ROOT = Path(__file__).resolve().parents[1]
CASES = sorted((ROOT / "studies" / "convergence").glob("[a-d]_*.toml"))


def scene_of(path, **changes):
    scene = parse_scene(Path(path).read_text())
    return replace(scene, **changes)


# ---------------------------------------------------------------- manufactured data


@pytest.fixture(scope="module", params=CASES, ids=lambda p: p.stem)
def case(request):
    return build_problem(scene_of(request.param))


def test_body_force_is_minus_div_sigma(case):
    """f_0 = −Div σ* (memory included), checked by central differences of σ*
    at interior points: error O(δ²) ≈ 1e-6 relative with δ = 1e-4."""
    ex, d = case.exact, 2
    rng = np.random.default_rng(1)
    x, y = rng.uniform(0.2, 0.8, (2, 6))
    t, delta = 0.7, 1e-4
    div = np.zeros((d, x.size))
    for j, (dx, dy) in enumerate([(delta, 0.0), (0.0, delta)]):
        plus = ex.stress(x + dx, y + dy, None, t)
        minus = ex.stress(x - dx, y - dy, None, t)
        div += (plus[:, j] - minus[:, j]) / (2 * delta)
    f = ex.body_force(x, y, None, t)
    assert np.allclose(f, -div, rtol=0, atol=1e-6 * np.abs(f).max())


def test_stress_memory_integral_against_a_fine_rectangle_sum(case):
    """σ* includes ∫_0^t R(t−s) ε(u*(s)) ds: compare with a midpoint sum of
    20000 panels (error O(1e-9) relative)."""
    ex, scene = case.exact, case.scene
    x, y, t = np.array([0.3]), np.array([0.4]), 0.8
    n = 20000
    s = (np.arange(n) + 0.5) * t / n
    es = ex.strain(np.full(n, x[0]), np.full(n, y[0]), None, s)       # (2, 2, n)
    mem = np.zeros((2, 2))
    for term in scene.memory.terms:
        lam, mu, tau = term.tensor.lam, term.tensor.mu, term.tau
        w = (t / n) * np.exp(-(t - s) / tau)
        mem += lam * (w @ (es[0, 0] + es[1, 1])) * np.eye(2) + 2 * mu * (es @ w)
    e = ex.strain(x, y, None, t)[:, :, 0]
    elastic = scene.material.lam * np.trace(e) * np.eye(2) + 2 * scene.material.mu * e
    assert np.allclose(ex.stress(x, y, None, t)[:, :, 0], elastic + mem, rtol=1e-7, atol=0)


def test_contact_load_balances_the_contact_law(case):
    """On Γ_C (y = 0, ν = (0, −1), τ = (1, 0)): f_C − σ*ν = p_ν(β*, u*_ν) ν
    + λ* ν [on the wall] + ∇j_τ(β*, u*_τ), each term computed here from the laws."""
    ex, scene = case.exact, case.scene
    x = np.linspace(0.05, 0.95, 13)
    y = np.zeros_like(x)
    t = 0.6
    nu, tau = np.array([0.0, -1.0]), np.array([1.0, 0.0])
    load = ex.contact_load(nu[:, None], tau[None, :, None])(x, y, None, t)
    sig_nu = np.einsum("ijp,j->ip", ex.stress(x, y, None, t), nu)
    u = ex.displacement(x, y, None, t)
    r, xi = nu @ u, tau @ u
    beta = ex.beta(x, y, None, t)
    expected = case.normal_law.value(beta, r)
    if scene.contact.gap is not None and scene.exact.multiplier is not None:
        g = scene.contact.gap(x, y, t=t)
        on = np.isclose(r, g, rtol=0, atol=1e-12)
        assert on.any() and (~on).any()          # the case has both parts
        expected = expected + np.where(on, scene.exact.multiplier(x, y, t=t), 0.0)
    friction = 0.0
    if case.friction is not None:
        friction = case.friction.gradient(beta, xi[:, None])[:, 0]
    assert np.allclose(load - sig_nu, np.outer(nu, expected) + np.outer(tau, friction),
                       rtol=0, atol=1e-12 * max(1.0, np.abs(load).max()))


def test_bonding_source_closes_the_ode(case):
    """s_β = ∂_t β* − F(u*_ν, u*_τ, β*): ∂_t β* by central differences."""
    ex = case.exact
    assert case.bonding is not None   # every committed case evolves β
    x = np.linspace(0.05, 0.95, 9)
    y = np.zeros_like(x)
    t, delta = 0.5, 1e-5
    nu, tau = np.array([0.0, -1.0]), np.array([1.0, 0.0])
    source = ex.beta_source(nu[:, None], tau[None, :, None])(x, y, None, t)
    dbeta = (ex.beta(x, y, None, t + delta) - ex.beta(x, y, None, t - delta)) / (2 * delta)
    u = ex.displacement(x, y, None, t)
    F = case.bonding.rate(nu @ u, (tau @ u)[:, None], ex.beta(x, y, None, t))
    assert np.allclose(source, dbeta - F, rtol=0, atol=1e-8)


# ---------------------------------------------------------------- exactness


EXACT_IN_SPACE_AND_TIME = scene_dict({
    "mesh": {"domain": "rectangle", "size": [1.0, 1.0], "cells": [3, 2], "pattern": "cross"},
    "contact.normal": law("adhesive_compliance", c=10000.0, gamma=5000.0, L=0.02),
    "contact.friction": [law("tresca", mu=1.0), law("adhesive_spring", gamma=500.0, L=0.02)],
    "contact.bonding": law("fremond", gamma_nu=300.0, gamma_tau=100.0, eps_a=0.0, L=0.02),
    # linear in space (P1 reproduces it) and β* constant: without memory the
    # scheme is exact at every t_n, whatever the time dependence
    "exact": {"u": ["0.01*(1 - y)*sin(3*t)", "0.008*(1 - y)*(1 + t*t)"], "beta": "0.7"},
    "time.steps": 5})


def test_a_field_the_scheme_represents_exactly_has_round_off_errors():
    scene = scene_from_dict(EXACT_IN_SPACE_AND_TIME)
    record = run_level(scene, "h", 0)
    # errors against |ε(u*)| ≈ 1e-2 and β* = 0.7: round-off, not discretisation
    assert record["err_u"] < 1e-12 and record["err_beta"] < 1e-12
    # the wall time splits into set-up and time loop, both spent
    assert record["setup_seconds"] > 0 and record["stepping_seconds"] > 0
    assert record["setup_seconds"] + record["stepping_seconds"] == pytest.approx(
        record["seconds"], rel=1e-12)


# ---------------------------------------------------------------- prolongation


@pytest.mark.parametrize("pattern", ["diagonal", "cross"])
def test_prolongation_is_exact_on_nested_meshes(pattern):
    """P carries a coarse P1 field to the fine mesh exactly: at every fine
    vertex it equals the coarse interpolant (checked by skfem's probes), and
    the fine strain integral equals the coarse one."""
    spec = scene_from_dict(scene_dict({"mesh.pattern": pattern}, EXACT_IN_SPACE_AND_TIME)).mesh
    meshes = nested_meshes(spec, 2)
    P = prolongation(meshes)
    coarse, fine = meshes[0], meshes[-1]
    rng = np.random.default_rng(0)
    uc = rng.standard_normal((coarse.p.shape[1], 2))
    probes = Basis(coarse, ElementTriP1()).probes(fine.p)
    assert np.allclose(P @ uc, probes @ uc, rtol=0, atol=1e-13)
    ec = strain_error_fine(coarse, strain_map(stiffness_basis(coarse)), uc.ravel())
    ef = strain_error_fine(fine, strain_map(stiffness_basis(fine)), (P @ uc).ravel())
    assert ef == pytest.approx(ec, rel=1e-12)
    assert cell_volumes(fine).sum() == pytest.approx(1.0, rel=1e-14)


def test_facet_parents_contain_their_children():
    mesh_spec = scene_from_dict(EXACT_IN_SPACE_AND_TIME).mesh
    meshes = nested_meshes(mesh_spec, 2)
    coarse, fine = meshes[0], meshes[-1]
    cf, ff = coarse.boundaries["bottom"], fine.boundaries["bottom"]
    parents = facet_parents(meshes, cf, ff)
    mid = fine.p[0, fine.facets[:, ff]].mean(axis=0)
    lo = coarse.p[0, coarse.facets[:, cf]].min(axis=0)[parents]
    hi = coarse.p[0, coarse.facets[:, cf]].max(axis=0)[parents]
    assert np.all((lo < mid) & (mid < hi))
    assert np.bincount(parents).tolist() == [4] * cf.size   # two refinements: 4 children


# ---------------------------------------------------------------- rates on small levels


def test_manufactured_case_converges_at_first_order_in_h():
    """Case (a) on 3 small levels (4x4 to 16x16 cells, k = 1/64): h-rate ≥ 0.9."""
    scene = scene_of(CASES[0], steps=64)
    records = [run_level(scene, "h", level) for level in range(3)]
    assert rates(records, "h")["E"] >= 0.9


def test_manufactured_case_converges_at_first_order_in_k():
    """Case (d) (β decaying fast) on a 8x8 mesh with 4, 8, 16 steps against a
    reference with 16x the steps on the same mesh (the time error alone): k-rate ≥ 0.9."""
    scene = scene_of(CASES[3], steps=4)
    scene = replace(scene, mesh=replace(scene.mesh, refine=1))
    reference = run_reference(scene, "k", 3)
    records = [run_level(scene, "k", level, reference) for level in range(3)]
    assert rates(records, "k")["E"] >= 0.9
