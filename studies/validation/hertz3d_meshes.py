"""Graded tetrahedral meshes for the 3D Hertz study, written with
scikit-fem and meshio (no gmsh needed).

    python studies/validation/hertz3d_meshes.py

The quarter x ≥ 0, y ≥ 0 of the block [−1, 1]² × [−1, 0], its top z = 0
pressed by a rigid sphere at the origin: a tensor grid of cubes of side
h_c within the core [0, c]² × [−c, 0], c = 0.11, whose spacing grows by
30 % a cell beyond, each cube cut into 24 tetrahedra around its face
centres and its centre, a split with the cube's symmetries, so that the
mesh is its own mirror image in the symmetry planes (:func:`cube_split`). Sides: ``top`` (z = 0), ``xsym`` (x = 0),
``ysym`` (y = 0), ``bottom`` (z = −1), ``xside`` (x = 1), ``yside``
(y = 1). L = 0, 1 is h_c = 0.01, 0.0075 (about 220 000 and 280 000 dofs);
``sphere_test`` (h_c = 0.02) is the test's; ``sphere_coarse`` (h_c = 0.05,
3 000 nodes) is committed, the mesh hertz3d_sphere.toml names, so that the
scene runs as it is. Binary gmsh 2.2 files.
"""

from pathlib import Path

import meshio
import numpy as np
from skfem import MeshTet

HERE = Path(__file__).parent / "meshes"
CORE, GROWTH, WIDTH = 0.11, 1.3, 1.0
LEVELS = {"coarse": 0.05, "test": 0.02, 0: 0.01, 1: 0.0075}


def graded(h_c, core=CORE, length=WIDTH, growth=GROWTH):
    """0 = s_0 < s_1 < ... = length: h_c apart up to ``core``, then each
    step ``growth`` times the last (the last one merged when short)."""
    s = list(np.arange(0.0, core + 0.5 * h_c, h_c))
    h = h_c
    while s[-1] < length:
        h *= growth
        s.append(s[-1] + h)
    s = np.array(s)
    if s[-1] - length > 0.5 * h:
        s = s[:-1]
    s[-1] = length
    return s


SIDES = {"top": (2, 0.0), "xsym": (0, 0.0), "ysym": (1, 0.0), "bottom": (2, -WIDTH),
         "xside": (0, WIDTH), "yside": (1, WIDTH)}


def cube_split(x, y, z):
    """The tetrahedra of the tensor grid x × y × z, each cell cut into 24:
    every face into four triangles around its centre, each joined to the
    cell's centre. The split has all the symmetries of the cube, so the mesh
    is the same around every cell and its own mirror image in every grid
    plane (x = 0 and y = 0 among them: the quarter model is the symmetric
    whole)."""
    grids = [np.asarray(a, dtype=float) for a in (x, y, z)]
    n = np.array([a.size for a in grids])
    mids = [0.5 * (a[1:] + a[:-1]) for a in grids]
    blocks, offset = [], 0

    def add(axes):                    # points on the grid of these 1D arrays
        nonlocal offset
        shape = tuple(a.size for a in axes)
        P = np.stack([g.ravel() for g in np.meshgrid(*axes, indexing="ij")])
        index = offset + np.arange(P.shape[1]).reshape(shape)
        blocks.append(P)
        offset += P.shape[1]
        return index

    corner = add(grids)
    face = [add([mids[a] if a != axis else grids[a] for a in range(3)]) for axis in range(3)]
    centre = add(mids)
    i, j, k = (a.ravel() for a in np.meshgrid(*(np.arange(m - 1) for m in n), indexing="ij"))
    c = centre[i, j, k]
    tets = []
    for axis in range(3):
        u, v = [a for a in range(3) if a != axis]
        for side in (0, 1):
            base = [i, j, k]
            base[axis] = base[axis] + side
            f = face[axis][tuple(base[a] if a == axis else (i, j, k)[a] for a in range(3))]
            loop = ((0, 0), (1, 0), (1, 1), (0, 1), (0, 0))
            for (a0, b0), (a1, b1) in zip(loop[:-1], loop[1:]):
                def vertex(da, db):
                    d = list(base)
                    d[u] = d[u] + da
                    d[v] = d[v] + db
                    return corner[d[0], d[1], d[2]]
                tets.append(np.stack([vertex(a0, b0), vertex(a1, b1), f, c]))
    t = np.hstack(tets)
    p = np.hstack(blocks)
    w = p[:, t]                                              # positive orientation
    volume = np.einsum("ij,ij->j", np.cross((w[:, 1] - w[:, 0]).T, (w[:, 2] - w[:, 0]).T).T,
                       w[:, 3] - w[:, 0])
    t[[0, 1]] = np.where(volume < 0, t[[1, 0]], t[[0, 1]])
    return MeshTet(p, t)


def block(h_c):
    """The quarter block (MeshTet) and its named sides {name: triangles (3, m)}."""
    s = graded(h_c)
    mesh = cube_split(s, s, -s[::-1])
    boundary = mesh.boundary_facets()
    mid = mesh.p[:, mesh.facets[:, boundary]].mean(axis=1)
    sides = {name: mesh.facets[:, boundary[np.abs(mid[axis] - value) < 1e-9]]
             for name, (axis, value) in SIDES.items()}
    assert sum(f.shape[1] for f in sides.values()) == boundary.size
    return mesh, sides


def write(path, mesh, sides):
    """A binary gmsh 2.2 file with the named sides."""
    blocks = [("triangle", f.T) for f in sides.values()] + [("tetra", mesh.t.T)]
    tags = [np.full(len(b[1]), i + 1) for i, b in enumerate(blocks)]
    field = {name: np.array([i + 1, 2]) for i, name in enumerate(sides)}
    field["body"] = np.array([len(sides) + 1, 3])
    meshio.write(path, meshio.Mesh(mesh.p.T, blocks,
                                   cell_data={"gmsh:physical": tags, "gmsh:geometrical": tags},
                                   field_data=field), file_format="gmsh22", binary=True)


def main(levels=("coarse", 0, 1), folder=HERE):
    folder.mkdir(exist_ok=True)
    for level in levels:
        mesh, sides = block(LEVELS[level])
        write(folder / f"sphere_{level}.msh", mesh, sides)
        print(f"sphere_{level}.msh: h_c = {LEVELS[level]:g}, {mesh.p.shape[1]} nodes, "
              f"{mesh.t.shape[1]} tetrahedra, top {sides['top'].shape[1]} triangles")


if __name__ == "__main__":
    main()
