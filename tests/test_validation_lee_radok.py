"""Lee & Radok on a small level (studies/validation/lee_radok.py, on the
coarse graded mesh block_L1 and few steps): a viscoelastic block on a
rigid cylinder, against the correspondence principle (a closed form no one
here wrote) and the scheme's own closed form under a held strain."""

import importlib.util
import math
from pathlib import Path

import numpy as np
import pytest

STUDY = Path(__file__).resolve().parents[1] / "studies" / "validation" / "lee_radok.py"


@pytest.fixture(scope="module")
def study():
    spec = importlib.util.spec_from_file_location("lee_radok_study", STUDY)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_relaxation_under_a_held_approach_is_the_rectangle_rule_of_E(study):
    """P_n/P_0 = E_n/E_0, E_n = E_0 − E_1 (k/τ) Σ_{m<n} e^{−mk/τ} (the
    right rectangle rule of σ = ∫ E(t − s) dε under ε held from t = 0,
    summed by hand), with the same u at every level; against E(t)/E_0 the
    error is first order in k (−27 % at t = 6 for k/τ = 0.5)."""
    errors = []
    for steps in (12, 24):
        record = study.run_relaxation(steps, mesh=None)
        k = record["k"]
        force = np.array(record["force"])
        n = np.arange(force.size)
        by_hand = np.array([1000.0 - 500.0 * (k / 1.0) * sum(math.exp(-m * k) for m in range(i))
                            for i in n]) / 1000.0
        np.testing.assert_allclose(force / force[0], by_hand, rtol=1e-9)
        assert record["drift"] <= 1e-12
        exact = (500.0 + 500.0 * np.exp(-np.array(record["t"]))) / 1000.0
        errors.append(force[-1] / force[0] / exact[-1] - 1.0)
    assert errors[0] == pytest.approx(-0.269, abs=0.002)
    assert 1.8 < errors[0] / errors[1] < 2.2


def test_creep_under_a_constant_load_tends_to_lee_and_radok_at_first_order(study):
    """a(t)² = 4R(1 − ν²)P_0 J(t)/π: within 1 % at t = 0 (Hertz), and the
    error at t = 6 falls by about 2 per halving of k."""
    errors = []
    for steps in (24, 48):
        rows = study.creep_rows([study.run_creep(steps, mesh=None)])
        assert abs(rows[0]["error_a2"]) < 0.01
        errors.append(rows[-1]["error_a2"])
    # 16.1 % and 8.0 % at k/τ = 1/4 and 1/8 (14.0 % and 6.5 % with the
    # cylinder's gap measured along the block's own normal, before the
    # foundation's normal at the closest point: docs/conventions.md)
    assert errors[1] < 0.09
    assert 1.7 < errors[0] / errors[1] < 3.0
