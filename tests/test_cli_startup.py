"""``adhcontact --help`` imports neither the library nor matplotlib nor
dask (they take about a second; the help should not wait for them), and
the short help of the commands imported on demand is their docstring's."""

import importlib
import subprocess
import sys

from adhesive_contact_cli.main import LAZY_COMMANDS

CHECK = """
import sys
from adhesive_contact_cli.main import main
try:
    main(["--help"])
except SystemExit as done:
    assert done.code == 0
heavy = sorted(m for m in ("adhesive_contact", "matplotlib", "scipy", "distributed", "skfem")
               if m in sys.modules)
print("heavy:", heavy)
"""


def test_help_imports_nothing_heavy():
    done = subprocess.run([sys.executable, "-c", CHECK], capture_output=True, text=True,
                          check=True)
    assert "converge" in done.stdout and "sweep" in done.stdout and "solve" in done.stdout
    assert done.stdout.strip().splitlines()[-1] == "heavy: []"


def test_lazy_short_help_is_the_commands_own():
    for name, (module, attribute, short) in LAZY_COMMANDS.items():
        command = getattr(importlib.import_module(module), attribute)
        assert command.name == name
        assert command.help.split("\n")[0].startswith(short.rstrip(".")), name
