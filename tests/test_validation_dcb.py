"""The double cantilever beam of studies/validation/dcb.py on a small level
(half the facets, an eighth of the steps): the cohesive law's peak force
against LEFM with the root-rotation correction, the glue's energy per unit
new crack area against G_c, and the one-level lag of the damage update
(warned with few steps, first order: less overshoot with more)."""

import importlib.util
import re
from pathlib import Path

import numpy as np
import pytest

STUDY = Path(__file__).resolve().parents[1] / "studies" / "validation" / "dcb.py"
CELLS = (150, 10)


@pytest.fixture(scope="module")
def study():
    spec = importlib.util.spec_from_file_location("dcb_study", STUDY)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def runs(study):
    return {n: study.run(n, CELLS) for n in (400, 800)}


def test_root_rotation_constant_is_williams(study):
    # E'/G = 2(1 + ν)/(1 − ν²) = 2.857 for ν = 0.3: Γ = 3.3714, χ = 0.6857
    _, _, chi = study.constants(study.scene_data())
    assert chi == pytest.approx(0.6857, abs=1e-4)


def test_the_arm_bends_as_beam_theory_before_the_crack_grows(study, runs):
    """The slope P/δ at small δ is 3E'I/(a0 + χh)³ from above, within 8 %:
    a displacement method is stiffer than the exact solution, and P1
    triangles of aspect 2, 10 through the thickness, are stiff in bending
    (7 % here, 2 % on the study's cells of aspect 1)."""
    rec, data = runs[800], study.scene_data()
    EI, _, chi = study.constants(data)
    slope = rec["P"][20] / rec["delta"][20]
    assert 1.0 < slope / (3 * EI / (study.A0 + chi * study.H) ** 3) < 1.08


def test_peak_and_toughness_against_lefm(study, runs):
    """Peak within 10 % of √(2E'IG_c)/(a0 + χh) (the study's level: 5 %), the
    glue's energy per new area within 25 % of G_c, both errors smaller at
    twice the steps (the lag of one level is first order in k)."""
    data = study.scene_data()
    coarse, fine = (study.summary(runs[n], data) for n in (400, 800))
    assert abs(fine["peak_error"]) < 0.10
    assert abs(fine["glue_per_area_over_Gc"] - 1) < 0.25
    assert abs(fine["peak_error"]) < abs(coarse["peak_error"])
    assert abs(fine["glue_per_area_over_Gc"] - 1) < abs(coarse["glue_per_area_over_Gc"] - 1)


def largest_drop(warnings):
    line = next(w for w in warnings if "cohesive damage update lags" in w)
    return float(re.search(r"lost up to ([0-9.e+-]+) of a facet", line).group(1))


def test_the_lag_is_warned_with_few_steps(runs):
    """The largest fall of β in one level exceeds 0.1 at these step counts,
    and falls with k."""
    assert 0.1 < largest_drop(runs[800]["warnings"]) < largest_drop(runs[400]["warnings"])


def test_the_crack_only_grows(runs):
    front = np.array(runs[800]["front"])
    assert front[0] == pytest.approx(10.0, abs=0.2) and front[-1] > 15.0
    assert np.all(np.diff(front) >= -1e-9)
