"""Tests for :mod:`adhesive_contact.postprocess` and :mod:`adhesive_contact.storage`:
each quantity against an independent computation (tensors built by hand,
rotations written out, sums of nodal forces). The plane-strain identity
σ_zz = ν (σ_xx + σ_yy) of :func:`stress_3x3` is checked through the ParaView
output in test_cli.py."""

import json
import math
import os
from types import SimpleNamespace

import numpy as np
import pytest
from conftest import law, prony, scene_dict

from adhesive_contact import build_problem, scene_from_dict, solve
from adhesive_contact.postprocess import (
    beta_mean,
    cell_von_mises,
    contact_measure,
    contact_nodal_forces,
    contact_state_counts,
    contact_states,
    contact_traction,
    normal_traction,
    state_masks,
    state_tolerance,
    stress_3x3,
    tangential_traction,
    to_global,
    total_contact_force,
    von_mises,
)
from adhesive_contact.storage import plain, read_json, write_atomic, write_json

# a block hanging from its top, pulled down and sideways onto a compliant
# layer with Tresca friction and a wall: normal and tangential forces
SCENE = scene_dict({
    "title": "block sheared on a compliant layer",
    "mesh": {"domain": "rectangle", "size": [1.0, 0.5], "cells": [8, 4]},
    "memory": prony((200.0, 0.3, 0.5)),
    "loads": {"body": ["200*t", "-800*t"]},
    "contact": {"gap": "0.002 + 0.01*(x - 0.5)**2", "normal": law("compliance", c=3000.0),
                "friction": [law("tresca", mu=0.5)]},
    "time.steps": 4,
})


@pytest.fixture(scope="module")
def solution():
    return solve(build_problem(scene_from_dict(SCENE)))


# ---------------------------------------------------------------- stress


def test_von_mises_of_uniaxial_and_pure_shear_stress():
    sigma, tau = 3.0, 2.0
    uniaxial = np.zeros((3, 3))
    uniaxial[0, 0] = sigma
    shear = np.zeros((3, 3))
    shear[0, 1] = shear[1, 0] = tau
    hydrostatic = 5.0 * np.eye(3)
    values = von_mises(np.stack([uniaxial, -uniaxial, shear, hydrostatic]))
    np.testing.assert_allclose(values, [sigma, sigma, math.sqrt(3) * tau, 0.0],
                               rtol=1e-14, atol=1e-14)
    # adding a pressure changes nothing
    np.testing.assert_allclose(von_mises(shear + 7.0 * np.eye(3)), math.sqrt(3) * tau,
                               rtol=1e-14)


def test_stress_3x3_carries_the_plane_strain_sigma_zz(solution):
    full = stress_3x3(solution)
    assert full.shape == solution.stress.shape[:2] + (3, 3)
    np.testing.assert_array_equal(full[..., :2, :2], solution.stress)
    np.testing.assert_array_equal(full[..., 2, 2], solution.stress_zz)
    np.testing.assert_array_equal(full[..., :2, 2], 0.0)
    np.testing.assert_array_equal(stress_3x3(solution, 2), full[2])
    # σ_vM² = σxx² + σyy² + σzz² − σxxσyy − σyyσzz − σzzσxx + 3σxy²
    sxx, syy, sxy = solution.stress[..., 0, 0], solution.stress[..., 1, 1], \
        solution.stress[..., 0, 1]
    szz = solution.stress_zz
    by_hand = np.sqrt(sxx**2 + syy**2 + szz**2 - sxx * syy - syy * szz - szz * sxx
                      + 3 * sxy**2)
    np.testing.assert_allclose(cell_von_mises(solution), by_hand, rtol=1e-10,
                               atol=1e-12 * by_hand.max())
    np.testing.assert_allclose(cell_von_mises(solution, -1), by_hand[-1], rtol=1e-10,
                               atol=1e-12 * by_hand.max())


# ---------------------------------------------------------------- contact


def test_traction_times_weights_is_the_force(solution):
    w = solution.problem.boundary.node_weights
    assert np.all(w > 0)
    for frame in ("nodal", "global"):
        traction = contact_traction(solution, frame)
        np.testing.assert_allclose(traction * w[:, None],
                                   contact_nodal_forces(solution, frame), rtol=1e-14)
    np.testing.assert_allclose((normal_traction(solution) * w).sum(axis=1),
                               solution.total_normal_force(), rtol=1e-12)
    np.testing.assert_allclose((tangential_traction(solution) * w[:, None]).sum(axis=1),
                               solution.total_tangential_force(), rtol=1e-12)


def test_global_forces_on_a_straight_side_are_the_nodal_ones_rotated(solution):
    """Γ_C is the bottom side: ν = (0, −1) and τ = (1, 0) at every node, so
    F_global = (F_τ, −F_ν), and their sum is the total force rotated."""
    nodal = solution.contact_force
    assert np.abs(nodal[-1, :, 0]).max() > 0 and np.abs(nodal[-1, :, 1]).max() > 0
    glob = contact_nodal_forces(solution)
    np.testing.assert_allclose(glob[..., 0], nodal[..., 1], rtol=1e-14, atol=0)
    np.testing.assert_allclose(glob[..., 1], -nodal[..., 0], rtol=1e-14, atol=0)
    total = total_contact_force(solution)
    np.testing.assert_allclose(total[:, 1], solution.total_normal_force(), rtol=1e-12)
    np.testing.assert_allclose(total[:, 0], solution.total_tangential_force()[:, 0],
                               rtol=1e-12)
    # the body is pressed down and pushed to +x: Γ_C pushes up and holds back
    assert total[-1, 1] > 0 and total[-1, 0] < 0
    with pytest.raises(ValueError, match="frame"):
        contact_nodal_forces(solution, "cartesian")


@pytest.mark.parametrize("d", [2, 3])
def test_to_global_rotates_by_each_nodal_frame(d):
    """Random frames per node: R_a F_a = Σ_c F_{a,c} (column c of R_a), and
    the length of each vector is kept."""
    rng = np.random.default_rng(d)
    nc = 7
    frames = np.linalg.qr(rng.standard_normal((nc, d, d)))[0]
    problem = SimpleNamespace(boundary=SimpleNamespace(frame=frames))
    nodal = rng.standard_normal((3, nc, d))
    glob = to_global(problem, nodal)
    by_hand = np.zeros_like(nodal)
    for a in range(nc):
        for c in range(d):
            by_hand[:, a, :] += nodal[:, a, c, None] * frames[a, :, c]
    np.testing.assert_allclose(glob, by_hand, rtol=1e-13, atol=1e-15)
    np.testing.assert_allclose(np.linalg.norm(glob, axis=2), np.linalg.norm(nodal, axis=2),
                               rtol=1e-13)


def test_beta_mean_is_weighted_by_the_facet_lengths():
    boundary = SimpleNamespace(facets=np.arange(3), measure=np.array([1.0, 2.0, 1.0]))
    fake = SimpleNamespace(problem=SimpleNamespace(boundary=boundary),
                           beta=np.array([[1.0, 1.0, 1.0], [0.0, 1.0, 0.5]]))
    np.testing.assert_allclose(beta_mean(fake), [1.0, (0 + 2 + 0.5) / 4], rtol=1e-15)
    fake.problem.boundary = None
    assert beta_mean(fake) is None


def test_contact_states_partition_the_nodes(solution):
    states = contact_states(solution)
    nc = solution.problem.boundary.nodes.size
    for key in ("separated", "on_wall", "compliance", "stick", "slip"):
        assert states[key].shape == (solution.t.size, nc) and states[key].dtype == bool
    # every node is separated, on the wall or in the compliant layer, once
    total = (states["separated"].astype(int) + states["on_wall"] + states["compliance"])
    np.testing.assert_array_equal(total, 1)
    assert not (states["stick"] & states["slip"]).any()
    assert not ((states["stick"] | states["slip"]) & states["separated"]).any()
    counts = contact_state_counts(solution)
    for key, value in counts.items():
        np.testing.assert_array_equal(states[key].sum(axis=1), value)
    assert states["compliance"][-1].any() or states["on_wall"][-1].any()


def test_states_use_a_tolerance_of_the_body_size(solution):
    """u_ν = −1e-10 on a body of size 1.1 is touching; −1e-6 is separated;
    a slip of 1e-10 is no slip. The tolerance is 1e-8 of the bounding
    box's diagonal, √(1 + 0.25)."""
    problem = solution.problem
    nc = problem.boundary.nodes.size
    assert state_tolerance(problem) == pytest.approx(1e-8 * math.sqrt(1.25), rel=1e-14)
    z = np.zeros((nc, 2))
    z[0] = [-1e-10, 1e-10]
    z[1] = [-1e-6, 0.0]
    z[2] = [0.0, 1e-6]
    none = np.zeros(nc, dtype=bool)
    masks = state_masks(problem, z, none, none)
    assert not masks["separated"][0] and masks["compliance"][0] and not masks["slip"][0]
    assert masks["separated"][1] and masks["slip"][2]


def test_without_a_compliant_layer_touching_is_the_wall():
    """law none with a wall: a node short of the wall (0 < u_ν < g) is
    separated, whatever the sign of u_ν; one at u_ν = g (or in the wall
    set) touches; no node is in compliance. The measure in contact is the
    nodal weights of the touching nodes."""
    problem = build_problem(scene_from_dict(scene_dict({
        **{k: SCENE[k] for k in ("mesh", "time")}, "boundary.dirichlet": ["top"],
        "contact": {"gap": "0.002", "normal": law("none")}})))
    nc = problem.boundary.nodes.size
    gap = problem.gap.at(0.0)
    z = np.zeros((nc, 2))
    z[:, 0] = 0.5 * gap                      # short of the wall
    z[3, 0] = gap[3] - 1e-12                 # at the wall, not in the set
    wall = np.zeros(nc, dtype=bool)
    wall[4] = True                           # in the step method's set
    z[4, 0] = gap[4]
    masks = state_masks(problem, z, wall, wall, gap)
    touching = np.zeros(nc, dtype=bool)
    touching[[3, 4]] = True
    np.testing.assert_array_equal(masks["separated"], ~touching)
    assert not masks["compliance"].any()
    # the same from a solution: the measure in contact
    fake = SimpleNamespace(problem=problem, t=np.zeros(1), frame_displacement=z[None],
                           on_wall=wall[None], stuck=wall[None], gap=gap[None])
    assert contact_measure(fake)[0] == pytest.approx(problem.boundary.node_weights[[3, 4]].sum())


# ---------------------------------------------------------------- storage


def test_plain_and_write_json_are_strict(tmp_path):
    doc = {"a": np.float64("nan"), "b": [np.inf, -np.inf, np.float32(1.5)], 3: np.int64(4),
           "c": np.bool_(True), "d": np.array([[1.0, np.nan]]), "e": -0.0}
    assert plain(doc) == {"a": None, "b": [None, None, 1.5], "3": 4, "c": True,
                          "d": [[1.0, None]], "e": 0.0}
    path = tmp_path / "doc.json"
    write_json(path, doc)

    def refuse(name):
        raise ValueError(name)
    assert json.loads(path.read_text(), parse_constant=refuse) == plain(doc)
    assert read_json(path) == plain(doc)
    assert read_json(tmp_path / "missing.json") is None
    (tmp_path / "bad.json").write_text("{")
    assert read_json(tmp_path / "bad.json") is None


def test_write_atomic_keeps_the_old_file_when_writing_fails(tmp_path):
    path = tmp_path / "file.txt"
    write_atomic(path, lambda f: f.write("old"))
    assert oct(os.stat(path).st_mode & 0o777) == oct(0o644)

    def fail(f):
        f.write("half")
        raise RuntimeError("disk full")
    with pytest.raises(RuntimeError, match="disk full"):
        write_atomic(path, fail)
    assert path.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["file.txt"]   # no temporary left
    write_atomic(path, lambda f: f.write(b"\x00new"), binary=True)
    assert path.read_bytes() == b"\x00new"
