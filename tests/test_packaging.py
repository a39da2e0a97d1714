"""Every subpackage of the library is installed by ``pip install .`` (the
README's first command is a non-editable install: a subpackage missing
from pyproject.toml's list would import from a checkout and fail there)."""

import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_pyproject_lists_every_subpackage():
    listed = set(tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
                 ["packages"])
    found = {".".join(p.parent.relative_to(ROOT).parts)
             for p in (ROOT / "adhesive_contact").rglob("__init__.py")}
    assert found <= listed, sorted(found - listed)
    assert "adhesive_contact_cli" in listed
