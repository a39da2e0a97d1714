"""Manufactured solutions are checked for admissibility before a run
(adhesive_contact.verification.admissibility): u* = 0 on the clamped sides, u*_ν ≤ g,
λ* ≥ 0 where u*_ν = g (found with a tolerance), 0 ≤ β* ≤ 1, and no
stick/slip ambiguity of friction with a kink. A violation is a SceneError
naming the condition and the point (exit 2 on the command line)."""

import numpy as np
import pytest
from conftest import law, scene_dict, to_toml
from test_cli import assert_one_line_error
from test_cli import run as run_cli

from adhesive_contact import SceneError, build_problem, scene_from_dict
from adhesive_contact.verification.admissibility import on_wall

#: the wall case (b) of studies/convergence, small: u*_ν = g for x ≤ 0.5
BASE = {
    "mesh": {"domain": "rectangle", "size": [1.0, 1.0], "cells": [4, 4]},
    "contact.gap": "0.004 + 0.1*maximum(x - 0.5, 0)**2",
    "contact.normal": law("compliance", c=50.0),
    "contact.friction": [law("tresca", mu=1.0)],
    "contact.bonding": law("fremond", gamma_nu=200.0, gamma_tau=100.0, eps_a=0.0, L=0.02),
    "exact": {"u": ["0.01*(1 - y)*(1 + x)*(0.5 + t)", "-0.004*(1 - y)"],
              "beta": "1 - 0.3*t", "multiplier": "50*(1 + x)"},
    "time.steps": 4}


def build(**changes):
    return build_problem(scene_from_dict(scene_dict({**BASE, **changes})))


def test_the_admissible_case_builds():
    problem = build()
    assert problem.exact is not None


@pytest.mark.parametrize("changes, key, needle", [
    ({"exact.u": ["0.01*(1 - y)*(1 + x)*(0.5 + t) + 0.001*t", "-0.004*(1 - y)"]},
     "exact.u", "must vanish on the clamped sides (top); u* = (0.00025, 0) at (0, 1), t = 0.25"),
    ({"exact.u": ["0.01*(1 - y)*(1 + x)*(0.5 + t)", "-0.005*(1 - y)"]},
     "exact.u", "must satisfy u*_nu <= g on Γ_C; u*_nu - g = 0.001 at (0, 0), t = 0"),
    ({"exact.multiplier": "50*(x - 0.25)"},
     "exact.multiplier", "must be >= 0 where u*_nu = g; lambda* = -12.5 at (0, 0), t = 0"),
    ({"exact.beta": "1.2 - t"},
     "exact.beta", "must lie in [0, 1] on Γ_C; β* = 1.2 at (0, 0), t = 0"),
    ({"exact.u": ["0.01*(1 - y)*((0.1 + 0.2) - 0.3)", "-0.004*(1 - y)"]},
     "exact.u", "stick/slip is ambiguous on Γ_C: |u*_tau| = 5.55e-19"),
])
def test_each_violation_is_named_with_its_point(changes, key, needle):
    with pytest.raises(SceneError) as info:
        build(**changes)
    assert info.value.key == key and needle in str(info.value), str(info.value)


def test_the_contact_set_is_found_with_a_tolerance():
    """u*_ν = (0.1 + 0.2)·0.01 is g = 0.003 up to round-off (not ==): the
    wall condition passes, and λ* is applied there, so its sign is checked."""
    r = (0.1 + 0.2) * 0.01
    assert r != 0.003 and on_wall(np.array([r]), np.array([0.003]))[0]
    u = ["0.01*(1 - y)*(1 + x)*(0.5 + t)", "-(0.1 + 0.2)*0.01*(1 - y)"]
    assert build(**{"contact.gap": "0.003", "exact.u": u}).exact is not None
    with pytest.raises(SceneError, match=r"^exact\.multiplier: must be >= 0 where u\*_nu = g"):
        build(**{"contact.gap": "0.003", "exact.u": u, "exact.multiplier": "-1"})


def test_smooth_friction_takes_round_off_slip_as_it_comes():
    """Without a kink a round-off u*_τ gives a round-off force: no ambiguity."""
    u = ["0.01*(1 - y)*((0.1 + 0.2) - 0.3)", "-0.004*(1 - y)"]
    friction = [law("adhesive_spring", gamma=500.0, L=0.02)]
    assert build(**{"exact.u": u, "contact.friction": friction}).exact is not None


def test_a_violation_exits_2_on_the_command_line(tmp_path):
    path = tmp_path / "scene.toml"
    path.write_text(to_toml(scene_dict({**BASE, "exact.beta": "1.2 - t"})))
    result = run_cli("solve", path, "--out", tmp_path / "out")
    assert_one_line_error(result, 2, "exact.beta: must lie in [0, 1]")
    assert not (tmp_path / "out").exists()
