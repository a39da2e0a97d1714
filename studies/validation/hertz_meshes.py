"""Graded triangle meshes for the 2D Hertz studies, written with numpy,
scipy's Delaunay and meshio (no gmsh needed).

    python studies/validation/hertz_meshes.py

Both bodies are the half x ≥ 0 of a symmetric problem (the side ``axis``,
x = 0, is held in x), graded from the first point of contact, the origin:
the element size is h_c within r_c = 0.15 of it and grows by 20 % of the
distance beyond (h(r) = h_c + 0.2 (r − r_c), at most h_max).

- ``disc_L.msh``: the quarter of the disc of radius 1 around (0, 1) with
  x ≥ 0, y ≤ 1; sides ``foot`` (the arc, its vertices on the circle),
  ``axis`` (x = 0) and ``top`` (y = 1).
- ``block_L.msh``: the rectangle [0, 4] × [−4, 0]; sides ``top`` (y = 0),
  ``axis`` (x = 0), ``bottom`` (y = −4) and ``right`` (x = 4).

L = 0..3 is h_c = 0.005 / 2^L. Within r_c the points are a lattice of
equilateral triangles whose rows follow the contact surface (straight rows
under the block's top, arcs concentric with the disc): row j at the depth
j h_c √3/2, its points h_c apart along the row and shifted by h_c/2 on odd
rows, the surface itself row 0 and the axis sampled at the rows' depths, so
the mesh under the contact is the same around every node and symmetric
about x = 0. (On the rings of an unstructured mesh the nodal contact forces
scatter by ±0.4 % from node to node, which the pressure at one node, the
peak p0, shows in full.) Beyond r_c the points are rings around the origin
(spacing h(r) along and across them), the boundaries sampled with the same
h, and the triangulation is the Delaunay one, with ghost points outside
the body so that every boundary edge is in it (each boundary edge's
diametral disc is checked empty), cut back to the body.
"""

from pathlib import Path

import meshio
import numpy as np
from scipy.spatial import Delaunay

HERE = Path(__file__).parent / "meshes"
R_CORE, GROWTH = 0.15, 0.2
LEVELS = {0: 0.005, 1: 0.0025, 2: 0.00125, 3: 0.000625}


def size(points, h_c, h_max):
    """h(x) (n,) at points (2, n): graded with the distance to the origin."""
    r = np.hypot(points[0], points[1])
    return np.minimum(h_c + GROWTH * np.maximum(r - R_CORE, 0.0), h_max)


def sample(curve, length, h_c, h_max, start=()):
    """Points (2, n) along a curve s -> x(s) of the given length (s in
    [0, length]), spaced by h at each point, both ends included; the
    parameters ``start`` (increasing, from 0) are kept exactly, the rest
    spaced from the last of them."""
    fixed = list(start) or [0.0]
    s = [fixed[-1]]
    while s[-1] < length:
        s.append(s[-1] + size(curve(np.array([s[-1]])), h_c, h_max)[0])
    s = np.array(s)
    s = s[0] + (s - s[0]) * (length - s[0]) / (s[-1] - s[0])   # end exactly at the end
    s = np.concatenate([fixed[:-1], s])
    if len(s) > 2 and s[-1] - s[-2] < 0.5 * (s[-2] - s[-3]):
        s = np.delete(s, -2)
    return curve(s)


def rings(h_c, h_max, r_max):
    """Points (2, n) on circles around the origin, spaced h along and across."""
    out, r, k = [np.zeros((2, 1))], 0.0, 0
    while r < r_max:
        r += size(np.array([[r], [0.0]]), h_c, h_max)[0]
        n = max(int(np.ceil(2 * np.pi * r / size(np.array([[r], [0.0]]), h_c, h_max)[0])), 6)
        angle = (np.arange(n) + 0.5 * (k % 2)) * 2 * np.pi / n
        out.append(r * np.array([np.cos(angle), np.sin(angle)]))
        k += 1
    return np.hstack(out)


def lattice_rows(h_c):
    """The core's lattice in row coordinates: (depth j h_c √3/2, offset
    (i + (j mod 2)/2) h_c along the row) for j ≥ 1 and offsets > 0 up to
    r_c + h_c, as two arrays (n,), and the row depths (m,) for j ≥ 1."""
    depths = np.arange(1, int(R_CORE / (h_c * np.sqrt(3) / 2)) + 1) * h_c * np.sqrt(3) / 2
    d, t = [], []
    for j, depth in enumerate(depths, start=1):
        along = (np.arange(0, int((R_CORE + h_c) / h_c) + 1) + 0.5 * (j % 2)) * h_c
        along = along[along > 0]
        d.append(np.full(along.size, depth))
        t.append(along)
    return np.concatenate(d), np.concatenate(t), depths


def rings_outside_core(h_c, h_max, r_max):
    """The rings of :func:`rings` beyond the core (r > r_c + 0.7 h_c)."""
    p = rings(h_c, h_max, r_max)
    return p[:, np.hypot(p[0], p[1]) > R_CORE + 0.7 * h_c]


def triangulate(boundary, normals, interior, distance, h_c, h_max, core=None):
    """The Delaunay triangulation of the boundary points (2, nb) (with their
    outward normals), the core's lattice points ``core`` (2, nc) within r_c
    of the origin, all kept, and the interior points at least 0.6 h from the
    boundary (``distance`` (n,) of points (2, n) to it, negative outside),
    cut back to the body: (points (2, n), triangles (3, nt))."""
    h_b = size(boundary, h_c, h_max)
    keep = distance(interior) > 0.6 * size(interior, h_c, h_max)
    points = np.hstack([boundary, interior[:, keep]])
    if core is not None:
        core = core[:, (np.hypot(core[0], core[1]) <= R_CORE) & (distance(core) > 0)]
        points = np.hstack([points, core])
    ghosts = boundary + 0.8 * h_b * normals
    tri = Delaunay(np.hstack([points, ghosts]).T).simplices.T
    tri = tri[:, (tri < points.shape[1]).all(axis=0)]
    x = points[:, tri]
    area = 0.5 * ((x[0, 1] - x[0, 0]) * (x[1, 2] - x[1, 0])
                  - (x[0, 2] - x[0, 0]) * (x[1, 1] - x[1, 0]))
    centroid = x.mean(axis=1)
    tri = tri[:, (area > 1e-3 * size(centroid, h_c, h_max) ** 2)
              & (distance(centroid) > 0)]
    x = points[:, tri]
    area = 0.5 * ((x[0, 1] - x[0, 0]) * (x[1, 2] - x[1, 0])
                  - (x[0, 2] - x[0, 0]) * (x[1, 1] - x[1, 0]))
    tri[1:, area < 0] = tri[2:0:-1, area < 0]   # counterclockwise
    return points, tri


def edges_of(points, tri, on_side):
    """The boundary edges (2, m) of the triangulation whose two vertices are
    on a side (``on_side`` (n,) bool)."""
    e = np.sort(np.hstack([tri[[0, 1]], tri[[1, 2]], tri[[2, 0]]]), axis=0)
    unique, count = np.unique(e, axis=1, return_counts=True)
    boundary = unique[:, count == 1]
    return boundary[:, on_side[boundary].all(axis=0)]


def write(path, points, tri, sides):
    """A gmsh 2.2 file with the named sides {name: edges (2, m)}."""
    blocks = [("line", e.T) for e in sides.values()] + [("triangle", tri.T)]
    tags = [np.full(len(b[1]), i + 1) for i, b in enumerate(blocks)]
    field = {name: np.array([i + 1, 1]) for i, name in enumerate(sides)}
    field["body"] = np.array([len(sides) + 1, 2])
    meshio.write(path, meshio.Mesh(np.column_stack([points.T, np.zeros(points.shape[1])]),
                                   blocks, cell_data={"gmsh:physical": tags,
                                                      "gmsh:geometrical": tags},
                                   field_data=field), file_format="gmsh22", binary=False)


def check_boundary_edges(points, tri, sides, total_edges):
    """Every boundary edge of the triangulation is on a named side."""
    named = sum(e.shape[1] for e in sides.values())
    assert named == total_edges, f"{total_edges - named} boundary edges on no side"


def boundary_edge_count(tri):
    e = np.sort(np.hstack([tri[[0, 1]], tri[[1, 2]], tri[[2, 0]]]), axis=0)
    _, count = np.unique(e, axis=1, return_counts=True)
    return int((count == 1).sum())


def disc(h_c, h_max=0.1):
    """The quarter disc x ≥ 0, |x − (0, 1)| ≤ 1, y ≤ 1."""
    n_core = int(R_CORE / h_c) + 1
    arc = sample(lambda s: np.array([np.sin(s), 1.0 - np.cos(s)]), np.pi / 2, h_c, h_max,
                 start=np.arange(n_core + 1) * h_c)
    depth, along, depths = lattice_rows(h_c)
    axis = sample(lambda s: np.array([0.0 * s, s]), 1.0, h_c, h_max,
                  start=np.concatenate([[0.0], depths]))
    rho = 1.0 - depth                              # rows concentric with the arc
    core = np.array([rho * np.sin(along / rho), 1.0 - rho * np.cos(along / rho)])
    top = sample(lambda s: np.array([1.0 - s, 1.0 + 0.0 * s]), 1.0, h_c, h_max)
    boundary = np.hstack([arc, top[:, 1:], axis[:, 1:-1]])
    n_arc, n_top = arc.shape[1], top.shape[1] - 1
    normals = np.zeros_like(boundary)
    normals[:, :n_arc] = arc - np.array([[0.0], [1.0]])
    normals[1, n_arc:n_arc + n_top] = 1.0
    normals[0, n_arc + n_top:] = -1.0
    normals /= np.linalg.norm(normals, axis=0)

    def distance(x):
        return np.minimum.reduce([x[0], 1.0 - x[1], 1.0 - np.hypot(x[0], x[1] - 1.0)])

    points, tri = triangulate(boundary, normals, rings_outside_core(h_c, h_max, 2.2), distance,
                              h_c, h_max, core)
    p = points
    tol = 1e-12
    sides = {"foot": edges_of(p, tri, np.abs(np.hypot(p[0], p[1] - 1.0) - 1.0) < 1e-9),
             "axis": edges_of(p, tri, np.abs(p[0]) < tol),
             "top": edges_of(p, tri, np.abs(p[1] - 1.0) < tol)}
    check_boundary_edges(p, tri, sides, boundary_edge_count(tri))
    return points, tri, sides


def block(h_c, width=4.0, h_max=0.25):
    """The rectangle [0, width] × [−width, 0]."""
    W = width
    n_core = int(R_CORE / h_c) + 1
    top = sample(lambda s: np.array([s, 0.0 * s]), W, h_c, h_max,
                 start=np.arange(n_core + 1) * h_c)
    depth, along, depths = lattice_rows(h_c)
    core = np.array([along, -depth])
    right = sample(lambda s: np.array([W + 0.0 * s, -s]), W, h_c, h_max)
    bottom = sample(lambda s: np.array([W - s, -W + 0.0 * s]), W, h_c, h_max)
    axis = sample(lambda s: np.array([0.0 * s, -s]), W, h_c, h_max,
                  start=np.concatenate([[0.0], depths]))[:, ::-1]   # from the bottom up
    parts = [top, right[:, 1:], bottom[:, 1:], axis[:, 1:-1]]
    outward = [(0.0, 1.0), (1.0, 0.0), (0.0, -1.0), (-1.0, 0.0)]
    boundary = np.hstack(parts)
    normals = np.hstack([np.repeat(np.array(n)[:, None], q.shape[1], axis=1)
                         for n, q in zip(outward, parts)])
    corners = np.isclose(np.abs(boundary[0] - W / 2), W / 2) & \
        np.isclose(np.abs(boundary[1] + W / 2), W / 2)
    normals[:, corners] = np.sign(boundary[:, corners] - np.array([[W / 2], [-W / 2]]))
    normals /= np.linalg.norm(normals, axis=0)

    def distance(x):
        return np.minimum.reduce([x[0], W - x[0], -x[1], W + x[1]])

    points, tri = triangulate(boundary, normals, rings_outside_core(h_c, h_max, 1.5 * W),
                              distance, h_c, h_max, core)
    p, tol = points, 1e-12
    sides = {"top": edges_of(p, tri, np.abs(p[1]) < tol),
             "axis": edges_of(p, tri, np.abs(p[0]) < tol),
             "bottom": edges_of(p, tri, np.abs(p[1] + W) < tol),
             "right": edges_of(p, tri, np.abs(p[0] - W) < tol)}
    check_boundary_edges(p, tri, sides, boundary_edge_count(tri))
    return points, tri, sides


def quality(points, tri):
    """The smallest angle of the triangles, in degrees."""
    x = points[:, tri]
    angles = []
    for i in range(3):
        a, b, c = x[:, i], x[:, (i + 1) % 3], x[:, (i + 2) % 3]
        u, v = b - a, c - a
        angles.append(np.degrees(np.arccos(np.clip(np.sum(u * v, axis=0) / (
            np.linalg.norm(u, axis=0) * np.linalg.norm(v, axis=0)), -1, 1))))
    return float(np.min(angles))


def main():
    HERE.mkdir(exist_ok=True)
    for level, h_c in LEVELS.items():
        for name, make in (("disc", disc), ("block", block)):
            points, tri, sides = make(h_c)
            write(HERE / f"{name}_{level}.msh", points, tri, sides)
            print(f"{name}_{level}.msh: h_c = {h_c:g}, {points.shape[1]} nodes, "
                  f"{tri.shape[1]} triangles, smallest angle {quality(points, tri):.1f}°, "
                  + ", ".join(f"{s} {e.shape[1]}" for s, e in sides.items()))


if __name__ == "__main__":
    main()
