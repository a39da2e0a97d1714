"""The layout of docs/architecture.md holds: each package imports only what
its row of "What may import what" allows, the library never imports the
command line, the command line draws nothing itself, and no module grows
past 700 lines."""

import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "adhesive_contact"
CLI = ROOT / "cli"

BASE = {"expressions", "storage", "threads", "laws", "step_methods", "linear_solvers"}
#: package -> what it may import (docs/architecture.md); a dotted entry
#: allows one module of a package
ALLOWED = {
    "expressions": set(), "storage": set(), "threads": set(), "laws": set(),
    "step_methods": set(),
    "linear_solvers": set(), "folders": {"storage"},
    "scene": {"expressions", "laws", "step_methods", "linear_solvers", "scheme.bonding",
              "verification.manufactured", "fem.meshes.builtin"},
    "fem": {"expressions", "scene"},
    "problem": {"expressions", "scene", "laws", "fem", "verification.manufactured",
                "verification.admissibility", "scheme.options"},
    "scheme": {"expressions", "threads", "scene", "laws", "step_methods", "linear_solvers"},
    "verification": BASE | {"scene", "fem", "problem", "scheme"},
    "postprocess": {"expressions", "threads", "fem"},
    "visuals": {"postprocess", "storage"},
    "io": {"scene", "problem", "scheme", "postprocess", "visuals", "resources", "folders",
           "storage", "threads"},
    "resources": {"scene", "fem", "linear_solvers", "scheme"},
    "studies": BASE | {"scene", "fem", "problem", "scheme", "verification", "postprocess",
                       "io", "resources", "folders", ""},
    "": None,   # adhesive_contact/__init__.py: the public names, from anywhere
}


def _modules():
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = path.relative_to(ROOT).with_suffix("").parts
        is_package = parts[-1] == "__init__"
        yield path, ".".join(parts[:-1] if is_package else parts), is_package


def _imports(path, module, is_package):
    """The adhesive_contact modules and names ``path`` imports (absolute)."""
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = module.split(".") if is_package else module.split(".")[:-1]
                base = base[:len(base) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if target == "adhesive_contact":
                yield from (f"{target}.{alias.name}" for alias in node.names)
            else:
                yield target
        elif isinstance(node, ast.Import):
            yield from (alias.name for alias in node.names)


def _package_of(module):
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else ""


def _allowed(importer, target):
    rules = ALLOWED[importer]
    if rules is None or _package_of(target) == importer:
        return True
    parts = target.split(".")[1:]
    return any(".".join(parts[:i]) in rules for i in range(1, len(parts) + 1)) or (
        "" in rules and len(parts) == 1 and parts[0] not in ALLOWED)


def test_every_package_has_a_row():
    packages = {_package_of(module) for _, module, _ in _modules()}
    assert packages == set(ALLOWED)


@pytest.mark.parametrize("path,module,is_package", list(_modules()),
                         ids=lambda v: v if isinstance(v, str) else None)
def test_imports_follow_the_layers(path, module, is_package):
    importer = _package_of(module)
    for target in _imports(path, module, is_package):
        assert not target.startswith("adhesive_contact_cli"), f"{module} imports the CLI"
        if target.startswith("adhesive_contact.") or target == "adhesive_contact":
            assert _allowed(importer, target), f"{module} imports {target}"


def test_the_library_never_chooses_a_backend():
    for path, module, _ in _modules():
        assert "matplotlib.use(" not in path.read_text(), module


def test_the_command_line_draws_nothing_and_stays_small():
    cli_lines = 0
    for path in CLI.glob("*.py"):
        text = path.read_text()
        cli_lines += len(text.splitlines())
        imported = {name.split(".")[0] for name in
                    _imports(path, f"adhesive_contact_cli.{path.stem}", False)}
        assert "matplotlib" not in imported, f"cli/{path.name} imports matplotlib"
    library_lines = sum(len(p.read_text().splitlines()) for p in PACKAGE.rglob("*.py"))
    assert cli_lines <= 0.15 * (cli_lines + library_lines)


def test_no_module_over_700_lines():
    for path in list(PACKAGE.rglob("*.py")) + list(CLI.glob("*.py")):
        assert len(path.read_text().splitlines()) <= 700, path.relative_to(ROOT)


def test_every_test_file_is_in_the_verification_map():
    table = (ROOT / "docs" / "verification.md").read_text()
    listed = set(re.findall(r"^\| `(test_\w+\.py)` \|", table, re.M))
    present = {path.name for path in (ROOT / "tests").glob("test_*.py")}
    assert listed == present


def test_no_function_over_80_lines_in_the_scheme_core():
    """The time scheme's core stays readable (issue: "no function over 80
    lines in scheme/ and step_methods/")."""
    long = []
    for folder in ("scheme", "step_methods"):
        for path in sorted((PACKAGE / folder).rglob("*.py")):
            for node in ast.walk(ast.parse(path.read_text())):
                if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                    lines = node.end_lineno - node.lineno + 1
                    if lines > 80:
                        long.append(f"{path.relative_to(ROOT)}:{node.lineno} {node.name} "
                                    f"({lines} lines)")
    assert not long, long
