"""``adhesive_contact.visuals`` draws the package's figures from Python: a
figure of a small solved scene without the command line imported, on the
caller's matplotlib backend (the library never chooses one); only the
command line selects Agg, and none of its modules imports matplotlib."""

import os
import re
import subprocess
import sys
from pathlib import Path

from conftest import COMPLIANT_BLOCK, scene_dict, solve_scene

from adhesive_contact.visuals import common as figure_common
from adhesive_contact.visuals import solution as run_figures


ROOT = Path(__file__).resolve().parents[1]

#: a small glued strip lifted at its top, solved in a fresh process (the
#: scene written out: conftest selects Agg for the tests' own process)
SOLVE = """
import sys
from adhesive_contact import build_problem, scene_from_dict, solve
solution = solve(build_problem(scene_from_dict({
    "dim": 2, "mesh": {"domain": "rectangle", "size": [2.0, 0.5], "cells": [4, 2]},
    "boundary": {"dirichlet": [], "contact": ["bottom"],
                 "displacement": {"top": ["0", "0.002*t"]}},
    "material": {"E": 1000.0, "nu": 0.3}, "time": {"T": 1.0, "steps": 2},
    "contact": {"gap": 0.05,
                "normal": {"law": "adhesive_compliance", "c": 1e4, "gamma": 5e3, "L": 0.01},
                "bonding": {"law": "fremond", "beta0": 1.0, "gamma_nu": 1e5,
                            "gamma_tau": 5e4, "eps_a": 0.0, "L": 0.01}}})))
"""

#: no backend chosen: importing and drawing chooses none of its own
UNCHOSEN = """
import matplotlib
from adhesive_contact import visuals
assert matplotlib.rcParams._get_backend_or_none() is None, "import chose a backend"
""" + SOLVE + """
fig = visuals.figure_beta(solution)
assert [ax.get_ylabel() for ax in fig.axes][:2] == [
    "bonding β\\n(1 = fully bonded, 0 = debonded)", "time t"]
assert "adhesive_contact_cli" not in sys.modules
print("backend:", matplotlib.get_backend())
"""

#: a backend chosen by the caller (as a notebook has its own) is kept
CHOSEN = """
import matplotlib
matplotlib.use("svg")
from adhesive_contact import visuals
""" + SOLVE + """
fig = visuals.figure_contact_traction(solution)
assert fig.axes[2].get_xlabel() == "x along Γ_C (units of length)"
names = visuals.write_plots(solution, sys.argv[1])   # a str folder
assert names == ["deformed.png", "contact_traction.png", "beta.png", "load_displacement.png",
                 "energy.png", "debonding.png"]
assert matplotlib.get_backend() == "svg", matplotlib.get_backend()
assert "adhesive_contact_cli" not in sys.modules
print("backend:", matplotlib.get_backend())
"""


def run_python(code, *args):
    """Run ``code`` with ``args`` in a fresh interpreter without MPLBACKEND;
    its stdout."""
    environment = {k: v for k, v in os.environ.items() if k != "MPLBACKEND"}
    done = subprocess.run([sys.executable, "-c", code, *map(str, args)], capture_output=True, text=True,
                          env=environment)
    assert done.returncode == 0, done.stderr
    return done.stdout


def test_a_figure_is_drawn_without_the_cli_and_no_backend_is_chosen():
    # headless: pyplot resolves its automatic backend to agg when the figure is made
    assert run_python(UNCHOSEN).strip().splitlines()[-1] == "backend: agg"


def test_the_callers_backend_is_kept_and_the_pngs_are_written(tmp_path):
    assert run_python(CHOSEN, tmp_path).strip().splitlines()[-1] == \
        "backend: svg"
    for name in ("deformed", "contact_traction", "beta", "load_displacement"):
        assert (tmp_path / f"{name}.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert not [p.name for p in tmp_path.iterdir() if ".tmp-" in p.name]   # atomic, no leftovers


def test_only_the_command_selects_agg():
    code = ("import os, sys\nfrom adhesive_contact_cli.main import main\n"
            "assert 'MPLBACKEND' not in os.environ\n"
            "try:\n    main(['--version'])\nexcept SystemExit:\n    pass\n"
            "print(os.environ['MPLBACKEND'], 'matplotlib' in sys.modules)")
    assert run_python(code).strip().splitlines()[-1] == "Agg False"


def test_no_cli_module_imports_matplotlib_and_the_library_never_calls_use():
    importing = re.compile(r"^\s*(import|from)\s+matplotlib", re.MULTILINE)
    assert [p.name for p in (ROOT / "cli").glob("*.py") if importing.search(p.read_text())] \
        == []
    calls = re.compile(r"matplotlib\.use\(|\buse\(\s*[\"']agg", re.IGNORECASE)
    assert [str(p.relative_to(ROOT)) for p in (ROOT / "adhesive_contact").rglob("*.py")
            if calls.search(p.read_text())] == []


# ----------------------------------------------------------------
# Figures that cannot cost the data: a dollar in the title is drawn, a
# plot that fails is a warning and the other outputs are kept.


def test_a_dollar_in_the_title_is_drawn(tmp_path):
    result, out = solve_scene(tmp_path, scene_dict({"title": "$x^$ and $"}, COMPLIANT_BLOCK))
    assert result.exit_code == 0, result.stderr
    assert {"deformed.png", "beta.png", "contact_traction.png"} <= set(os.listdir(out))
    assert figure_common.plot_title("$x^$") == r"\$x^\$"
    assert len(figure_common.plot_title("a" * 500)) == figure_common.TITLE_CHARS


def test_a_plot_that_fails_is_a_warning_and_the_data_is_kept(tmp_path, monkeypatch):
    def broken(solution, path):
        raise RuntimeError("no font")
    monkeypatch.setattr(run_figures, "plot_beta", broken)
    result, out = solve_scene(tmp_path, COMPLIANT_BLOCK)
    assert result.exit_code == 0, result.stderr
    assert "warning: beta.png was not drawn: RuntimeError: no font" in result.stderr
    assert {"summary.json", "solution.npz", "deformed.png"} <= set(os.listdir(out))
    assert "beta.png" not in os.listdir(out)
