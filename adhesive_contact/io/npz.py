"""``solution.npz``, written entry by entry into a zip, as
:func:`numpy.savez_compressed` would write it, but with the history u
(N+1, npoints, d) streamed level by level from wherever it is kept, and
stored uncompressed: a history of floating-point displacements shrinks by
about 7 % under zlib (the 2D strip at 1e5 dofs, 51 levels: 42.4 → 39.4 MB),
for 1.0–1.2 s of compression, a sixth of the whole run. The other entries
are compressed (booleans and β shrink 4–100 fold). :func:`numpy.load`
reads both.

Keys (docs/outputs.md): ``points``, ``cells``, ``contact_facets``, ``t``,
``u`` (the displacement at the levels ``u_levels``: every level, or the
field levels of ``[output] every``; none when ``[output] fields`` leaves
u out), ``u_levels``, ``beta``, ``reactions`` (N+1, n_sides, d): the force of each held
side's support on the body, ``reaction_sides``: their names;
``contact_nodes`` (nc,): the mesh indices of the contact nodes (the
vertices of Γ_C in increasing index, the order of every per-node array),
``contact_points`` (nc, d) their coordinates and ``contact_pressure``
(N+1, nc) the normal traction −σ_ν there (positive in compression); and the rest
of a :class:`~adhesive_contact.Solution` (:data:`SOLUTION_KEYS`), so that
:func:`~adhesive_contact.io.load_solution` gives it back: ``contact_force``,
``frame_displacement``, ``on_wall``, ``stuck``, ``probes``, ``iterations``,
``residual``, ``held_reaction`` (the reaction per held dof), and the stress
of the last level, ``stress_last`` (ncells, d, d) and, in 2D,
``stress_zz_last`` (ncells,); the scalars of every level (the columns of
``scalars.csv`` without units): ``scalar_names``, ``scalar_kinds`` and
``scalar_values`` (N+1, ncolumns).
"""

import time
import zipfile

import numpy as np

from ..postprocess.level_scalars import level_scalars
from ..postprocess.quantities import normal_traction
from ..postprocess.reactions import reaction_sides, reactions
from .xdmf import contact_facets


def _write_array(archive, name, array):
    with archive.open(f"{name}.npy", "w", force_zip64=True) as f:
        np.lib.format.write_array(f, np.asanyarray(array), allow_pickle=False)


def _write_levels(archive, name, levels, indices, shape):
    """An (len(indices), *shape) array whose i-th entry is
    ``levels[indices[i]]``, one level at a time, stored uncompressed (see
    the module doc)."""
    shape = (len(indices), *shape)
    entry = zipfile.ZipInfo(f"{name}.npy", date_time=time.localtime()[:6])
    entry.compress_type = zipfile.ZIP_STORED
    with archive.open(entry, "w", force_zip64=True) as f:
        np.lib.format.write_array_header_2_0(
            f, {"descr": np.lib.format.dtype_to_descr(np.dtype(float)),
                "fortran_order": False, "shape": shape})
        for n in indices:
            f.write(np.ascontiguousarray(levels[int(n)], dtype=float).tobytes())


#: the Solution's per-level arrays kept under their own names; held_reaction
#: is Solution.reaction
SOLUTION_KEYS = ("contact_force", "frame_displacement", "on_wall", "stuck", "probes",
                 "iterations", "residual")


def write_npz(solution, path, field_levels=None, columns=None):
    """Write ``solution.npz`` of a solution (its u may be kept on disk, see
    :class:`~adhesive_contact.io.StreamingRecorder`): u at ``field_levels``
    (default: every level) when the problem's ``output.fields`` has it, and
    the scalars of every level (``columns``, the run's
    :func:`~adhesive_contact.postprocess.level_scalars.level_scalars` if
    not given)."""
    problem = solution.problem
    columns = level_scalars(solution) if columns is None else columns
    if field_levels is None:
        field_levels = np.arange(solution.t.size)
    if problem.output is not None and not problem.output.writes("u"):
        field_levels = np.zeros(0, dtype=np.int64)
    field_levels = np.asarray(field_levels, dtype=np.int64)
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED) as archive:
        _write_array(archive, "points", problem.mesh.p.T)
        _write_array(archive, "cells", problem.mesh.t.T.astype(np.int64))
        _write_array(archive, "contact_facets", contact_facets(problem))
        _write_array(archive, "t", solution.t)
        _write_levels(archive, "u", solution.u, field_levels, problem.mesh.p.T.shape)
        _write_array(archive, "u_levels", field_levels)
        _write_array(archive, "beta", solution.beta)
        _write_array(archive, "reactions", reactions(solution))
        _write_array(archive, "reaction_sides", np.array(reaction_sides(problem), dtype=str))
        nodes = (problem.boundary.nodes if problem.boundary is not None
                 else np.zeros(0, dtype=np.int64))
        _write_array(archive, "contact_nodes", nodes.astype(np.int64))
        _write_array(archive, "contact_points", problem.mesh.p[:, nodes].T)
        _write_array(archive, "contact_pressure",
                     normal_traction(solution) if nodes.size else np.zeros((solution.t.size, 0)))
        for name in SOLUTION_KEYS:
            _write_array(archive, name, getattr(solution, name))
        held = solution.reaction if solution.reaction is not None else \
            np.zeros((solution.t.size, 0))
        _write_array(archive, "held_reaction", held)
        _write_array(archive, "scalar_names", np.array([c.name for c in columns], dtype=str))
        _write_array(archive, "scalar_kinds", np.array([c.kind for c in columns], dtype=str))
        _write_array(archive, "scalar_values",
                     np.column_stack([np.asarray(c.values, dtype=float) for c in columns])
                     if columns else np.zeros((solution.t.size, 0)))
        _write_array(archive, "stress_last", solution.stress[-1])
        if solution.stress_zz is not None:
            _write_array(archive, "stress_zz_last", solution.stress_zz[-1])
