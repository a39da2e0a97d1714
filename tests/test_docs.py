"""Every code block and command of README.md and docs/*.md is run or checked.

- fenced ```python blocks (and indented blocks that start with an import)
  run, in the order of their file, in one namespace per file, from a
  temporary folder that holds the repository's ``studies/`` (the paths the
  blocks name) and the ``default/`` output folder of ``adhcontact solve``
  (read by docs/python.md); the names a block takes from its prose
  (``toml_text``, ``document``, ``folder``) are given. A convergence
  study of ``levels=4`` runs with ``levels=2`` (16 s against 4 s; the same
  calls);
- fenced ```toml blocks are scenes and must be valid (``parse_scene``);
  indented TOML fragments must parse;
- commands: ``adhcontact ...`` lines have every option they use checked
  against the command's own options; those without a placeholder
  (SCENE.toml, DIR, ...) or a cluster address are run (``adhcontact solve``
  on the built-in scene), those with SCENE.toml are run on a one-step
  scene for ``solve`` and ``check`` (``converge`` and ``sweep`` are too
  slow to run here: their options are checked); ``dask worker`` and
  ``dask scheduler`` options are checked against ``dask ... --help``;
  ``python studies/...py`` and ``examples/...`` scripts must exist
  (examples are run by tests/test_examples.py); the install commands
  (``python3 -m venv``, ``pip install``) are not run: the ``test`` extra
  they name must exist in pyproject.toml, and ``python -m pytest -q`` is
  this suite;
- every other indented block is mathematics (it holds a symbol no code
  here uses), checked so that no code block goes unnoticed.
"""

import re
import shlex
import subprocess
import sys
import tomllib
from pathlib import Path

import click
import pytest
from click.testing import CliRunner

from adhesive_contact import parse_scene
from adhesive_contact_cli.main import main

ROOT = Path(__file__).resolve().parents[1]
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
#: the first words of a command line
COMMANDS = ("adhcontact", "python", "python3", ".venv/bin/", "dask", "pip", "/usr/bin/time",
            "PATH=")
#: characters of mathematics, which no code block here holds
MATH = set("σεβγνττλμΣ∫≤≥−½ᵀ⁻⁽⁾²³ΩΓ∂⟨⟩∈")
#: placeholders of a command's usage line
PLACEHOLDER = re.compile(r"\b(SCENE\.toml|DIR|ADDRESS|J|R|N|KEY|V1|V2)\b")
#: a one-step scene for the commands given SCENE.toml
SMALL = """title = "small"
dim = 2
[mesh]
domain = "rectangle"
size = [2.0, 0.5]
cells = [8, 2]
[boundary]
dirichlet = ["top"]
contact = ["bottom"]
[material]
E = 1000.0
nu = 0.3
[loads]
body = ["0", "-10*t"]
[contact.normal]
law = "compliance"
c = 1000.0
[time]
T = 1.0
steps = 1
"""


def blocks(path):
    """(kind, line, text) of every fenced block (kind: its language) and
    every indented block (kind "indented") of a markdown file."""
    lines = path.read_text(encoding="utf-8").split("\n")
    found, i = [], 0
    while i < len(lines):
        fence = re.match(r"^```(\w*)", lines[i])
        if fence:
            j = lines.index("```", i + 1)
            found.append((fence.group(1) or "text", i + 1, "\n".join(lines[i + 1:j])))
            i = j + 1
            continue
        if lines[i].startswith("    ") and (i == 0 or not lines[i - 1].strip()):
            j = i
            while j < len(lines) and (lines[j].startswith("    ") or (
                    not lines[j].strip() and j + 1 < len(lines)
                    and lines[j + 1].startswith("    "))):
                j += 1
            found.append(("indented", i + 1, "\n".join(line[4:] for line in lines[i:j])))
            i = j
            continue
        i += 1
    return found


def kind_of(kind, text):
    """python, toml, commands or math."""
    first = text.lstrip().split("\n")[0]
    if kind in ("python", "toml"):
        return kind
    if first.startswith(("from ", "import ")):
        return "python"
    if first.startswith(COMMANDS):
        return "commands"
    try:
        tomllib.loads(text)
        return "toml"
    except tomllib.TOMLDecodeError:
        pass
    assert MATH & set(text), f"a block that is neither code nor mathematics: {text!r}"
    return "math"


ALL = [(path, *block) for path in DOCS for block in blocks(path)]


def of_kind(wanted):
    return [(p, line, text) for p, kind, line, text in ALL if kind_of(kind, text) == wanted]


def label(item):
    return f"{item[0].name}:{item[1]}"


def test_the_blocks_are_found():
    kinds = {kind_of(kind, text) for _, kind, _, text in ALL}
    assert kinds == {"python", "toml", "commands", "math"}
    assert len(of_kind("python")) >= 8 and len(of_kind("commands")) >= 6


@pytest.fixture(scope="module")
def workdir(tmp_path_factory):
    """A folder with studies/ and the default/ output of adhcontact solve."""
    folder = tmp_path_factory.mktemp("docs")
    (folder / "studies").symlink_to(ROOT / "studies")
    result = CliRunner().invoke(main, ["solve", "--quiet", "--out", str(folder / "default")])
    assert result.exit_code == 0, result.output
    return folder


@pytest.mark.parametrize("path", sorted({p for p, _, _ in of_kind("python")}),
                         ids=lambda p: p.name)
def test_python_blocks_run(path, workdir, monkeypatch):
    import matplotlib.pyplot as plt

    monkeypatch.chdir(workdir)
    text = (ROOT / "cli" / "default_scene.toml").read_text(encoding="utf-8")
    (workdir / f"files-{path.stem}").mkdir(exist_ok=True)
    namespace = {"toml_text": text, "document": tomllib.loads(text),
                 "folder": workdir / f"files-{path.stem}", "__name__": "__docs__"}
    for p, line, code in of_kind("python"):
        if p != path:
            continue
        code = code.replace("levels=4", "levels=2")
        try:
            exec(compile(code, f"{path.name}:{line}", "exec"), namespace)
        finally:
            plt.close("all")


@pytest.mark.parametrize("item", of_kind("toml"), ids=label)
def test_toml_blocks_parse(item):
    path, line, text = item
    document = tomllib.loads(text)
    if "dim" in document and "mesh" in document:   # a whole scene
        parse_scene(text)


def command_lines(text):
    """The commands of a block: its lines joined across continuations,
    split at &&, comments dropped."""
    joined = re.sub(r"\n\s+(?=\[|-)", " ", text)
    out = []
    for line in joined.split("\n"):
        line = line.split("  #")[0].strip()
        out += [part.strip() for part in line.split("&&") if part.strip()]
    return out


def options_used(command):
    """The options of a usage line: --name or -x tokens, brackets and
    alternatives (a|b) dropped."""
    tokens = command.replace("[", " ").replace("]", " ").replace("|", " | ").split()
    return sorted({t.split("=")[0] for t in tokens if t.startswith("-") and t != "-"})


def click_options(name):
    command = main.get_command(click.Context(main), name)
    assert command is not None, f"adhcontact has no command {name!r}"
    return {opt for param in command.params for opt in (*param.opts, *param.secondary_opts)}


def check_adhcontact(command, workdir, tmp_path):
    words = command.replace("[", " ").replace("]", " ").split()
    name = words[1]
    unknown = set(options_used(command)) - click_options(name) - {"--help"}
    assert not unknown, f"{command!r}: adhcontact {name} has no option {sorted(unknown)}"
    if name not in ("solve", "check") or "--scheduler" in command:
        return "options checked"
    scene = tmp_path / "small.toml"
    scene.write_text(SMALL)
    args = [w for w in shlex.split(command)[1:] if "[" not in w and "]" not in w]
    args = [str(scene) if w == "SCENE.toml" else w for w in args]
    if "--out" in args:
        args[args.index("--out") + 1] = str(tmp_path / "out")
    elif name == "solve":
        args += ["--out", str(tmp_path / "out")]
    result = CliRunner().invoke(main, args)
    assert result.exit_code == 0, (command, result.output)
    return "ran"


def check_command(command, workdir, tmp_path):
    """How ``command`` was checked (see the module docstring)."""
    command = command.removeprefix(".venv/bin/").removeprefix("/usr/bin/time -v ")
    head = command.split()[0]
    if head == "adhcontact":
        return check_adhcontact(command, workdir, tmp_path)
    if head == "dask":
        sub = command.split()[1]
        done = subprocess.run([str(Path(sys.executable).parent / "dask"), sub, "--help"],
                              capture_output=True, text=True, timeout=120)
        assert done.returncode == 0, done.stderr
        for option in options_used(command):
            assert option in done.stdout, f"dask {sub} has no option {option}"
        return "options checked"
    if command.startswith("python3 -m venv") or command.startswith("pip install"):
        extra = re.search(r"\.\[(\w+)\]", command)
        if extra:
            pyproject = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
            assert extra.group(1) in pyproject["project"]["optional-dependencies"]
        return "not run (installation)"
    if command.startswith("python -m pytest"):
        return "this suite"
    if head in ("python", "python3"):
        script = command.split()[1]
        assert (ROOT / script).is_file(), f"{command!r}: no {script}"
        return "script exists"
    if head.startswith("PATH="):
        script = command.split()[2]
        assert (ROOT / script).is_file(), f"{command!r}: no {script}"
        return "script exists"
    raise AssertionError(f"a command of an unknown kind: {command!r}")


@pytest.mark.parametrize("item", of_kind("commands"), ids=label)
def test_commands_are_valid(item, workdir, tmp_path, monkeypatch):
    monkeypatch.chdir(workdir)
    path, line, text = item
    for command in command_lines(text):
        check_command(command, workdir, tmp_path)


def test_a_wrong_option_in_a_usage_line_would_be_caught(tmp_path):
    with pytest.raises(AssertionError, match="has no option"):
        check_adhcontact("adhcontact solve SCENE.toml [--output DIR]", tmp_path, tmp_path)
    assert check_adhcontact("adhcontact solve SCENE.toml [--out DIR]", tmp_path,
                            tmp_path) == "ran"


def readme_row(table):
    """The keys cell of the README's scene table row of ``table``."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    row = re.search(rf"^\| `{re.escape(table)}` \| (.*) \|$", text, re.MULTILINE)
    assert row, f"README.md has no row for {table}"
    return row.group(1)


def test_the_readme_scene_table_names_every_law_and_integrator():
    """README.md's table of scenes names every law of the registries, every
    bonding integrator and every mesh pattern (a law left out of it, as
    coulomb and cohesive were, is a law a new user does not find)."""
    from adhesive_contact.laws import BONDING_LAWS, FRICTION_LAWS, NORMAL_LAWS
    from adhesive_contact.scene.keys import KEYS
    from adhesive_contact.bonding import INTEGRATORS
    wanted = {"[contact.normal]": NORMAL_LAWS, "[contact.friction]": FRICTION_LAWS,
              "[contact.bonding]": {**BONDING_LAWS, **INTEGRATORS}}
    for table, names in wanted.items():
        row = readme_row(table)
        missing = [name for name in names if f"`{name}`" not in row]
        assert not missing, f"README.md's {table} row leaves out {missing}"
    patterns = {p for choices in KEYS["mesh.pattern"].choices.values() for p in choices}
    row = readme_row("[mesh]")
    assert patterns and all(f"`{p}`" in row for p in patterns)
