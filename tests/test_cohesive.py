"""The cohesive law (adhesive_contact.laws.cohesive) against closed forms:
the bilinear triangle and the Xu–Needleman exponential curve under a
monotone opening; the work of separation equal to G_c by quadrature in
pure modes and at a mixed mode, against the Benzeggagh–Kenane formula
written out here; unloading and reloading on the damaged secant; the
damage update of the scheme (β nonincreasing, in [0, 1] for any step);
a block whose glue opens uniformly in mode I, mode II and at 45° through
the whole scheme, its dissipated energy per area against G_Ic, G_IIc and
BK (first order in k);
and the scene keys (one-line errors naming the key)."""

import numpy as np
import pytest
from conftest import law, scene_dict

from adhesive_contact import build_problem, scene_from_dict
from adhesive_contact.laws import CohesiveDamage, CohesiveNormal
from adhesive_contact.scene import SceneError
from adhesive_contact.bonding import damage

SIGMA, G1, G2, K, ETA = 2.0, 0.05, 0.15, 1.0e4, 1.7


def bilinear(**kw):
    return CohesiveNormal("bilinear", SIGMA, G1, stiffness=K, **kw)


def exponential(**kw):
    return CohesiveNormal("exponential", SIGMA, G1, **kw)


def monotone_traction(normal, openings, shear=None):
    """t_n along a monotone path, β taken as the history's β* (exact
    irreversible update: the path only opens)."""
    beta = normal.intact(openings, shear)
    return -normal.value(beta, -openings), beta


def test_bilinear_traction_is_the_triangle():
    d0, df = SIGMA / K, 2 * G1 / SIGMA
    d = np.linspace(0, 1.5 * df, 3001)
    t, _ = monotone_traction(bilinear(), d)
    exact = np.where(d < d0, K * d, np.maximum(SIGMA * (df - d) / (df - d0), 0.0))
    np.testing.assert_allclose(t, exact, atol=1e-12 * SIGMA)
    assert t.max() == pytest.approx(SIGMA, rel=1e-3)


def test_exponential_traction_is_xu_needleman():
    dc = G1 / (np.e * SIGMA)
    d = np.linspace(0, 15 * dc, 3001)
    t, _ = monotone_traction(exponential(), d)
    exact = SIGMA * (d / dc) * np.exp(1 - d / dc)
    np.testing.assert_allclose(t, exact, rtol=1e-12, atol=1e-14)
    assert t.max() == pytest.approx(SIGMA, rel=1e-6)
    assert exponential().K == pytest.approx(np.e * SIGMA / dc)


def work_of_separation(normal, angle, dmax, n=400001):
    """∫ t · dδ along the proportional path δ = s (cos θ, sin θ), trapezoid."""
    s = np.linspace(0, dmax, n)
    dn, dt = s * np.cos(angle), s * np.sin(angle)
    beta = normal.intact(dn, dt)
    tn = -normal.value(beta, -dn)
    tt = beta * normal.K * np.minimum(dt, normal.L)
    power = tn * np.cos(angle) + tt * np.sin(angle)
    return np.sum(0.5 * (power[1:] + power[:-1]) * np.diff(s))


def bk(mix):
    """Benzeggagh–Kenane, G_c = G_Ic + (G_IIc − G_Ic) B^η."""
    return G1 + (G2 - G1) * mix ** ETA


@pytest.mark.parametrize("shape", ["bilinear", "exponential"])
@pytest.mark.parametrize("angle", [0.0, np.pi / 2, np.pi / 5])
def test_work_of_separation_is_the_toughness(shape, angle):
    normal = bilinear(toughness_shear=G2, mixity=ETA) if shape == "bilinear" else \
        exponential(toughness_shear=G2, mixity=ETA)
    mix = np.sin(angle) ** 2          # G_II/(G_I + G_II) with one stiffness
    expected = bk(mix)
    dmax = normal.L if shape == "bilinear" else normal.L * 0.999
    # the exponential tail beyond the cutoff, (1 + x) e^{-x} G_c, is < 1e-7 G_c
    assert work_of_separation(normal, angle, dmax) == pytest.approx(expected, rel=2e-5)


def test_mode_one_law_ignores_shear_and_has_no_shear_traction():
    normal = bilinear()
    assert not normal.mixed
    assert normal.intact(np.array([0.0]), np.array([1.0]))[0] == 1.0


def test_glue_dissipation_sums_to_the_toughness():
    """Σ (β_{j−1} − β_j) K δ_{j−1}²/2 of the scheme's debonding energy
    (postprocess/energy.py), along a monotone opening by small steps."""
    normal = bilinear()
    d = np.linspace(0, normal.L, 20001)
    beta = np.minimum.accumulate(np.concatenate([[1.0], normal.intact(d[:-1])]))
    psi = 0.5 * d[:-1] ** 2
    dissipated = np.sum((beta[:-1] - beta[1:]) * K * psi)
    assert dissipated == pytest.approx(G1, rel=1e-3)


def test_unload_reload_follows_the_damaged_secant():
    normal = bilinear()
    law = CohesiveDamage(normal)
    identity = lambda f: f                            # one point per facet
    path = np.concatenate([np.linspace(0, 0.6 * normal.L, 50),          # load
                           np.linspace(0.6 * normal.L, 0.1 * normal.L, 50),  # unload
                           np.linspace(0.1 * normal.L, 0.6 * normal.L, 50)])  # reload
    beta = np.ones(1)
    betas, tractions = [], []
    for d in path:
        beta = damage.advance(law, np.array([-d]), None, identity, beta)
        betas.append(beta[0])
        tractions.append(-normal.value(beta, np.array([-d]))[0])
    betas = np.array(betas)
    assert np.all(np.diff(betas) <= 0)                 # irreversible
    held = betas[49]
    np.testing.assert_array_equal(betas[50:], held)   # no damage below the maximum
    secant = held * K * path[50:]
    np.testing.assert_allclose(tractions[50:], secant, rtol=1e-12)
    # the damaged secant passes through the envelope at the maximum opening
    d0, df = SIGMA / K, 2 * G1 / SIGMA
    assert held * K * path[49] == pytest.approx(SIGMA * (df - path[49]) / (df - d0), rel=1e-9)


def test_damage_update_stays_in_the_unit_interval_for_any_step():
    law = CohesiveDamage(exponential())
    rng = np.random.default_rng(3)
    beta = np.ones(200)
    for _ in range(20):
        beta_new = damage.advance(law, rng.normal(0, 0.1, 200), None, lambda f: f, beta)
        assert np.all(beta_new <= beta) and np.all(beta_new >= 0)
        beta = beta_new
    assert law.stable_step() == np.inf


def test_lipschitz_constant_bounds_difference_quotients():
    normal = bilinear(toughness_shear=G2, mixity=ETA)
    rng = np.random.default_rng(0)
    b1, b2 = rng.uniform(0, 1, (2, 10000))
    r1, r2 = rng.uniform(-2 * normal.L, normal.L, (2, 10000))
    quotient = np.abs(normal.value(b1, r1) - normal.value(b2, r2)) / (np.abs(b1 - b2) + np.abs(r1 - r2))
    assert quotient.max() <= normal.lipschitz * (1 + 1e-12)


COHESIVE = {"law": "cohesive", "shape": "bilinear", "strength": SIGMA, "toughness": G1,
            "stiffness": K}


def scene(normal, bonding=None):
    return scene_from_dict(scene_dict({"contact.normal": normal,
                                       "contact.bonding": bonding or {"law": "cohesive"}}))


def test_scene_builds_the_laws():
    problem = build_problem(scene(dict(COHESIVE, toughness_shear=G2, mixity=ETA)))
    assert isinstance(problem.normal_law, CohesiveNormal)
    assert isinstance(problem.bonding, CohesiveDamage)
    assert problem.friction is not None and problem.friction.laws[0].K == K


@pytest.mark.parametrize("change, key, words", [
    ({"shape": "trilinear"}, "contact.normal.shape", "'bilinear', 'exponential'"),
    ({"stiffness": None}, "contact.normal.stiffness", "required for shape = 'bilinear'"),
    ({"shape": "exponential"}, "contact.normal.stiffness", "bilinear' only"),
    ({"mixity": 2.0}, "contact.normal.toughness_shear", "required with mixity"),
    ({"toughness": 1e-5}, "contact.normal.toughness", "delta_f > delta_0"),
    ({"strength": -1.0}, "contact.normal.strength", "must be > 0"),
])
def test_bad_cohesive_keys(change, key, words):
    normal = {k: v for k, v in dict(COHESIVE, **change).items() if v is not None}
    with pytest.raises(SceneError) as err:
        scene(normal)
    assert err.value.key == key and words in str(err.value)


def test_cohesive_needs_both_tables_and_the_explicit_update():
    with pytest.raises(SceneError) as err:
        scene(COHESIVE, {"law": "none"})
    assert err.value.key == "contact.bonding.law"
    with pytest.raises(SceneError) as err:
        scene(law("compliance", c=1.0))
    assert err.value.key == "contact.normal.law"
    with pytest.raises(SceneError) as err:
        scene(COHESIVE, {"law": "cohesive", "integrator": "implicit"})
    assert err.value.key == "contact.bonding.integrator"


def test_a_facet_with_unequal_openings_dissipates_the_toughness():
    """Two points of one facet open at different rates (δ₂ = 3 δ₁ + δ_0, up to the cap L = δ_f):
    the scheme's debonding energy Σ (β_{n−1} − β_n) K P_B δ²_{n−1}/2
    (postprocess/energy.py below the cap) sums to G_c, because the update
    is driven by the facet's r.m.s. opening."""
    normal = bilinear()
    law = CohesiveDamage(normal)
    mean = lambda f: f.reshape(-1, 2).mean(axis=1)
    d0 = SIGMA / K
    beta, dissipated = np.ones(1), 0.0
    for s in np.linspace(0, normal.L, 40001):
        opening = np.array([s, min(3 * s + d0, normal.L)])
        new = damage.advance(law, -opening, None, mean, beta)
        dissipated += (beta - new)[0] * K * np.mean(opening ** 2) / 2
        beta = new
    assert beta[0] == 0.0
    assert dissipated == pytest.approx(G1, rel=1e-3)


# ------------------------------------------------------------ through the scheme

def uniform_separation(top, steps):
    """A 2 × 0.5 block whose top is moved by ``top`` (u_x, u_y expressions)
    over a mixed-mode cohesive bottom (G_Ic = 0.02, G_IIc = 0.05, η = 2): Γ_C
    opens uniformly; the glue's dissipated energy per unit area at the end,
    when every facet is broken (β = 0)."""
    from adhesive_contact import solve
    from adhesive_contact.postprocess import energies

    data = scene_dict({
        "boundary": {"dirichlet": [], "contact": ["bottom"], "displacement": {"top": top}},
        "contact.normal": {"law": "cohesive", "shape": "bilinear", "strength": 1.0,
                           "toughness": 0.02, "stiffness": 1e3, "toughness_shear": 0.05,
                           "mixity": 2.0},
        "contact.bonding": {"law": "cohesive"}, "time": {"T": 1.0, "steps": steps}})
    solution = solve(build_problem(scene_from_dict(data)))
    assert solution.success and solution.beta[-1].max() == 0.0
    return energies(solution).dissipated["debonding"][-1] / 2.0


@pytest.mark.parametrize("top, toughness", [
    (["0", "0.15*t"], 0.02),                   # mode I
    (["0.15*t", "0"], 0.05),                   # mode II: the shear traction of the law
])
def test_a_uniform_separation_dissipates_the_toughness_to_first_order(top, toughness):
    """The debonding energy per area tends to G_c with k, first order (the
    one-level lag: an upper Riemann sum of ∫ K δ²/2 dD): within 2 % at 800
    steps, its error halved from 400."""
    coarse, fine = (uniform_separation(top, n) / toughness - 1.0 for n in (400, 800))
    assert 0.0 < fine < 0.02
    assert fine == pytest.approx(coarse / 2.0, rel=0.15)


def test_a_uniform_mixed_separation_dissipates_the_bk_toughness():
    """Top moved at 45°: B = ½ at the interface up to the block's own
    deformation, G_c(½) = 0.02 + 0.03 · ½² = 0.0275 (BK, η = 2); within 2 %."""
    assert uniform_separation(["0.1*t", "0.1*t"], 800) == pytest.approx(0.0275, rel=0.02)


def test_the_second_order_scheme_refuses_the_cohesive_law():
    """Its damage update follows the previous level (first order): the
    second-order scheme would not be second order with it."""
    from adhesive_contact import SceneError, scene_from_dict

    data = {"dim": 2, "mesh": {"domain": "rectangle", "size": [2.0, 0.5], "cells": [8, 2]},
            "boundary": {"dirichlet": ["left"], "contact": ["bottom"]},
            "material": {"E": 1000.0, "nu": 0.3},
            "contact": {"normal": {"law": "cohesive", "shape": "bilinear", "strength": 1.0,
                                   "toughness": 0.01, "stiffness": 1000.0},
                        "bonding": {"law": "cohesive"}},
            "time": {"T": 1.0, "steps": 4, "scheme": "second-order"}}
    with pytest.raises(SceneError, match=r"^time\.scheme: \"second-order\" has no "
                                         r"second-order update for the cohesive law"):
        scene_from_dict(data)
    data["time"]["scheme"] = "paper"
    assert scene_from_dict(data).contact.bonding.law == "cohesive"
