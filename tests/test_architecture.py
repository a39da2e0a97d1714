"""The layout of docs/architecture.md holds: the package is a stack of
floors and each module imports only its own package and the floors below
it, the library never imports the command line, the command line draws
nothing itself, and no module grows past 700 lines."""

import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "adhesive_contact"
CLI = ROOT / "cli"

#: the floors of the package, from the ground up (docs/architecture.md, "The
#: layers"): a module imports its own package and the packages of lower
#: floors, never one of its own floor or above; "" is the package's face
#: (adhesive_contact/__init__.py: the public names)
LAYERS = (
    ("expressions", "storage", "threads", "errors", "laws", "bonding", "step_methods",
     "linear_solvers"),
    ("folders", "fem"),
    ("verification",),
    ("scene",),
    ("scheme",),
    ("problem", "resources"),
    ("postprocess",),
    ("visuals",),
    ("io",),
    ("studies",),
    ("",),
)
FLOOR = {package: floor for floor, packages in enumerate(LAYERS) for package in packages}


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
    """``importer``'s package may import ``target`` (a module, or a name
    of the package's face): its own package or one on a lower floor."""
    parts = target.split(".")[1:]
    package = parts[0] if parts and parts[0] in FLOOR else ""
    return package == importer or FLOOR[package] < FLOOR[importer]


def test_every_package_is_on_one_floor():
    packages = {_package_of(module) for _, module, _ in _modules()}
    assert packages == set(FLOOR)
    assert sum(len(floor) for floor in LAYERS) == len(FLOOR)


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
