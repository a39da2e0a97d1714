"""What a run's outputs cost beside its solve, and how much ``[output]
every`` and ``fields`` save.

    python studies/bench/outputs.py [--repeat 3]     # about 4 minutes here

The scene is the built-in default scene refined to 240 × 24 cells (12,050
dofs, 241 contact nodes) with 400 steps (``outputs/strip_12k.toml``), run
with every level's fields (``every = 1``), with ``every = 10`` and with
the scalars only (``fields = []``). For each, ``--repeat`` times:

- the whole process, ``adhcontact solve SCENE --out DIR --quiet``: its
  wall seconds and the bytes of every file it wrote;
- the same steps in this process (:func:`in_process`, the calls the
  command makes, each timed): the solve without its recording, the
  recording of the levels (u to the scratch file, the fields of the field
  levels to the XDMF series), the field levels left at the end (the last
  level and the peaks), the energies and level scalars, ``summary.json``,
  ``scalars.csv``, ``solution.npz``, and the figures; *writing* is every
  one of these but the solve and the figures, *drawing* the figures.

Writes ``outputs.csv`` and ``outputs.json`` (with the machine) beside
this script and prints one row per configuration (medians).
"""

import argparse
import json
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

from machine import adhcontact, describe  # studies/bench/machine.py, beside this script

HERE = Path(__file__).resolve().parent
SCENE = HERE / "outputs" / "strip_12k.toml"
CONFIGS = {"every_1": "", "every_10": "\n[output]\nevery = 10\n",
           "scalars_only": "\n[output]\nfields = []\n"}
FIELDS = ("config", "repeats", "process_s", "files_mb", "solve_s", "recording_s",
          "pending_s", "scalars_s", "summary_s", "scalars_csv_s", "npz_s", "writing_s",
          "drawing_s", "in_process_s", "writing_share", "writing_and_drawing_share")


def scene_text(config):
    return SCENE.read_text() + CONFIGS[config]


def whole_process(config):
    """(wall seconds, bytes of the files) of one ``adhcontact solve``."""
    with tempfile.TemporaryDirectory() as folder:
        scene = Path(folder) / "scene.toml"
        scene.write_text(scene_text(config))
        out = Path(folder) / "out"
        t0 = time.perf_counter()
        subprocess.run([adhcontact(), "solve", str(scene), "--out", str(out), "--quiet"],
                       check=True, stdout=subprocess.DEVNULL)
        seconds = time.perf_counter() - t0
        return seconds, sum(p.stat().st_size for p in out.iterdir())


class TimedRecorder:
    """A StreamingRecorder whose ``record`` is timed."""

    def __init__(self, recorder):
        self.recorder, self.seconds = recorder, 0.0

    def record(self, level):
        t0 = time.perf_counter()
        self.recorder.record(level)
        self.seconds += time.perf_counter() - t0

    def __getattr__(self, name):
        return getattr(self.recorder, name)


def in_process(config):
    """{part: seconds} of the calls ``adhcontact solve`` makes, each timed."""
    import matplotlib
    matplotlib.use("Agg")
    from adhesive_contact import build_problem, parse_scene, solve
    from adhesive_contact.io import StreamingRecorder
    from adhesive_contact.io.npz import write_npz
    from adhesive_contact.io.scalars import write_scalars_csv
    from adhesive_contact.io.summary import write_summary
    from adhesive_contact.postprocess import energies
    from adhesive_contact.postprocess.level_scalars import level_scalars
    from adhesive_contact.problem.warnings import solution_warnings
    from adhesive_contact.threads import one_blas_thread
    from adhesive_contact.visuals import write_plots

    out = {}
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        problem = build_problem(parse_scene(scene_text(config)))
        t0 = time.perf_counter()
        recorder = TimedRecorder(StreamingRecorder(problem, folder))
        solution = solve(problem, recorder=recorder)
        out["recording_s"] = recorder.seconds
        out["solve_s"] = time.perf_counter() - t0 - recorder.seconds
        t0 = time.perf_counter()
        levels = recorder.field_levels()
        out["pending_s"] = time.perf_counter() - t0
        with one_blas_thread():
            t0 = time.perf_counter()
            lines = solution_warnings(solution)
            history = energies(solution)
            columns = level_scalars(solution, history)
            out["scalars_s"] = time.perf_counter() - t0
            for name, write in (
                    ("summary_s", lambda: write_summary(solution, folder / "summary.json", None,
                                                        history, lines, levels, columns)),
                    ("scalars_csv_s", lambda: write_scalars_csv(folder / "scalars.csv",
                                                                problem, columns)),
                    ("npz_s", lambda: write_npz(solution, folder / "solution.npz", levels,
                                                columns)),
                    ("drawing_s", lambda: write_plots(solution, folder, [], history))):
                t0 = time.perf_counter()
                write()
                out[name] = time.perf_counter() - t0
            t0 = time.perf_counter()
            recorder.close()
            out["pending_s"] += time.perf_counter() - t0
    out["writing_s"] = sum(out[k] for k in ("recording_s", "pending_s", "scalars_s",
                                            "summary_s", "scalars_csv_s", "npz_s"))
    out["in_process_s"] = out["solve_s"] + out["writing_s"] + out["drawing_s"]
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--configs", default=",".join(CONFIGS))
    args = parser.parse_args()
    rows = []
    for config in args.configs.split(","):
        runs = []
        for _ in range(args.repeat):
            seconds, size = whole_process(config)
            runs.append({"process_s": seconds, "files_mb": size / 1e6, **in_process(config)})
        row = {"config": config, "repeats": args.repeat}
        row.update({k: statistics.median(r[k] for r in runs) for k in runs[0]})
        row["writing_share"] = row["writing_s"] / row["in_process_s"]
        row["writing_and_drawing_share"] = ((row["writing_s"] + row["drawing_s"])
                                            / row["in_process_s"])
        rows.append(row)
        print(f"{config:13s} process {row['process_s']:6.2f} s, files {row['files_mb']:7.1f} MB;"
              f" in process: solve {row['solve_s']:.2f} s, writing {row['writing_s']:.2f} s "
              f"({100 * row['writing_share']:.0f} %), drawing {row['drawing_s']:.2f} s "
              f"(writing and drawing {100 * row['writing_and_drawing_share']:.0f} %)",
              flush=True)
    with open(HERE / "outputs.csv", "w") as f:
        f.write(",".join(FIELDS) + "\n")
        for row in rows:
            f.write(",".join(f"{row[k]:.4g}" if isinstance(row[k], float) else str(row[k])
                             for k in FIELDS) + "\n")
    (HERE / "outputs.json").write_text(json.dumps({"machine": describe(), "rows": rows},
                                                  indent=1))


if __name__ == "__main__":
    main()
