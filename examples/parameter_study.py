"""A small parameter study: the block scene for three foundation stiffnesses.

    python examples/parameter_study.py [FOLDER]

Runs adhesive_contact.studies.Sweep over contact.normal.c on a coarse copy
of studies/scenes/block.toml and prints one line per run from its
records (runs.csv holds the same). The study is kept in FOLDER (default: a
temporary folder, removed at the end); run again with the same FOLDER, it
resumes and computes nothing.
"""

import sys
import tempfile
import tomllib
from pathlib import Path

from adhesive_contact.studies import Sweep

ROOT = Path(__file__).resolve().parents[1]


def main(folder):
    document = tomllib.loads((ROOT / "studies" / "scenes" / "block.toml").read_text())
    document["mesh"]["cells"] = [16, 8]          # coarse and short: a few tenths of a second
    document["time"]["steps"] = 8
    sweep = Sweep(document, [("contact.normal.c", [1e3, 1e4, 1e5])], folder=folder)
    result = sweep.run()
    print(f"{'c':>8} {'outcome':>8} {'on wall':>8} {'normal F at T':>14}")
    for record in result.records:
        print(f"{record['values']['contact.normal.c']:8.0e} {record['outcome']:>8} "
              f"{record['on_wall_T']:8d} {record['normal_force_T']:14.2f}")
    print(f"files: {', '.join(result.files)} in {folder}")
    return result


if __name__ == "__main__":
    if len(sys.argv) > 1:
        main(Path(sys.argv[1]))
    else:
        with tempfile.TemporaryDirectory() as tmp:
            main(Path(tmp) / "sweep")
