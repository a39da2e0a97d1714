"""The committed scenes and the README's example run, as scikit-fem runs its
docs/examples in its test suite."""

import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from adhesive_contact import build_problem, load_scene, parse_scene, solve

ROOT = Path(__file__).resolve().parents[1]
SCENES = sorted((ROOT / "studies").glob("*/*.toml"))


@pytest.mark.parametrize("path", SCENES, ids=lambda p: f"{p.parent.name}/{p.stem}")
def test_every_committed_scene_runs(path):
    """Each scene parses, builds and runs (at most 4 steps on its own mesh);
    a mesh file is found relative to the scene file."""
    scene = load_scene(path)
    scene = replace(scene, steps=min(scene.steps, 4), T=scene.T * min(scene.steps, 4) / scene.steps)
    solution = solve(build_problem(scene))
    assert np.isfinite(solution.u).all()
    if solution.beta.size:
        assert (solution.beta >= 0).all() and (solution.beta <= 1).all()


def test_wall_scene_shows_wall_compliance_and_separation():
    """What studies/README.md says of wall.toml at t = 1: 13 nodes on the wall,
    14 in compliance, 38 separated, and the wall never crossed."""
    solution = solve(build_problem(parse_scene((ROOT / "studies/scenes/wall.toml").read_text())))
    un = solution.normal_displacement[-1]
    on_wall = solution.on_wall[-1]
    assert (on_wall.sum(), ((un > 0) & ~on_wall).sum(), (un < 0).sum()) == (13, 14, 38)
    assert (solution.normal_displacement - solution.problem.gap).max() <= 1e-12


def test_readme_python_example_runs(monkeypatch):
    text = (ROOT / "README.md").read_text()
    block = re.search(r"```python\n(.*?)```", text, re.S).group(1)
    namespace = {}
    monkeypatch.chdir(ROOT)
    exec(compile(block, "README.md", "exec"), namespace)   # our own README, not input
    assert namespace["solution"].u.shape[0] == namespace["scene"].steps + 1
