"""Real geometry: meshes from files, curved contact sides, the gap from a
foundation's geometry.

The committed meshes are made by studies/meshes/make_meshes.py (gmsh); the
tests also write small meshes with meshio to check what the reader refuses.
"""

import json
import os
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import meshio
import numpy as np
import pytest
from adhesive_contact_cli.main import main
from click.testing import CliRunner
from conftest import DELETE, law, run, scene_dict, to_toml

from adhesive_contact import (
    SceneError,
    build_problem,
    load_scene,
    parse_scene,
    scene_from_dict,
    solve,
)
from adhesive_contact.fem.contact_boundary import facet_normals
from adhesive_contact.fem.meshes import build_mesh, read_mesh_file
from adhesive_contact.fem.meshes.builtin import structured_mesh
from adhesive_contact.postprocess import penetration, total_contact_force
from adhesive_contact.scene import MeshSpec
from adhesive_contact.verification.errors import prolongation

MESHES = Path(__file__).resolve().parents[1] / "studies" / "meshes"
HALF_DISC = MESHES / "half_disc.msh"
CYLINDER = MESHES / "cylinder_foot.msh"


def file_scene(path, changes=None, dim=2):
    """A scene on the mesh file ``path`` (top clamped, foot the contact side)."""
    base = {"dim": dim, "mesh": {"domain": "file", "file": str(path)},
            "boundary": {"dirichlet": ["top"], "contact": ["foot"]},
            "material": {"E": 1000.0, "nu": 0.3}, "time": {"T": 1.0, "steps": 1}}
    return scene_dict(changes, base)


def write_msh(path, mesh, sides, cell_type=None, cells=None):
    """Write a scikit-fem mesh (or other cells) as gmsh 2.2 with named sides."""
    d = mesh.dim()
    facet = "line" if d == 2 else "triangle"
    blocks = [(facet, mesh.facets[:, mesh.boundaries[s]].T) for s in sides]
    blocks.append((cell_type or ("triangle" if d == 2 else "tetra"),
                   mesh.t.T if cells is None else cells))
    tags = [np.full(len(b[1]), i + 1) for i, b in enumerate(blocks)]
    field = {s: np.array([i + 1, d - 1]) for i, s in enumerate(sides)}
    field["body"] = np.array([len(sides) + 1, d])
    points = mesh.p.T if d == 3 else np.column_stack([mesh.p.T, np.zeros(mesh.p.shape[1])])
    meshio.write(path, meshio.Mesh(points, blocks, cell_data={
        "gmsh:physical": tags, "gmsh:geometrical": tags}, field_data=field),
        file_format="gmsh22", binary=False)


# ---------------------------------------------------------------- reading files


def test_gmsh_formats_22_and_41_give_the_same_mesh():
    a = read_mesh_file(HALF_DISC, 2)
    b = read_mesh_file(MESHES / "half_disc_v22.msh", 2)
    assert np.array_equal(a.p, b.p) and np.array_equal(a.t, b.t)
    assert set(a.boundaries) == {"top", "foot"}
    for name in a.boundaries:
        assert np.array_equal(a.boundaries[name], b.boundaries[name])
    # the groups are the arc and the flat side: every foot vertex on the unit circle
    foot = np.unique(a.facets[:, a.boundaries["foot"]])
    np.testing.assert_allclose(np.hypot(a.p[0, foot], a.p[1, foot] - 1.0), 1.0, atol=1e-12)
    top = np.unique(a.facets[:, a.boundaries["top"]])
    np.testing.assert_allclose(a.p[1, top], 1.0, atol=1e-12)


def test_mesh_file_is_relative_to_the_scene_file(tmp_path):
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "part.msh").write_bytes(HALF_DISC.read_bytes())
    scene_file = tmp_path / "scene.toml"
    scene_file.write_text(to_toml(file_scene("sub/part.msh")))
    scene = load_scene(scene_file)
    assert Path(scene.mesh.path) == (tmp_path / "sub" / "part.msh").resolve()
    assert scene.resolved["mesh"]["file"] == "part.msh"
    assert len(scene.resolved["mesh"]["sha256"]) == 64
    assert build_problem(scene).mesh.p.shape[1] == 222
    with pytest.raises(SceneError, match=r"^mesh\.file: no such file .*part\.msh"):
        parse_scene(scene_file.read_text(), base_dir=tmp_path / "elsewhere")


def test_wrong_group_name_lists_the_groups(tmp_path):
    with pytest.raises(SceneError) as err:
        build_problem(scene_from_dict(file_scene(HALF_DISC, {"boundary.contact": ["bottom"]})))
    assert str(err.value) == ("boundary.contact[0]: the mesh has no boundary group 'bottom'; "
                              "its groups are: foot, top")
    with pytest.raises(SceneError, match=r"^loads\.traction\.side: .* its groups are: foot, top"):
        build_problem(scene_from_dict(file_scene(HALF_DISC, {
            "boundary.contact": [], "loads.traction": {"side": [0, 1]}})))
    # the CLI: one line, exit 2, nothing written
    path = tmp_path / "bad.toml"
    path.write_text(to_toml(file_scene(HALF_DISC, {"boundary.dirichlet": ["lid"]})))
    result = CliRunner().invoke(main, ["solve", str(path), "--out", str(tmp_path / "out")])
    assert result.exit_code == 2
    assert result.output.strip().splitlines() == [
        "error: boundary.dirichlet[0]: the mesh has no boundary group 'lid'; its groups are: "
        "foot, top"]
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("cells, message", [
    ("quad", "cells of type 'quad'; supported are first-order triangle cells only in 2D"),
    ("triangle6", "cells of type 'triangle6'"),
    ("none", "has no 2D cells of the scene's dim = 2 (cell types found: line); in gmsh, "
             "put the surface in a physical group"),
])
def test_unsupported_cells_are_refused(tmp_path, cells, message):
    mesh = structured_mesh(MeshSpec("rectangle", (2.0, 1.0), (2, 1)))
    path = tmp_path / "m.msh"
    if cells == "quad":
        write_msh(path, mesh, ["bottom", "top"], "quad", np.array([[0, 3, 4, 1]]))
    elif cells == "triangle6":
        write_msh(path, mesh, ["bottom", "top"], "triangle6",
                  np.array([[0, 3, 4, 1, 2, 5]]))
    else:
        write_msh(path, mesh, ["bottom", "top"], "line", mesh.facets[:, :1].T)
    with pytest.raises(SceneError, match=r"^mesh\.file: .*" + message.replace("(", r"\(")
                       .replace(")", r"\)")):
        build_problem(scene_from_dict(file_scene(path, {"boundary.contact": ["bottom"]})))


def test_points_off_the_plane_are_refused_in_2d(tmp_path):
    raw = meshio.read(HALF_DISC)
    raw.points[:, 2] = 0.1 * raw.points[:, 0]
    meshio.write(tmp_path / "tilted.msh", raw, file_format="gmsh22", binary=False)
    with pytest.raises(SceneError, match=r"^mesh\.file: 'tilted\.msh' has points off the "
                                         r"plane z = 0"):
        build_problem(scene_from_dict(file_scene(tmp_path / "tilted.msh")))


def test_scene_reader_keeps_the_builtin_side_check():
    with pytest.raises(SceneError, match=r"boundary\.contact\[0\]: unknown side 'foot'; "
                                         "sides are left, right, bottom, top"):
        scene_from_dict(scene_dict({"boundary.contact": ["foot"]}))
    with pytest.raises(SceneError, match=r"^mesh\.cells: unknown key; allowed here: domain, file, "
                                         "refine"):
        scene_from_dict(file_scene(HALF_DISC, {"mesh.cells": [2, 2]}))


# ---------------------------------------------------------------- refinement


@pytest.mark.parametrize("path, dim", [(HALF_DISC, 2), (CYLINDER, 3)])
def test_refined_file_meshes_are_nested_and_keep_their_groups(path, dim):
    spec = scene_from_dict(file_scene(path, dim=dim,
                                      changes={"boundary.dirichlet": ["top"]})).mesh
    coarse, fine = build_mesh(spec), build_mesh(replace(spec, refine=1))
    P = prolongation([coarse, fine])    # raises unless fine refines coarse
    np.testing.assert_allclose(P @ coarse.p.T, fine.p.T, atol=1e-14)
    for name, facets in coarse.boundaries.items():
        assert fine.boundaries[name].size == 2 ** (dim - 1) * facets.size
        # the fine group covers the coarse one: equal measures
        assert facet_normals(fine, fine.boundaries[name])[1].sum() == pytest.approx(
            facet_normals(coarse, facets)[1].sum(), rel=1e-12)
    # no re-projection: the new foot vertices are chord midpoints, inside the circle
    foot = np.unique(fine.facets[:, fine.boundaries["foot"]])
    radius = np.hypot(fine.p[0, foot], fine.p[1, foot] - 1.0)
    assert radius.max() == pytest.approx(1.0, abs=1e-12) and radius.min() < 1.0 - 1e-4


# ---------------------------------------------------------------- curved sides


@pytest.mark.parametrize("path, dim", [(HALF_DISC, 2), (CYLINDER, 3)])
def test_nodal_normals_on_a_curved_side_are_radial(path, dim):
    """On a polygonal arc of a circle the length-weighted mean of the facet
    normals at a vertex is the radial direction up to O(h²)."""
    problem = build_problem(scene_from_dict(file_scene(path, {
        "contact.normal": law("compliance", c=1e3)}, dim=dim)))
    b = problem.boundary
    x = problem.mesh.p[:, b.nodes]
    radial = x.copy()
    radial[1] -= 1.0
    # the clamped vertices where the arc meets the top keep the normal of
    # their one facet of Γ_C
    ends = b.held.all(axis=1)
    if dim == 3:
        radial[2] = 0.0
        ends |= (np.abs(x[2]) < 1e-12) | (np.abs(x[2] - 1.0) < 1e-12)
    radial /= np.linalg.norm(radial, axis=0)
    angle = np.arccos(np.clip(np.sum(b.frame[:, :, 0].T * radial, axis=0), -1, 1))
    h = 0.14 if dim == 2 else 0.47
    assert angle[~ends].max() < 0.5 * h ** 2
    # the frames are orthonormal
    eye = np.einsum("aji,ajk->aik", b.frame, b.frame)
    np.testing.assert_allclose(eye, np.broadcast_to(np.eye(dim), eye.shape), atol=1e-14)


def test_patch_test_on_a_curved_file_mesh():
    """u* linear and zero on the clamped top: the manufactured loads (tractions
    σ* n on every other facet, with each facet's own normal) are reproduced
    exactly by P1, on a mesh with a curved side, in 2D and 3D."""
    for path, dim, u in [(HALF_DISC, 2, ["0.01*(y - 1)", "0.02*(1 - y)"]),
                         (CYLINDER, 3, ["0.01*(y - 1)", "0.02*(1 - y)", "-0.01*(y - 1)"])]:
        problem, solution = run(file_scene(path, {
            "boundary.contact": DELETE, "exact.u": [f"t*({c})" for c in u]}, dim=dim))
        p = problem.mesh.p
        exact = problem.exact.displacement(*p, t=1.0) if dim == 3 else \
            problem.exact.displacement(p[0], p[1], t=1.0)
        np.testing.assert_allclose(solution.u[-1], exact.T, rtol=0, atol=1e-13)


def test_file_rectangle_equals_the_builtin_rectangle(tmp_path):
    """The built-in rectangle's triangles written to a .msh: the same run."""
    changes = {"mesh.cells": [8, 2], "contact.normal": law("adhesive_compliance", c=1e4,
                                                            gamma=100.0, L=0.01),
               "contact.friction": [law("nonmonotone", a=2.0, b=1.0, alpha=50.0)],
               "contact.gap": "0.002 + 0.001*x",
               "contact.bonding": law("fremond", gamma_nu=100.0, gamma_tau=50.0,
                                      eps_a=0.0, L=0.01),
               "loads.body": ["100*t*x", "-300*t"], "time.steps": 3}
    builtin = scene_dict(changes)
    mesh = structured_mesh(scene_from_dict(builtin).mesh)
    write_msh(tmp_path / "rect.msh", mesh, ["bottom", "top"])
    on_file = scene_dict({**changes, "mesh": {"domain": "file", "file": "rect.msh"}})
    a = build_problem(scene_from_dict(builtin))
    b = build_problem(scene_from_dict(on_file, base_dir=tmp_path))
    assert np.array_equal(a.mesh.p, b.mesh.p) and np.array_equal(a.mesh.t, b.mesh.t)
    sa, sb = solve(a), solve(b)
    assert sa.success and sb.success
    np.testing.assert_allclose(sb.u, sa.u, rtol=0, atol=1e-12 * np.abs(sa.u).max())
    np.testing.assert_allclose(sb.beta, sa.beta, rtol=0, atol=1e-12)


# ---------------------------------------------------------------- the foundation


def test_plane_foundation_on_a_flat_side_is_a_constant_gap():
    changes = {"contact.normal": law("compliance", c=1e4), "loads.body": ["0", "-2000*t"]}
    _, a = run(scene_dict({**changes, "contact.gap": 0.003}))
    _, b = run(scene_dict({**changes, "contact.foundation": {
        "point": [0.0, -0.003], "normal": [0.0, 2.0]}}))
    assert a.success and b.success and (a.gap_violation() > -1e-12).any()
    np.testing.assert_array_equal(b.gap, a.gap)
    np.testing.assert_allclose(b.u, a.u, rtol=0, atol=1e-14)


def test_foundation_normal_and_gap_at_the_closest_point():
    """Half-disc foot over a slanted plane and over a disc: every contact
    node's frame normal is the foundation's at its closest point and the
    gap is the distance to it (node to surface), against closed forms."""
    base = {"contact.normal": law("compliance", c=1e3)}
    n = np.array([0.2, 1.0]) / np.hypot(0.2, 1.0)
    p = build_problem(scene_from_dict(file_scene(HALF_DISC, {**base, "contact.foundation": {
        "point": [0.0, -0.1], "normal": list(n)}})))
    x, nu = p.mesh.p[:, p.boundary.nodes], p.boundary.frame[:, :, 0].T
    np.testing.assert_allclose(nu, np.broadcast_to(-n[:, None], nu.shape), rtol=0, atol=1e-15)
    depth = (x - np.array([[0.0], [-0.1]])).T @ n
    np.testing.assert_allclose(p.gap.at(0.0), depth, rtol=1e-14)
    assert np.isfinite(p.gap.at(0.0)).all()
    # a disc of radius 0.5 around (0, -0.6): ν along the centre, g = |x − c| − r,
    # and x + g ν the closest point of the circle
    q = build_problem(scene_from_dict(file_scene(HALF_DISC, {**base, "contact.foundation": {
        "shape": "sphere", "point": [0.0, -0.6], "radius": 0.5}})))
    nu, g = q.boundary.frame[:, :, 0].T, q.gap.at(0.0)
    w = x - np.array([[0.0], [-0.6]])
    np.testing.assert_allclose(nu, -w / np.linalg.norm(w, axis=0), rtol=0, atol=1e-15)
    np.testing.assert_allclose(g, np.linalg.norm(w, axis=0) - 0.5, rtol=1e-14)
    y = x + g * nu
    np.testing.assert_allclose(np.hypot(y[0], y[1] + 0.6), 0.5, rtol=1e-14)
    assert g.min() == pytest.approx(0.1, abs=2e-3)


@pytest.mark.parametrize("key, vector, dim", [
    ("normal", [0.0, 5e-324], 2), ("normal", [1e-300, 1e308], 2), ("normal", [0.0, 1e-170], 2),
    ("axis", [0.0, 0.0, 5e-324], 3)])
def test_a_foundation_direction_whose_length_under_or_overflows_is_refused(key, vector, dim):
    # |v|² is 0 or inf in floating point: v/|v| removed the wall without a word
    foundation = ({"point": [0.0, -0.1], "normal": vector} if key == "normal" else
                  {"shape": "cylinder", "point": [0.0, -2.0, 0.0], "axis": vector,
                   "radius": 1.9})
    scene = file_scene(HALF_DISC if dim == 2 else CYLINDER, {
        "contact.normal": law("compliance", c=1e3), "contact.foundation": foundation},
        dim=dim)
    with pytest.raises(SceneError, match=rf"^contact\.foundation\.{key}: .* has a length "
                                         r"whose square (under|over)flows in floating "
                                         r"point; give the direction with components of "
                                         r"moderate size, e\.g\. \[0, 1\]$"):
        scene_from_dict(scene)
    # the same direction scaled to moderate size is a wall
    scale = max(abs(c) for c in vector)
    moderate = [c / scale for c in vector]
    scene["contact"]["foundation"][key] = moderate
    problem = build_problem(scene_from_dict(scene))
    assert np.isfinite(problem.gap.at(0.0)).any()


def test_cylinder_foundation_in_3d():
    p = build_problem(scene_from_dict(file_scene(CYLINDER, {
        "contact.normal": law("compliance", c=1e3), "contact.foundation": {
            "shape": "cylinder", "point": [0.0, -2.0, 0.0], "axis": [0.0, 0.0, 1.0],
            "radius": 1.9}}, dim=3)))
    x, nu, g = p.mesh.p[:, p.boundary.nodes], p.boundary.frame[:, :, 0].T, p.gap.at(0.0)
    w = x - np.array([[0.0], [-2.0], [0.0]])
    w[2] = 0.0
    np.testing.assert_allclose(g, np.linalg.norm(w, axis=0) - 1.9, rtol=1e-13)
    assert np.abs(nu[2]).max() == 0.0   # across the axis
    y = x + g * nu
    np.testing.assert_allclose(np.hypot(y[0], y[1] + 2.0), 1.9, rtol=1e-12)


def _pressed_half_disc(foundation, approach=0.01):
    """The half-disc foot, its top pushed down by ``approach``, frictionless
    Signorini contact with a foundation (two steps)."""
    return run(file_scene(HALF_DISC, {
        "boundary.dirichlet": [], "boundary.displacement": {"top": ["0", f"-{approach}*t"]},
        "contact.normal": law("none"), "contact.foundation": foundation,
        "time.steps": 2}))


def test_a_curved_body_stays_on_a_plane_foundation():
    """Node to surface: the wall bounds the displacement along the plane's
    normal, so no node of the half-disc crosses the plane y = 0 and the
    nodes on the wall lie on it (to round-off). Along the body's own normal
    the sideways displacement entered the bound and the wall nodes sank
    below the plane by up to 5 % of the approach; the penetration is
    reported against the plane itself."""
    problem, solution = _pressed_half_disc({"point": [0.0, 0.0], "normal": [0.0, 1.0]})
    assert solution.success and solution.on_wall[-1].sum() >= 3
    y = problem.mesh.p[1, problem.boundary.nodes] + solution.u[:, problem.boundary.nodes, 1]
    assert y.min() > -1e-14
    np.testing.assert_allclose(y[solution.on_wall], 0.0, atol=1e-14)
    # the wall's force is along the plane's normal: the total contact force is vertical
    total = total_contact_force(solution)[-1]
    assert total[1] > 0 and abs(total[0]) < 1e-12 * total[1]
    np.testing.assert_allclose(penetration(solution), -y.min(axis=1), rtol=0, atol=1e-15)


def test_penetration_is_measured_against_a_curved_foundation():
    """On a disc the wall is the linearisation of d_F(x + u) ≥ 0 at the
    closest point: a node on the wall sits on the tangent at its closest
    point, u_τ along it, at the distance √(r² + u_τ²) − r outside the
    (convex) disc; the reported penetration is r − |x + u − c|."""
    problem, solution = _pressed_half_disc({"shape": "sphere", "point": [0.0, -2.0],
                                            "radius": 2.0}, approach=0.05)
    assert solution.success and solution.on_wall[-1].sum() >= 3
    nodes = problem.boundary.nodes
    y = problem.mesh.p[:, nodes][None] + solution.u[:, nodes].transpose(0, 2, 1)
    depth = 2.0 - np.hypot(y[:, 0], y[:, 1] + 2.0)
    np.testing.assert_allclose(penetration(solution), depth.max(axis=1), rtol=0, atol=1e-15)
    wall = solution.on_wall[-1]
    slip = solution.frame_displacement[-1, wall, 1]
    assert np.abs(slip).max() > 1e-4
    np.testing.assert_allclose(depth[-1, wall], 2.0 - np.sqrt(4.0 + slip ** 2), rtol=1e-6,
                               atol=1e-15)


@pytest.mark.parametrize("changes, message", [
    ({"contact.gap": 0.1, "contact.foundation": {"point": [0, 0], "normal": [0, 1]}},
     "contact.foundation: give exactly one of contact.gap"),
    ({"contact.foundation": {"point": [0, 0], "normal": [0, 0]}},
     "contact.foundation.normal: must be a nonzero vector"),
    ({"contact.foundation": {"shape": "cylinder", "point": [0, 0], "radius": 1.0}},
     "contact.foundation.shape: must be one of 'plane', 'sphere'"),
    ({"contact.foundation": {"shape": "sphere", "point": [0, 0], "radius": -1.0}},
     "contact.foundation.radius: must be > 0"),
])
def test_foundation_table_is_checked(changes, message):
    with pytest.raises(SceneError, match="^" + message.replace("(", r"\(")):
        scene_from_dict(scene_dict({"contact.normal": law("compliance", c=1.0), **changes}))


def test_a_body_inside_the_foundation_is_refused():
    with pytest.raises(SceneError, match=r"^contact\.foundation: the contact node \(.*\) "
                                         "lies inside the foundation"):
        build_problem(scene_from_dict(scene_dict({
            "contact.normal": law("compliance", c=1.0),
            "contact.foundation": {"point": [0.0, 0.1], "normal": [0.0, 1.0]}})))


@pytest.mark.parametrize("path, dim", [(None, 3), (HALF_DISC, 2), (CYLINDER, 3)])
def test_fine_contact_facets_find_their_coarse_facet(path, dim):
    """Two refinements: each fine facet's centroid lies in its parent facet
    (barycentric coordinates in [0, 1] and on its plane)."""
    from adhesive_contact.verification.errors import facet_parents, nested_meshes
    if path is None:
        spec = MeshSpec("box", (1.0, 0.5, 0.5), (2, 1, 1), dim=3)
        side = "bottom"
    else:
        spec = scene_from_dict(file_scene(path, dim=dim)).mesh
        side = "foot"
    meshes = nested_meshes(spec, 2)
    coarse, fine = meshes[0], meshes[-1]
    cf, ff = coarse.boundaries[side], fine.boundaries[side]
    parents = cf[facet_parents(meshes, cf, ff)]
    centroid = fine.p[:, fine.facets[:, ff]].mean(axis=1)            # (d, n)
    corners = coarse.p[:, coarse.facets[:, parents]]                  # (d, dim, n)
    A = np.concatenate([corners, np.ones((1, dim, ff.size))]).transpose(2, 0, 1)
    b = np.concatenate([centroid, np.ones((1, ff.size))]).T[:, :, None]
    bary = np.array([np.linalg.lstsq(A[i], b[i], rcond=None)[0][:, 0] for i in range(ff.size)])
    assert bary.min() > 0 and bary.max() < 1
    recon = np.einsum("dvn,nv->dn", corners, bary)
    np.testing.assert_allclose(recon, centroid, atol=1e-13)


@pytest.mark.parametrize("spec", [
    MeshSpec(domain="rectangle", size=(2.0, 1.0), cells=(4, 3), pattern="diagonal", refine=1),
    MeshSpec(domain="rectangle", size=(2.0, 1.0), cells=(4, 3), pattern="cross"),
    MeshSpec(domain="box", size=(2.0, 1.0, 0.5), cells=(3, 2, 2))])
def test_builtin_sides_and_facets_equal_scikit_fems_own(spec):
    """The sides found on the boundary facets alone, and the facets handed
    over to the named copy, are those scikit-fem finds and builds itself."""
    from skfem import MeshTet, MeshTri

    from adhesive_contact.fem.meshes.builtin import SIDES, side_tests

    mesh = structured_mesh(spec)
    fresh = (MeshTri if mesh.dim() == 2 else MeshTet)(mesh.p, mesh.t)
    np.testing.assert_array_equal(mesh.facets, fresh.facets)
    np.testing.assert_array_equal(mesh.t2f, fresh.t2f)
    np.testing.assert_array_equal(mesh.f2t, fresh.f2t)
    own = fresh.with_boundaries(side_tests(spec.size))
    assert set(mesh.boundaries) == set(own.boundaries) == set(SIDES[mesh.dim()])
    for name, facets in own.boundaries.items():
        assert facets.size > 0
        np.testing.assert_array_equal(mesh.boundaries[name], facets)


# ---------------------------------------------------------------- mesh paths that are not files


@pytest.mark.parametrize("make, needle", [
    (lambda d: os.mkfifo(d / "m.msh") or "m.msh", "is a named pipe (FIFO), not a regular file"),
    (lambda d: "/dev/zero", "'/dev/zero' is a device, not a regular file"),
    (lambda d: (d / "m.msh").mkdir() or "m.msh", "is a folder, not a regular file"),
    (lambda d: "~nosuchuser12345/m.msh", "no such user's home folder (~nosuchuser12345)"),
    (lambda d: "m\0.msh", "mesh.file: the path holds a NUL character"),
])
def test_a_mesh_path_that_is_not_a_regular_file_is_one_line_exit_2(tmp_path, make, needle):
    # a FIFO blocked the read for ever, /dev/zero ran out of memory, the rest
    # were tracebacks; in a child, so that a hang fails the test
    scene = tmp_path / "scene.toml"
    scene.write_text(to_toml(file_scene(make(tmp_path))))
    result = subprocess.run([sys.executable, "-c", "from adhesive_contact_cli.main import "
                             "main; main()", "solve", str(scene), "--out", str(tmp_path / "o")],
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 2, result.stderr
    lines = result.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: mesh.file: ") and needle in lines[0]
    assert not (tmp_path / "o").exists()


def test_load_solution_of_a_scene_text_naming_a_fifo_is_refused(tmp_path):
    from adhesive_contact import OutputFolderError, load_solution

    (tmp_path / "m.msh").write_bytes(HALF_DISC.read_bytes())
    scene = tmp_path / "scene.toml"
    scene.write_text(to_toml(file_scene("m.msh")))
    out = tmp_path / "out"
    assert CliRunner().invoke(main, ["solve", str(scene), "--out", str(out)]).exit_code == 0
    os.mkfifo(tmp_path / "pipe.msh")
    summary = json.loads((out / "summary.json").read_text())
    summary["source"]["text"] = summary["source"]["text"].replace("m.msh", "pipe.msh")
    (out / "summary.json").write_text(json.dumps(summary))
    with pytest.raises(OutputFolderError, match="its scene cannot be built here: mesh.file: "
                       ".*pipe.msh' is a named pipe"):
        load_solution(out)


# ---------------------------------------------------------------- defective mesh files


def strip_mesh():
    from skfem import MeshTri

    mesh = MeshTri.init_tensor(np.linspace(0, 2, 5), np.linspace(0, 1, 3))
    return mesh.with_boundaries({"top": lambda x: np.isclose(x[1], 1.0),
                                 "foot": lambda x: np.isclose(x[1], 0.0)})


def write_defective(path, defect):
    """A 2 x 1 strip of 16 triangles as gmsh 2.2, with one defect."""
    mesh = strip_mesh()
    if defect == "nan":
        mesh = type(mesh)(np.where(np.arange(mesh.p.shape[1]) == 4, np.nan, mesh.p), mesh.t)
        mesh = mesh.with_boundaries({"top": lambda x: np.isclose(x[1], 1.0),
                                     "foot": lambda x: x[1] < 1e-9})
    elif defect in ("tiny", "huge"):
        scale = 1e-300 if defect == "tiny" else 1e300
        mesh = type(mesh)(mesh.p * scale, mesh.t).with_boundaries(
            {"top": lambda x: np.isclose(x[1], scale), "foot": lambda x: x[1] == 0})
    cells = None
    if defect == "collapsed":   # a sliver on the three nodes of the left side, x = 0
        cells = np.vstack([mesh.t.T, [[0, 1, 2]]])
    write_msh(path, mesh, ["top", "foot"], cells=cells)
    if defect == "empty foot":
        text = path.read_text().replace('1 2 "foot"', '1 9 "foot"')
        path.write_text(text)


@pytest.mark.parametrize("defect, needle", [
    ("nan", "has a node that is not finite: (nan, nan)"),
    ("tiny", "spans 2e-300; a mesh must span between 1e-100 and 1e+100"),
    ("huge", "spans 2e+300; a mesh must span between 1e-100 and 1e+100"),
    ("collapsed", "has 1 collapsed triangle cells (zero area), the first with corners (0, 0); "
                  "(0, 0.5); (0, 1)"),
    ("empty foot", "boundary.contact[0]: the mesh's boundary group 'foot' is empty"),
])
def test_a_defective_mesh_file_is_one_line_naming_the_file_and_the_defect(tmp_path, defect,
                                                                           needle):
    # tracebacks (SVD, a singular factor, eigh) or a run without contact
    write_defective(tmp_path / "m.msh", defect)
    scene = tmp_path / "scene.toml"
    scene.write_text(to_toml(file_scene("m.msh", {"contact.normal": law("compliance",
                                                                        c=100.0)})))
    result = CliRunner().invoke(main, ["solve", str(scene), "--out", str(tmp_path / "o")])
    lines = result.stderr.splitlines()
    assert result.exit_code == 2, result.stderr
    assert len(lines) == 1 and needle in lines[0], lines
    assert "'m.msh'" in lines[0] or "boundary." in lines[0]
    assert not (tmp_path / "o").exists()


def test_a_mesh_file_cut_short_is_one_line_without_meshios_warnings(tmp_path):
    (tmp_path / "m.msh").write_bytes((MESHES / "half_disc_v22.msh").read_bytes()[:3000])
    scene = tmp_path / "scene.toml"
    scene.write_text(to_toml(file_scene("m.msh")))
    result = subprocess.run([sys.executable, "-c", "from adhesive_contact_cli.main import "
                             "main; main()", "solve", str(scene), "--out", str(tmp_path / "o")],
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 2
    assert result.stderr.count("\n") == 1 and result.stderr.startswith(
        "error: mesh.file: cannot read 'm.msh' as a mesh: "), result.stderr


def two_strips(tmp_path):
    """Two strips of :func:`strip_mesh` side by side in one file m.msh
    (x ∈ [0, 2] and [3, 5]), their feet named "foot", the top of the first
    only named "top"; the mesh."""
    from skfem import MeshTri

    a = strip_mesh()
    both = MeshTri(np.hstack([a.p, a.p + np.array([[3.0], [0.0]])]),
                   np.hstack([a.t, a.t + a.p.shape[1]]))
    both = both.with_boundaries({"top": lambda x: np.isclose(x[1], 1.0) & (x[0] < 2.5),
                                 "foot": lambda x: np.isclose(x[1], 0.0)})
    write_msh(tmp_path / "m.msh", both, ["top", "foot"])
    return both


def test_a_part_of_the_mesh_held_by_no_side_is_refused(tmp_path):
    # two strips in one file, only the first hung from its top: a singular factor
    both = two_strips(tmp_path)
    scene = scene_from_dict(file_scene(tmp_path / "m.msh"))
    with pytest.raises(SceneError, match=r"^boundary: the part of the mesh around \(4, 0\.5\) "
                                         r"\(15 nodes, not connected to the rest\): the held "
                                         r"sides \(top\) leave the body free to move rigidly "
                                         r"\(translation along x, translation along y, "
                                         r"rotation\)"):
        build_problem(scene)
    # each strip hung from its top: both held, the problem builds
    both = both.with_boundaries({"top": lambda x: np.isclose(x[1], 1.0),
                                 "foot": lambda x: np.isclose(x[1], 0.0)})
    write_msh(tmp_path / "m.msh", both, ["top", "foot"])
    assert build_problem(scene_from_dict(file_scene(tmp_path / "m.msh"))).free.size


def test_the_contact_terms_hold_a_part_of_the_mesh_on_its_own(tmp_path):
    """Two strips in one file, only the first hung from its top, both on a
    compliant foot: the layer holds the second strip's vertical translation
    and rotation but not its slide along x, which is refused naming that
    part; with Tresca friction on the foot as well, nothing is free."""
    two_strips(tmp_path)
    layer = {"contact.normal": law("compliance", c=100.0)}
    with pytest.raises(SceneError, match=r"^boundary: the part of the mesh around \(4, 0\.5\) "
                                         r"\(15 nodes, not connected to the rest\): the held "
                                         r"sides \(top\) and the contact terms on Γ_C \(a normal "
                                         r"law\) leave the body free to move rigidly "
                                         r"\(translation along x\)"):
        build_problem(scene_from_dict(file_scene(tmp_path / "m.msh", layer)))
    held = build_problem(scene_from_dict(file_scene(
        tmp_path / "m.msh", {**layer, "contact.friction": law("tresca", mu=1.0)})))
    assert held.free.size


@pytest.mark.parametrize("content, needle", [
    (b"$", "cannot read 'm.msh' as a mesh: meshio gave up on it (meshio: "),   # SystemExit
    (b"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n", "'m.msh' has no nodes"),      # IndexError
])
def test_a_mesh_file_meshio_gives_up_on_is_one_line(tmp_path, content, needle):
    # found by tests/test_fuzz_surfaces.py: meshio called sys.exit(1), or read no nodes
    (tmp_path / "m.msh").write_bytes(content)
    with pytest.raises(SceneError) as err:
        build_problem(scene_from_dict(file_scene(tmp_path / "m.msh")))
    assert "\n" not in str(err.value) and str(err.value).startswith("mesh.file: ")
    assert needle in str(err.value), str(err.value)
