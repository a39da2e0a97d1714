"""The resource guard (adhesive_contact.resources): the estimate of memory,
time and output counts what the build makes, and a run larger than the
machine or longer than a day is refused unless forced; converge and sweep
check their largest run. The memory a run may take is the smallest of the
free memory, the address-space limit (ulimit -v, set in a child) and the
cgroup's limit (a cgroup tree written for the test); a mesh file larger than
that is refused before it is read."""

import json
import os
import subprocess
import sys
import textwrap

from conftest import COMPLIANT_BLOCK, assert_refused, invoke, scene_dict, solve_scene, to_toml

from adhesive_contact import build_problem, resources, scene_from_dict

def test_the_estimate_counts_what_the_build_makes():
    for changes in ({}, {"mesh.pattern": "cross", "mesh.refine": 2},
                    {"boundary.contact": ["bottom", "left"], "mesh.refine": 1}):
        scene = scene_from_dict(scene_dict(changes, COMPLIANT_BLOCK))
        est, problem = resources.estimate(scene), build_problem(scene)
        assert est.dofs == problem.ndofs and est.cells == problem.mesh.t.shape[1]
        # an upper bound: a corner shared by two contact sides is counted
        # twice (one shared with a Dirichlet side is a contact node)
        extra = 0 if len(scene.contact_sides) == 1 else 1
        assert est.contact_nodes == problem.boundary.nodes.size + extra
        assert est.levels == scene.steps + 1


def test_a_scene_larger_than_the_machine_is_refused_unless_forced(tmp_path, monkeypatch):
    est = resources.estimate(scene_from_dict(COMPLIANT_BLOCK))
    monkeypatch.setattr(resources, "memory_limits",
                        lambda: {"available memory": est.memory_bytes / 2})
    result, out = solve_scene(tmp_path, COMPLIANT_BLOCK)
    assert_refused(result, out, "is too large for this machine: it would need about")
    assert "--force" in result.stderr and "mesh.cells" in result.stderr
    result, out = solve_scene(tmp_path, COMPLIANT_BLOCK, "--force")
    assert result.exit_code == 0, result.stderr
    record = json.loads((out / "summary.json").read_text())["resources"]
    assert record["estimate"]["dofs"] == record["used"]["dofs"] == 30
    assert record["estimate"]["levels"] == record["used"]["levels"] == 3
    assert record["used"]["peak_memory_bytes"] > 0 and record["used"]["seconds"] > 0


def test_a_run_longer_than_a_day_is_refused(tmp_path):
    result, out = solve_scene(tmp_path, scene_dict({"time.steps": 10**8 - 1,
                                                    "mesh.cells": [1, 1]}, COMPLIANT_BLOCK))
    assert_refused(result, out, "is too large for this machine")


def test_converge_and_sweep_check_their_largest_run_and_their_out(tmp_path):
    scene = tmp_path / "scene.toml"
    scene.write_text(to_toml(COMPLIANT_BLOCK))
    result = invoke("converge", scene, "--param", "k", "--levels", 20, "--steps", 1000,
                 "--out", tmp_path / "c")
    assert_refused(result, tmp_path / "c", "the largest run of the study is too large")
    result = invoke("converge", scene, "--param", "k", "--levels", 40, "--out", tmp_path / "c")
    assert_refused(result, tmp_path / "c", "--levels")
    result = invoke("sweep", scene, "--set", "time.steps=2,99999999", "--out", tmp_path / "s")
    assert_refused(result, tmp_path / "s", "the variant time.steps=99999999 is too large")
    locked = tmp_path / "locked"
    locked.mkdir(mode=0o500)
    if os.access(locked, os.W_OK):   # root writes anywhere: a file in the way instead
        locked = tmp_path / "file"
        locked.write_text("a file")
    for args in (("converge", scene, "--param", "k"), ("sweep", scene, "--set",
                                                       "time.steps=1,2")):
        result = invoke(*args, "--out", locked / "out")
        assert_refused(result, locked / "out", "cannot be written")


# ---------------------------------------------------------------- the limits of the process


def test_the_guard_takes_the_address_space_limit(tmp_path):
    # under ulimit -v a run the limit cannot hold failed in PARDISO (error -2)
    scene = tmp_path / "scene.toml"
    scene.write_text(to_toml(scene_dict({"mesh.cells": [160, 40]}, COMPLIANT_BLOCK)))
    code = textwrap.dedent(f"""
        import resource, sys
        from adhesive_contact import resources, parse_scene
        from adhesive_contact_cli.main import main
        est = resources.estimate(parse_scene(open({str(scene)!r}).read()))
        used = resources._status("VmSize")
        # room for half the estimate beyond what this process maps already
        limit = used + int(est.memory_bytes / 2)
        resource.setrlimit(resource.RLIMIT_AS, (limit, resource.RLIM_INFINITY))
        print(int(est.memory_bytes), file=sys.stderr)
        main(["solve", {str(scene)!r}, "--out", {str(tmp_path / "out")!r}])
    """)
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            timeout=120)
    estimate, *lines = result.stderr.splitlines()
    assert result.returncode == 2, result.stderr
    assert len(lines) == 1 and "that the address-space limit (ulimit -v) leaves" in lines[0]
    assert lines[0].startswith("error: mesh.cells, mesh.refine, time.steps, boundary.contact: "
                               "the scene is too large for this machine: it would need about")
    assert not (tmp_path / "out").exists()


def test_the_cgroup_limit_is_read(tmp_path):
    v2, v1 = tmp_path / "v2", tmp_path / "v1"
    (v2 / "job").mkdir(parents=True)
    (v2 / "job" / "memory.max").write_text("1000000\n")
    (v2 / "job" / "memory.current").write_text("400000\n")
    (tmp_path / "cgroup2").write_text("0::/job\n")
    assert resources._cgroup_room(str(v2), str(tmp_path / "cgroup2")) == 600000
    (v2 / "job" / "memory.max").write_text("max\n")   # no limit
    assert resources._cgroup_room(str(v2), str(tmp_path / "cgroup2")) is None
    (v1 / "memory" / "job").mkdir(parents=True)
    (v1 / "memory" / "job" / "memory.limit_in_bytes").write_text("3000000\n")
    (v1 / "memory" / "job" / "memory.usage_in_bytes").write_text("1000000\n")
    (tmp_path / "cgroup1").write_text("5:cpu:/x\n4:memory:/job\n0::/\n")
    assert resources._cgroup_room(str(v1), str(tmp_path / "cgroup1")) == 2000000
    (v1 / "memory" / "job" / "memory.limit_in_bytes").write_text("9223372036854771712\n")
    assert resources._cgroup_room(str(v1), str(tmp_path / "cgroup1")) is None


def test_the_smallest_limit_is_the_memory_a_run_may_take(monkeypatch):
    monkeypatch.setattr(resources, "_cgroup_room", lambda: 5 * 2**30)
    limits = resources.memory_limits()
    assert limits["the cgroup's memory limit"] == 5 * 2**30
    assert resources.available_memory() == min(limits.values())
    est = resources.estimate(scene_from_dict(COMPLIANT_BLOCK))
    monkeypatch.setattr(resources, "_cgroup_room", lambda: int(est.memory_bytes / 2))
    assert resources.refusal(est).endswith(
        f"more than the {resources._bytes(int(est.memory_bytes / 2))} that the cgroup's "
        "memory limit leaves")


def test_a_mesh_file_larger_than_memory_is_refused_before_it_is_read(tmp_path, monkeypatch):
    mesh = tmp_path / "m.msh"
    mesh.write_bytes(b"$MeshFormat\n" + b" " * 10_000)
    scene = tmp_path / "scene.toml"
    scene.write_text(to_toml({"dim": 2, "mesh": {"domain": "file", "file": "m.msh"},
                              "boundary": {"dirichlet": ["top"]},
                              "material": {"E": 1.0, "nu": 0.3}, "time": {"T": 1.0, "steps": 1}}))
    monkeypatch.setattr(resources, "memory_limits", lambda: {"available memory": 40_000})
    monkeypatch.setattr(resources, "estimate", None)   # never reached: the file is not read
    result = invoke("solve", scene, "--out", tmp_path / "out")
    assert_refused(result, tmp_path / "out", "mesh.file: the scene is too large for this "
                   "machine: the mesh file is 0.01 MB; reading it takes about 0.0501 MB, "
                   "0.04 MB available; use a smaller mesh, or --force to read it anyway")
