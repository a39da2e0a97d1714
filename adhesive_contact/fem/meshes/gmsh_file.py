"""Meshes read from a file: gmsh .msh (formats 2.2 and 4.1) and the other
formats meshio reads, with the file's named boundary groups.

The cells must be first-order simplices of the scene's dimension:
triangles in 2D (a z column of zeros is dropped), tetrahedra in 3D. The
boundary groups are the named groups of facet cells (lines in 2D,
triangles in 3D): gmsh's physical groups (``field_data`` with the
``gmsh:physical`` tags), or meshio's ``cell_sets`` for other formats.
Points used by no cell (gmsh's geometry points) are dropped. The mesh
comes back with ``mesh.boundaries[name]`` the scikit-fem facets of each
group.
"""

import contextlib
import io
from pathlib import Path

import numpy as np
from skfem import MeshTet, MeshTri

from .facets import facet_index, with_boundaries

#: the cell type the mesh is made of, and that of its facets, by dimension
CELL = {2: "triangle", 3: "tetra"}
FACET = {2: "line", 3: "triangle"}


class MeshFileError(ValueError):
    """A mesh file that cannot be used; ``str(err)`` is one line."""


def _topological_dim(cell_type):
    for prefix, dim in (("vertex", 0), ("line", 1), ("triangle", 2), ("quad", 2),
                        ("polygon", 2), ("tetra", 3), ("hexahedron", 3), ("wedge", 3),
                        ("pyramid", 3), ("polyhedron", 3)):
        if cell_type.startswith(prefix):
            return dim
    return -1


def _read(path):
    """meshio's mesh of ``path``; what meshio prints (its warnings go to
    stderr) is kept out of the terminal and, when the file cannot be read,
    joined into the one line of the error."""
    import meshio
    printed = io.StringIO()
    try:
        with contextlib.redirect_stdout(printed), contextlib.redirect_stderr(printed):
            return meshio.read(path)
    except (Exception, SystemExit) as err:   # meshio raises many kinds (and may exit)
        reason = (" ".join(str(err).split()) if not isinstance(err, SystemExit) else
                  "meshio gave up on it") or type(err).__name__
        said = " ".join(printed.getvalue().split())
        raise MeshFileError(f"cannot read {Path(path).name!r} as a mesh: {reason}"
                            + (f" (meshio: {said[:300]})" if said else "")) from None


def _points(raw, dim, name):
    """The points (dim, n): a 2D file's z column must be zero and is dropped."""
    p = np.asarray(raw.points, dtype=float)
    if p.ndim != 2 or not p.shape[0]:   # a file cut short may leave none
        raise MeshFileError(f"{name!r} has no nodes (is the file complete?)")
    if p.shape[1] < dim:
        raise MeshFileError(f"{name!r} has {p.shape[1]}D points, the scene has dim = {dim}")
    if p.shape[1] > dim:
        extra = np.abs(p[:, dim:]).max() if p.size else 0.0
        if extra > 1e-12 * max(1.0, np.abs(p[:, :dim]).max()):
            raise MeshFileError(f"{name!r} has points off the plane z = 0; a 2D mesh must "
                                "lie in it (or set dim = 3)")
        p = p[:, :dim]
    return p.T


def _cells(raw, dim, name):
    """The volume cells (dim+1, nt) of the file, checked."""
    top = max((_topological_dim(b.type) for b in raw.cells), default=-1)
    if top != dim:
        found = ", ".join(sorted({b.type for b in raw.cells})) or "none"
        hint = (f"; in gmsh, put the {'surface' if dim == 2 else 'volume'} in a physical "
                "group (only grouped cells are saved)" if top < dim else "")
        raise MeshFileError(f"{name!r} has no {dim}D cells of the scene's dim = {dim} "
                            f"(cell types found: {found}){hint}")
    blocks = [b for b in raw.cells if _topological_dim(b.type) == dim]
    bad = sorted({b.type for b in blocks if b.type != CELL[dim]})
    if bad:
        raise MeshFileError(f"{name!r} has cells of type {bad[0]!r}; supported are "
                            f"first-order {CELL[dim]} cells only in {dim}D "
                            "(no quadrilaterals/hexahedra, no second order)")
    return np.concatenate([b.data for b in blocks]).T.astype(np.int64)


def _facet_groups(raw, dim):
    """{name: facet vertex indices (dim, n)} of the named groups of facet cells."""
    groups = {}
    physical = raw.cell_data.get("gmsh:physical")
    if raw.field_data and physical is not None:
        for name, (tag, gdim) in ((n, v[:2]) for n, v in raw.field_data.items()):
            if int(gdim) != dim - 1:
                continue
            parts = [b.data[tags == tag] for b, tags in zip(raw.cells, physical)
                     if b.type == FACET[dim]]
            groups[name] = np.concatenate(parts).T if parts else np.zeros((dim, 0), int)
    else:
        for name, per_block in raw.cell_sets.items():
            if name.startswith("gmsh:"):
                continue
            parts = [b.data[np.asarray(ix, dtype=np.int64)]
                     for b, ix in zip(raw.cells, per_block) if b.type == FACET[dim]]
            if parts and sum(p.shape[0] for p in parts):
                groups[name] = np.concatenate(parts).T
    return groups


#: the extent of a mesh (its bounding box's largest side): cell measures are
#: products of d coordinates, which under- or overflow beyond these
MIN_EXTENT, MAX_EXTENT = 1e-100, 1e100
#: a cell whose measure is below this fraction of h^d (h its longest edge) is
#: collapsed: its stiffness is singular
COLLAPSED = 1e-12


def _check_geometry(name, points, cells, local):
    """The nodes used by cells finite, the mesh's extent between MIN_EXTENT
    and MAX_EXTENT, no collapsed cell (``local``: ``cells`` numbered into
    ``points``)."""
    bad = ~np.isfinite(points).all(axis=0)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise MeshFileError(f"{name!r} has a node that is not finite: "
                            f"({', '.join(f'{c:g}' for c in points[:, i])})")
    extent = float(np.ptp(points, axis=1).max()) if points.size else 0.0
    if not MIN_EXTENT <= extent <= MAX_EXTENT:
        raise MeshFileError(f"{name!r} spans {extent:g}; a mesh must span between "
                            f"{MIN_EXTENT:g} and {MAX_EXTENT:g} (its cells' areas and "
                            "volumes would under- or overflow): scale its coordinates")
    x = points[:, local]                       # (d, d+1, nt)
    edges = x[:, 1:, :] - x[:, :1, :]          # (d, d, nt)
    measure = np.abs(np.linalg.det(np.moveaxis(edges, -1, 0)))   # d! |cell|
    longest = np.zeros(local.shape[1])
    for a in range(local.shape[0]):
        for b in range(a + 1, local.shape[0]):
            longest = np.maximum(longest, np.linalg.norm(x[:, a] - x[:, b], axis=0))
    collapsed = measure <= COLLAPSED * longest ** points.shape[0]
    if collapsed.any():
        c = int(np.flatnonzero(collapsed)[0])
        corners = "; ".join("(" + ", ".join(f"{v:.6g}" for v in x[:, a, c]) + ")"
                            for a in range(local.shape[0]))
        what = "area" if points.shape[0] == 2 else "volume"
        raise MeshFileError(f"{name!r} has {int(collapsed.sum())} collapsed "
                            f"{CELL[points.shape[0]]} cells (zero {what}), the first with "
                            f"corners {corners}")


def read_mesh_file(path, dim):
    """The scikit-fem mesh of a mesh file, its boundary groups named.

    Parameters
    ----------
    path : path of the file
    dim : 2 or 3, the scene's dimension

    Returns
    -------
    MeshTri or MeshTet with ``boundaries`` {group name: facet indices}

    Raises
    ------
    MeshFileError
        An unreadable file, cells of another kind or dimension, a 2D mesh
        off z = 0, or a group whose cells are not facets of the mesh.
    """
    name = Path(path).name
    raw = _read(path)
    p = _points(raw, dim, name)
    t = _cells(raw, dim, name)
    if t.size and (t.min() < 0 or t.max() >= p.shape[1]):
        raise MeshFileError(f"{name!r} has cells with node numbers outside its "
                            f"{p.shape[1]} nodes")
    groups = _facet_groups(raw, dim)
    used = np.unique(t)
    _check_geometry(name, p[:, used], t, np.searchsorted(used, t))
    renumber = np.full(p.shape[1], -1)
    renumber[used] = np.arange(used.size)
    # C-ordered arrays: scikit-fem copies others and says so on stderr
    mesh = (MeshTri if dim == 2 else MeshTet)(np.ascontiguousarray(p[:, used]),
                                              np.ascontiguousarray(renumber[t]))
    boundaries = {}
    for group, nodes in groups.items():
        index = facet_index(mesh, renumber[nodes]) if nodes.size else np.zeros(0, int)
        if np.any(index < 0):
            raise MeshFileError(f"{name!r}: group {group!r} has {FACET[dim]} cells that are "
                                "not facets of the mesh")
        boundaries[group] = np.unique(index)
    return with_boundaries(mesh, boundaries) if boundaries else mesh
