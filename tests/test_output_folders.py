"""Output folders under faults (adhesive_contact/folders.py, adhesive_contact/io/folder.py):
a folder that held a whole run holds it or the new whole run after a
failed publish, a SIGKILL at every step of the publish, a file-size limit
(the disk filling up) and a concurrent publisher; staging folders are known
by their marker, not their name; a killed study's temporary files go.

Every fault is placed deterministically: the kill at the k-th file move for
every k, the file-size limit with ``resource.setrlimit`` in a child, the
concurrent run as a child holding the lock."""

import errno
import json
import os
import resource
import signal
import subprocess
import sys
import textwrap
import time

import pytest
from adhesive_contact import load_solution
from adhesive_contact.folders import MARKER, FolderLock, publish, read_marker, recover
from adhesive_contact.storage import remove_stale_temporaries
from adhesive_contact_cli.main import main
from conftest import KILL_AT_MOVE, law, runner, scene_dict, to_toml

CLI = "from adhesive_contact_cli.main import main; main()"

SCENE = scene_dict({"title": "block", "mesh.cells": [32, 8], "loads.body": ["0", "-10*t"],
                    "contact.normal": law("compliance", c=100.0), "time.steps": 20})


def dead_pid():
    """The pid of a process that has ended."""
    child = subprocess.Popen([sys.executable, "-c", "pass"])
    child.wait()
    return child.pid


def snapshot(folder):
    """{name: bytes} of the files of a folder (not its subfolders)."""
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir()) if p.is_file()}


def cli(*args, cwd=None, limit=None, timeout=120):
    """``adhcontact args`` in a child process (with a file-size limit)."""
    def preexec():
        if limit is not None:
            resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
    return subprocess.run([sys.executable, "-c", CLI, *map(str, args)], cwd=cwd,
                          capture_output=True, text=True, timeout=timeout,
                          preexec_fn=preexec)


@pytest.fixture
def scene(tmp_path):
    path = tmp_path / "scene.toml"
    path.write_text(to_toml(SCENE))
    return path


@pytest.fixture
def earlier(tmp_path, scene):
    """A folder holding a complete run (and a user's file), and its bytes."""
    out = tmp_path / "out"
    result = runner().invoke(main, ["solve", str(scene), "--out", str(out), "-q"])
    assert result.exit_code == 0, result.output
    (out / "notes.txt").write_text("mine")
    return out, snapshot(out)


def staging_folders(*folders):
    return [p for folder in folders for p in folder.iterdir()
            if p.is_dir() and (p / MARKER).exists()]


# ---------------------------------------------------------------- staging by marker


def test_a_users_folder_named_like_a_staging_folder_stays(tmp_path, scene, earlier):
    out, before = earlier
    beside = tmp_path / f"out.tmp-{dead_pid()}-backup"
    inside = out / f".adhcontact.tmp-{dead_pid()}-mine"
    for folder in (beside, inside):
        folder.mkdir()
        (folder / "summary.json").write_text("{}")
    result = runner().invoke(main, ["solve", str(scene), "--out", str(out), "-q"])
    assert result.exit_code == 0, result.output
    assert (beside / "summary.json").read_text() == "{}"
    assert (inside / "summary.json").read_text() == "{}"


def test_the_staging_folder_of_a_killed_run_is_removed(tmp_path, scene, earlier):
    out, before = earlier
    # a run killed while writing its staging folder (its marker says "writing")
    code = textwrap.dedent(f"""
        import os, signal
        from adhesive_contact.folders import staged_folder
        with staged_folder({str(out)!r}, ["summary.json", "solution.npz"]) as staging:
            (staging / "solution.npz").write_bytes(b"half")
            os.kill(os.getpid(), signal.SIGKILL)
    """)
    child = subprocess.run([sys.executable, "-c", code])
    assert child.returncode == -signal.SIGKILL
    [stale] = staging_folders(out)
    assert read_marker(stale)["state"] == "writing"
    assert snapshot(out) == before    # the earlier run is untouched
    result = runner().invoke(main, ["solve", str(scene), "--out", str(out), "-q"])
    assert result.exit_code == 0, result.output
    assert not stale.exists() and staging_folders(out, tmp_path) == []


# ---------------------------------------------------------------- a publish that fails


def test_a_folder_where_an_output_file_goes_is_refused_before_the_run(scene, earlier):
    out, before = earlier
    (out / "solution.h5").unlink()
    (out / "solution.h5").mkdir()
    before = snapshot(out)
    result = runner().invoke(main, ["solve", str(scene), "--out", str(out), "-q"])
    assert result.exit_code == 2
    assert result.stderr.strip() == (f"error: --out: '{out}/solution.h5' is a folder, where "
                                     "the run writes a file; rename it or use another --out")
    assert snapshot(out) == before and staging_folders(out) == []


def make_publish(tmp_path):
    """A folder ``out`` holding an old run and a staging folder of a new one."""
    target = tmp_path / "out"
    target.mkdir(parents=True)
    for name in ("summary.json", "a.h5", "c.png"):
        (target / name).write_text(f"old {name}")
    staging = tmp_path / "out.tmp-x"
    staging.mkdir()
    (staging / MARKER).write_text(json.dumps({"kind": "adhcontact staging folder",
                                              "target": "out", "state": "writing",
                                              "outputs": [], "names": []}))
    for name in ("summary.json", "a.h5", "b.png"):
        (staging / name).write_text(f"new {name}")
    return target, staging


PUBLISHED = ["summary.json", "a.h5", "b.png", "c.png"]


def test_a_publish_that_fails_keeps_the_earlier_run(tmp_path, monkeypatch):
    # a folder where a file goes (made after the command's check): refused first
    target, staging = make_publish(tmp_path)
    (target / "b.png").mkdir()
    before = snapshot(target)
    with pytest.raises(OSError, match="b.png' is a folder, where the run writes a file; "
                                      "the earlier files in .* are kept"):
        publish(staging, target, PUBLISHED)
    assert snapshot(target) == before
    # a move that fails midway: everything is moved back
    (target / "b.png").rmdir()
    real, calls = os.replace, []

    def failing(at):
        def replace(a, b):
            calls.append(a)
            if len(calls) in at:
                raise OSError(errno.EIO, "Input/output error")
            return real(a, b)
        return replace

    for at in range(2, 8):   # 1: the marker; 2-4: the old files out; 5-7: the new in
        target, staging = make_publish(tmp_path / str(at))
        before = snapshot(target)
        calls.clear()
        monkeypatch.setattr(os, "replace", failing({at}))
        with pytest.raises(OSError, match="Input/output error.*the earlier files there "
                                          "are kept"):
            publish(staging, target, PUBLISHED)
        monkeypatch.setattr(os, "replace", real)
        assert snapshot(target) == before and not staging.exists()
    # and when moving back fails too, the next run finishes the publish
    target, staging = make_publish(tmp_path / "twice")
    calls.clear()
    monkeypatch.setattr(os, "replace", failing({6, 7}))
    with pytest.raises(OSError, match="the next run into it completes the move"):
        publish(staging, target, PUBLISHED)
    monkeypatch.setattr(os, "replace", real)
    assert read_marker(staging)["state"] == "publishing"
    recover(target)
    assert snapshot(target) == {n: f"new {n}".encode() for n in ("a.h5", "b.png",
                                                                  "summary.json")}
    assert not staging.exists()


# ---------------------------------------------------------------- SIGKILL at every move

OLD = {"summary.json": "old", "solution.h5": "old h5", "solution.npz": "old npz",
       "contact_map.png": "old map"}
NEW = {"summary.json": "new", "solution.h5": "new h5", "solution.npz": "new npz",
       "beta.png": "new beta"}
OUTPUTS = sorted(set(OLD) | set(NEW))

KILLED_PUBLISH = KILL_AT_MOVE + textwrap.dedent("""
    with folders.staged_folder(target, {outputs!r}) as staging:
        for name, text in {new!r}.items():
            (staging / name).write_text(text)
    print(calls[0])
""").format(outputs=OUTPUTS, new=NEW)


def whole_run(folder, user=True):
    """"old" or "new" when ``folder`` holds exactly one of the two runs
    (and the user's file), None when it holds no summary.json; fails on a
    mixed folder."""
    files = {p.name: p.read_text() for p in folder.iterdir() if p.is_file()
             and p.name != "notes.txt"}
    assert not user or (folder / "notes.txt").read_text() == "mine"
    if "summary.json" not in files:
        return None
    run = files["summary.json"]
    assert files == {"old": OLD, "new": NEW}[run], files
    return run


@pytest.mark.parametrize("fresh", [False, True], ids=["into an earlier run", "a new folder"])
def test_a_kill_at_any_move_of_a_publish_loses_no_whole_run(tmp_path, fresh):
    seen, k = [], 0
    while True:
        target = tmp_path / f"out{k}"
        if not fresh:
            target.mkdir()
            for name, text in {**OLD, "notes.txt": "mine"}.items():
                (target / name).write_text(text)
        child = subprocess.run([sys.executable, "-c", KILLED_PUBLISH, str(target), str(k)],
                               capture_output=True, text=True)
        if child.returncode == 0:   # k is past the last move: the publish finished
            assert whole_run(target, user=not fresh) == "new"
            seen.append("new")
            break
        assert child.returncode == -signal.SIGKILL, child.stderr
        if fresh and not target.exists():
            seen.append("none")
        else:
            # at once, before any recovery: a summary.json means one whole run
            at_kill = whole_run(target, user=not fresh)
            recover(target)   # what the next run into the folder does first
            after = whole_run(target, user=not fresh)
            # the new run once its publish began (finished by the recovery)
            assert after in ("old", "new") and (at_kill != "new" or after == "new")
            seen.append(after)
        assert staging_folders(tmp_path) == [] or not target.exists()
        k += 1
    assert k >= (2 if fresh else 2 * len(OLD))   # every move was a kill point
    # the earlier run until the publish begins, the new one from then on
    assert seen == sorted(seen, key=["none", "old", "new"].index)
    assert seen[-1] == "new" and ("old" in seen or fresh)


def test_a_solve_killed_at_random_moments_keeps_a_whole_run(tmp_path, scene, earlier):
    out, before = earlier
    for delay in (0.7, 2.2):   # seconds into the run (derandomised)
        child = subprocess.Popen([sys.executable, "-c", CLI, "solve", str(scene), "--out",
                                  str(out), "-q"], stdout=subprocess.DEVNULL,
                                 stderr=subprocess.DEVNULL)
        try:
            child.wait(delay)
        except subprocess.TimeoutExpired:
            child.kill()
            child.wait()
        result = cli("solve", scene, "--out", out, "-q")   # recovers, then runs
        assert result.returncode == 0, result.stderr
        assert staging_folders(out, tmp_path) == []
        solution = load_solution(out)
        assert solution.success and solution.t.size == 21
        assert (out / "notes.txt").read_text() == "mine"


# ---------------------------------------------------------------- a full disk


def test_a_full_disk_ends_with_one_line_and_keeps_the_earlier_run(tmp_path, scene, earlier):
    out, before = earlier
    assert len(before["solution.h5"]) > 400 * 1024   # the limit is met while writing
    result = cli("solve", scene, "--out", out, "-q", limit=400 * 1024)
    assert result.returncode == 1, result.stderr
    assert result.stderr == (f"error: --out: cannot write '{out}': File too large (the "
                             "earlier run there is kept)\n")
    assert snapshot(out) == before
    assert staging_folders(out, tmp_path) == []
    # into a new folder: nothing is left
    result = cli("solve", scene, "--out", tmp_path / "new", "-q", limit=400 * 1024)
    assert result.returncode == 1 and result.stderr.count("\n") == 1, result.stderr
    assert not (tmp_path / "new").exists() and staging_folders(tmp_path) == []


# ---------------------------------------------------------------- the lock


HOLD_LOCK = textwrap.dedent("""
    import sys, time
    from adhesive_contact.folders import FolderLock
    with FolderLock(sys.argv[1]):
        print("locked", flush=True)
        time.sleep(60)
""")


def test_a_second_run_into_a_locked_folder_is_refused(tmp_path, scene, earlier):
    out, before = earlier
    holder = subprocess.Popen([sys.executable, "-c", HOLD_LOCK, str(out)],
                              stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline() == "locked\n"
        started = time.monotonic()
        result = runner().invoke(main, ["solve", str(scene), "--out", str(out), "-q"])
        assert time.monotonic() - started < 30   # refused before the solve
        assert result.exit_code == 2
        assert result.stderr == (f"error: --out: '{out}' is being written by another "
                                 f"process (pid {holder.pid}); its lock is "
                                 f"'{tmp_path}/.out.lock'; wait for that run to end, or use "
                                 "another --out\n")
        assert snapshot(out) == before
    finally:
        holder.kill()
        holder.wait()
    # the holder was killed: its lock is taken over
    assert (tmp_path / ".out.lock").read_text() == f"{holder.pid}\n"
    result = runner().invoke(main, ["solve", str(scene), "--out", str(out), "-q"])
    assert result.exit_code == 0, result.output
    assert not (tmp_path / ".out.lock").exists()


def test_concurrent_publishers_leave_one_whole_run(tmp_path, scene):
    out = tmp_path / "out"
    other = tmp_path / "other.toml"
    other.write_text(to_toml(scene_dict({"time.steps": 8}, SCENE)))
    children = [subprocess.Popen([sys.executable, "-c", CLI, "solve", str(path), "--out",
                                  str(out), "-q"], stdout=subprocess.DEVNULL,
                                 stderr=subprocess.PIPE, text=True)
                for path in (scene, other)]
    codes = [child.wait(120) for child in children]
    errors = [child.stderr.read() for child in children]
    assert sorted(codes) in ([0, 0], [0, 2]), errors
    for code, error in zip(codes, errors):
        if code == 2:
            assert "is being written by another process" in error
    solution = load_solution(out)
    levels = solution.t.size
    assert levels in (9, 21)
    # the ParaView series is of the same run as summary.json
    assert (out / "contact.xdmf").read_text().count("<Time ") == levels
    assert (out / "solution.xdmf").read_text().count("<Time ") == levels


# ---------------------------------------------------------------- a partial run


def test_a_partial_run_does_not_replace_a_complete_one(tmp_path, scene, earlier):
    out, before = earlier
    failing = tmp_path / "failing.toml"
    failing.write_text(to_toml(scene_dict({"solver.max_iter": 1}, SCENE)))  # fails at step 1
    result = runner().invoke(main, ["solve", str(failing), "--out", str(out), "-q"])
    assert result.exit_code == 1
    assert result.stderr.startswith("error: step 1 (t = 0.05) did not converge")
    assert result.stderr.endswith(
        f"The 1 levels done were not written: {out}/ holds a complete earlier run, which "
        "is kept (use another --out to keep a partial run).\n"), result.stderr
    assert snapshot(out) == before
    # into a new folder the partial run is written, marked partial
    result = runner().invoke(main, ["solve", str(failing), "--out", str(tmp_path / "new")])
    assert result.exit_code == 1 and "(summary.json: run.partial = true)" in result.stderr
    assert load_solution(tmp_path / "new").t.size == 1


# ---------------------------------------------------------------- temporary files


def test_a_killed_writers_temporary_files_are_removed(tmp_path):
    dead, alive = dead_pid(), os.getpid()
    names = {f".error_vs_h.png.tmp-{dead}-k3j2h1g0": False,
             f".rates.json.tmp-{alive}-a1b2c3d4": True,     # a live writer's
             ".notes.tmp-mine": True, "error_vs_h.png": True}
    for name in names:
        (tmp_path / name).write_text("x")
    assert remove_stale_temporaries(tmp_path) == [f".error_vs_h.png.tmp-{dead}-k3j2h1g0"]
    assert {p.name for p in tmp_path.iterdir()} == {n for n, kept in names.items() if kept}


def test_a_rerun_of_converge_removes_a_killed_runs_temporary_plot(tmp_path):
    scene = tmp_path / "scene.toml"
    scene.write_text(to_toml(scene_dict({"mesh.cells": [4, 2], "time.steps": 2}, SCENE)))
    out = tmp_path / "study"
    args = ["converge", str(scene), "--param", "h", "--levels", "2", "--ref-h", "1",
            "--out", str(out)]
    assert runner().invoke(main, args).exit_code == 0
    stale = out / f".error_vs_h.png.tmp-{dead_pid()}-x8y7z6w5"
    stale.write_bytes(b"\x89PNG half")
    result = runner().invoke(main, args)
    assert result.exit_code == 0, result.output
    assert "0 of 2 levels computed now" in result.output
    assert not stale.exists()
    assert not [p for p in out.rglob("*") if ".tmp-" in p.name]


def test_the_lock_file_names_its_owner(tmp_path):
    with FolderLock(tmp_path / "a" / "b") as lock:
        assert lock.path == tmp_path / "a" / ".b.lock"
        assert lock.path.read_text() == f"{os.getpid()}\n"
    assert not (tmp_path / "a").exists()   # the parent it made is gone again


# ---------------------------------------------------------------- --out names


@pytest.mark.parametrize("make, needle", [
    (lambda d: d / ("o" * 300), "is 300 bytes long; at most 239 are allowed here"),
    (lambda d: (d / "link").symlink_to(d / "nowhere") or d / "link",
     "is a symbolic link to nothing (or a loop of links)"),
    (lambda d: ((d / "a").symlink_to(d / "b"), (d / "b").symlink_to(d / "a")) and d / "a",
     "is a symbolic link to nothing (or a loop of links)"),
    (lambda d: (d / "link").symlink_to(d / "nowhere") or d / "link" / "out",
     "is a symbolic link to nothing (or a loop of links)"),
])
def test_an_out_that_cannot_be_made_is_refused_before_the_solve(tmp_path, scene, make,
                                                               needle):
    # a traceback, or exit 1 after the whole solve
    out = make(tmp_path)
    result = runner().invoke(main, ["solve", str(scene), "--out", str(out), "-q"])
    assert result.exit_code == 2, result.output
    assert result.stderr.count("\n") == 1 and result.stderr.startswith("error: --out: ")
    assert needle in result.stderr
    assert not list(tmp_path.glob("*.lock")) and not list(tmp_path.glob(".*.lock"))
