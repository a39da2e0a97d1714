"""Hostile cases of the third reliability round (the defects found on the
newest surfaces), each kept as a test: bad input is one line naming the
key or value and what is allowed, exit 2, no traceback and nothing written.

The commands run in a child process where a defect used to hang or eat
the machine's memory, so that a hang fails the test instead of the suite.
"""

import os
import subprocess
import sys

import pytest

from adhesive_contact import load_scene

COMMANDS = (["solve"], ["check"], ["converge", "--param", "h", "--levels", "2"],
            ["sweep", "--set", "time.steps=1,2"])


def cli(*args, cwd, timeout=60):
    """``adhcontact ARGS`` in a child, with a time limit."""
    return subprocess.run([sys.executable, "-c", "from adhesive_contact_cli.main import main; "
                           "main()", *args], capture_output=True, text=True, timeout=timeout,
                          cwd=cwd)


def one_error_line(result, needle):
    assert result.returncode == 2, (result.returncode, result.stderr)
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), result.stderr
    assert needle in lines[0], lines[0]
    assert "Traceback" not in result.stderr + result.stdout


# ---------------------------------------------------------------- scene paths that are no scene

def _fifo(d):
    os.mkfifo(d / "scene.toml")
    return str(d / "scene.toml")


def _large(d):
    (d / "scene.toml").write_bytes(b"# " + b"x" * (2 << 20) + b"\n")
    return str(d / "scene.toml")


@pytest.mark.parametrize("make, needle", [
    (_fifo, "a named pipe (FIFO), not a regular file"),
    (lambda d: "/dev/zero", "'/dev/zero': a device, not a regular file"),
    (_large, "larger than 1 MiB, which no scene is"),
])
@pytest.mark.parametrize("command", COMMANDS, ids=lambda c: c[0])
def test_a_scene_path_that_is_no_scene_file_is_one_line_exit_2(tmp_path, make, needle, command):
    """A FIFO as the scene path hung every command; /dev/zero was read until
    memory ran out (exit 1 naming --force); both are refused before the file
    is opened, and a file past any scene's size before it is parsed."""
    path = make(tmp_path)
    result = cli(command[0], path, *command[1:], "--out", str(tmp_path / "out"), cwd=tmp_path) \
        if command[0] != "check" else cli("check", path, cwd=tmp_path)
    one_error_line(result, needle)
    assert not (tmp_path / "out").exists()


def test_the_library_refuses_a_scene_path_that_is_no_regular_file(tmp_path):
    os.mkfifo(tmp_path / "pipe.toml")
    with pytest.raises(OSError, match="a named pipe"):
        load_scene(tmp_path / "pipe.toml")
    with pytest.raises(OSError, match="a device"):
        load_scene("/dev/zero")
