"""The committed scenes and the README's example run, as scikit-fem runs its
docs/examples in its test suite."""

import re
import tomllib
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from conftest import scene_dict

from adhesive_contact import build_problem, load_scene, parse_scene, solve
from adhesive_contact.resources import estimate
from adhesive_contact.scene import scene_from_dict

ROOT = Path(__file__).resolve().parents[1]
SCENES = sorted((ROOT / "studies").glob("*/*.toml"))
RUN_UP_TO = 2e5


@pytest.mark.parametrize("path", SCENES, ids=lambda p: f"{p.parent.name}/{p.stem}")
def test_every_committed_scene_runs(path):
    """Each scene parses, builds and runs (at most 4 steps on its own mesh);
    a mesh file is found relative to the scene file. A benchmark scene of
    more than RUN_UP_TO dofs (studies/bench/block_3d_1e6.toml: 6 minutes)
    is parsed and estimated only: the benchmark runs it."""
    scene = load_scene(path)
    if estimate(scene).dofs > RUN_UP_TO:
        assert path.parent.name == "bench"
        return
    scene = replace(scene, steps=min(scene.steps, 4), T=scene.T * min(scene.steps, 4) / scene.steps)
    solution = solve(build_problem(scene))
    assert solution.success, solution.message
    assert np.all(solution.residual <= scene.solver.tol)
    assert np.isfinite(solution.u).all()
    if solution.beta.size:
        assert (solution.beta >= 0).all() and (solution.beta <= 1).all()


def test_wall_scene_shows_wall_compliance_and_separation():
    """What studies/README.md says of wall.toml at t = 1: 13 nodes on the wall,
    14 in compliance, 38 separated, and the wall never crossed."""
    solution = solve(build_problem(parse_scene((ROOT / "studies/scenes/wall.toml").read_text())))
    assert solution.success, solution.message
    un = solution.normal_displacement[-1]
    on_wall = solution.on_wall[-1]
    assert (on_wall.sum(), ((un > 0) & ~on_wall).sum(), (un < 0).sum()) == (13, 14, 38)
    assert (solution.normal_displacement - solution.gap).max() <= 1e-12


def test_readme_python_example_runs(monkeypatch):
    text = (ROOT / "README.md").read_text()
    (block,) = [b for b in re.findall(r"```python\n(.*?)```", text, re.S)
                if "solution = solve(" in b]   # the one that solves a scene
    namespace = {}
    monkeypatch.chdir(ROOT)
    exec(compile(block, "README.md", "exec"), namespace)   # our own README, not input
    assert namespace["solution"].u.shape[0] == namespace["scene"].steps + 1


def test_conmech_setup0_scene_is_the_peer_problem():
    """studies/bench/conmech_setup0.toml has conmech's 5233 nodes, and its
    Lamé pair λ = μ = 4 is the pair E = 10, ν = 0.25 of its comment: the
    same displacements to round-off."""
    path = ROOT / "studies/bench/conmech_setup0.toml"
    lame = solve(build_problem(load_scene(path)))
    assert lame.problem.mesh.p.shape[1] == 5233
    data = scene_dict({"material": {"E": 10.0, "nu": 0.25}}, tomllib.loads(path.read_text()))
    young = solve(build_problem(scene_from_dict(data)))
    assert np.abs(young.u - lame.u).max() <= 1e-12 * np.abs(lame.u).max()
    # the body force pushes Γ_C into the layer: every contact node is in
    # compliance, but the clamped one (u = 0)
    free = ~lame.problem.boundary.held.all(axis=1)
    assert free.sum() == free.size - 1
    assert (lame.normal_displacement[-1][free] > 0).all()
