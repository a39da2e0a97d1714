"""Mesh sources behind one function: :func:`build_mesh`.

- ``domain = "rectangle"`` / ``"box"``: structured meshes with the sides
  left/right/bottom/top(/front/back) (:mod:`.builtin`);
- ``domain = "file"``: a gmsh or other meshio-readable file, its named
  boundary groups as sides (:mod:`.gmsh_file`).

``refine`` uniform refinements follow; the meshes of one scene at
different ``refine`` are nested (coarse vertices first, one new vertex per
coarse edge), and named sides follow the refinement (:mod:`.facets`).
"""

from pathlib import Path

import numpy as np

from ...errors import SceneError
from .builtin import side_tests, structured_mesh
from .facets import facet_index, refined_with_boundaries, refinement_parents
from .gmsh_file import MeshFileError, read_mesh_file

__all__ = ["build_mesh", "mesh_size", "named_facets", "side_tests", "facet_index",
           "refinement_parents", "read_mesh_file"]


def build_mesh(spec, base_dir=None):
    """The mesh of a :class:`~adhesive_contact.scene.MeshSpec`, sides named.

    A relative ``spec.path`` is taken relative to ``base_dir`` (default:
    the working directory). A file that cannot be used raises
    :class:`~adhesive_contact.scene.SceneError` on ``mesh.file``."""
    if spec.domain != "file":
        return structured_mesh(spec)
    path = Path(spec.path)
    if base_dir is not None and not path.is_absolute():
        path = Path(base_dir) / path
    try:
        mesh = read_mesh_file(path, spec.dim)
    except MeshFileError as err:
        raise SceneError("mesh.file", str(err)) from None
    return refined_with_boundaries(mesh, spec.refine)


def named_facets(mesh, names, key, indexed=True):
    """The boundary facets of the named sides ``names`` (concatenated).

    Raises :class:`~adhesive_contact.scene.SceneError` on ``key[i]`` (on
    ``key.name`` when not ``indexed``; one line listing the mesh's boundary
    names) for a name the mesh does not have, or a group that is not on
    the boundary."""
    groups = mesh.boundaries or {}
    boundary = np.zeros(mesh.facets.shape[1], dtype=bool)
    boundary[mesh.boundary_facets()] = True
    out = []
    for i, name in enumerate(names):
        where = f"{key}[{i}]" if indexed else f"{key}.{name}"
        if name not in groups:
            have = ", ".join(sorted(groups)) or "none"
            raise SceneError(where, f"the mesh has no boundary group {name!r}; its groups "
                             f"are: {have}")
        if not len(groups[name]):   # a side that would silently hold or touch nothing
            raise SceneError(where, f"the mesh's boundary group {name!r} is empty (no "
                             "facets); in gmsh, put the side's curves (surfaces in 3D) in it")
        if not boundary[groups[name]].all():
            raise SceneError(where, f"group {name!r} has facets inside the body; a side "
                             "must lie on the boundary")
        out.append(groups[name])
    return np.concatenate(out) if out else np.zeros(0, dtype=np.int64)


def mesh_size(mesh):
    """The largest edge length h of the mesh."""
    edges = mesh.facets if mesh.dim() == 2 else mesh.edges
    p = mesh.p[:, edges]
    return float(np.max(np.linalg.norm(p[:, 1] - p[:, 0], axis=0)))
