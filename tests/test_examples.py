"""Every script of examples/ runs, prints what it promises and writes
nothing into the repository (each in a subprocess, from a temporary
working directory, as a user would run it)."""

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = sorted((ROOT / "examples").glob("*.py"))
#: a line each script must print: what it is for
EXPECTED = {
    "run_scene.py": " 1.00 ",
    "scene_in_code.py": "refused: time.steps: must be an integer in 1..1e+08, got 0",
    "parameter_study.py": "files: runs.csv in ",
    "plot_outputs.py": "beta_and_force.png: 21 levels",
}


def _tree():
    """Paths and modification times of the repository's files (outside
    .git, .venv and caches)."""
    skip = {".git", ".venv", "__pycache__", ".pytest_cache"}
    return {p: p.stat().st_mtime_ns for p in ROOT.rglob("*")
            if p.is_file() and not skip & set(p.relative_to(ROOT).parts)}


def test_every_example_is_checked():
    assert sorted(p.name for p in EXAMPLES) == sorted(EXPECTED)


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.name)
def test_example_runs_and_writes_nothing_in_the_repository(path, tmp_path):
    before = _tree()
    done = subprocess.run([sys.executable, str(path)], cwd=tmp_path, capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert EXPECTED[path.name] in done.stdout
    assert _tree() == before
    assert list(tmp_path.iterdir()) == []
