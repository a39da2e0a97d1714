"""The memory of ``adhcontact solve`` is flat in the number of steps: the
levels stream to the output files as they are computed
(adhesive_contact.io.StreamingRecorder). The same mesh with 100 and with
1000 steps (a Prony memory, so the kernel keeps O(1) levels): peak resident
memory, outputs and plots included, within 20 % (measured 185 and 193 MiB),
and the growth under a quarter of the 142 MB that the history of u and σ
would take in memory."""

import subprocess
import sys

from conftest import law, prony, scene_dict, to_toml

RUN = """
import resource, sys
from adhesive_contact_cli.main import main
main(["solve", sys.argv[1], "--out", sys.argv[2]], standalone_mode=False)
print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)
"""


def peak_kib(tmp_path, steps):
    scene = tmp_path / f"steps{steps}.toml"
    scene.write_text(to_toml(scene_dict({
        "mesh": {"domain": "rectangle", "size": [2.0, 1.0], "cells": [60, 30]},
        "memory": prony((200.0, 0.3, 0.5)),
        "loads": {"body": ["0", "-400*t"]},
        "contact": {"gap": 0.002, "normal": law("compliance", c=5000.0)},
        "time.steps": steps})))
    done = subprocess.run([sys.executable, "-c", RUN, str(scene), str(tmp_path / f"out{steps}")],
                          capture_output=True, text=True, check=True)
    return int(done.stdout.split()[-1])


def test_peak_memory_of_1000_steps_is_within_20_percent_of_100(tmp_path):
    small, large = peak_kib(tmp_path, 100), peak_kib(tmp_path, 1000)
    history = 1000 * (1891 * 2 + 3600 * 4) * 8 / 1024   # u and σ of 1000 levels, KiB
    assert large < 1.2 * small, (small, large)
    # and far less than a history kept in memory would add (142 MB)
    assert large - small < 0.25 * history, (small, large)
