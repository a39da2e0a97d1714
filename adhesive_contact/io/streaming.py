"""A recorder that streams the levels of a run to its files.

:class:`StreamingRecorder` writes u_n of every level to a scratch HDF5
file as soon as it is computed, and the fields of the field levels
(``[output] every`` and ``fields``, :mod:`.field_levels`) to the XDMF time
series (:class:`~adhesive_contact.io.xdmf.XdmfSeries`): a level of the
grid at once, a candidate peak when the run ends (it is kept in memory
until a later level passes its peak; at most one level per reported
force). In memory it keeps per level only what is
small: β per contact facet, the contact force, frame displacement and
states per contact node, the probes, the reactions per held dof, the
iterations and residual; and the
last level's u and σ. The Solution it builds reads u_n from the scratch
file (:class:`DiskLevels`) and holds σ of the last level only; its
field levels are :meth:`StreamingRecorder.field_levels`.

The memory of a run is then flat in the number of steps N, up to the
O(N·n_Γ) contact history, and the memory kernel: a Prony series keeps
O(1) levels of u, a general kernel r(t) all of them (its history sum
needs every u_j).
"""

from pathlib import Path

import numpy as np

from ..scheme.options import OutputOptions
from .field_levels import FieldLevels, reported_forces
from .h5 import H5File
from .xdmf import XdmfSeries

#: kept per level in memory (small), as in HistoryRecorder
SMALL = ("t", "gap", "beta", "contact_force", "frame_displacement", "on_wall", "stuck",
         "probes", "reaction", "iterations", "residual")
SCRATCH = ".levels.h5"


class DiskLevels:
    """A read-only (M+1, ...) array of levels kept in an HDF5 dataset:
    ``levels[n]`` (negative n counts from the end), ``shape``, ``len``."""

    def __init__(self, dataset, count):
        self.dataset, self.count = dataset, count
        self.shape = (count, *dataset.shape[1:])

    def __len__(self):
        return self.count

    def __getitem__(self, n):
        if not isinstance(n, (int, np.integer)):
            raise TypeError("DiskLevels is read one level at a time: levels[n]")
        if not -self.count <= n < self.count:
            raise IndexError(f"level {n} of {self.count}")
        return self.dataset[n % self.count]


class StreamingRecorder:
    """Levels to ``folder`` as they are computed (module docstring).

    Use as ``solve(problem, recorder=StreamingRecorder(problem, folder))``;
    then, with the Solution, :func:`~adhesive_contact.io.write_npz` and
    plots may read u; :meth:`close` ends the files and removes the scratch
    file (``names`` lists the files that stay)."""

    def __init__(self, problem, folder):
        self.folder = Path(folder)
        self.problem = problem
        output = problem.output if problem.output is not None else OutputOptions()
        self.series = XdmfSeries(problem, self.folder, output.fields)
        self.names = list(self.series.names)
        self.chooser = FieldLevels(output.every)
        self.candidates = {}   # level -> Level, kept until the run ends or it is passed
        levels = problem.options.steps + 1
        npoints, d = problem.mesh.p.shape[1], problem.dim
        self.scratch = H5File(self.folder / SCRATCH, "w")   # a full disk raises (h5.py)
        self.u = self.scratch.file.create_dataset("u", (levels, npoints, d), dtype=float,
                                             chunks=(1, npoints, d),
                                             maxshape=(None, npoints, d))
        self.small = {name: [] for name in SMALL}
        self.last = None
        self.count = 0
        self.empty = _empty_shapes(problem)

    def record(self, level):
        """Keep level ``level.n``'s small fields and u, and write its fields
        if it is a field level of the grid (or keep it as a candidate peak)."""
        if level.n >= self.u.shape[0]:   # an adaptive run: more levels than N + 1
            self.u.resize(2 * self.u.shape[0], axis=0)
        self.u[level.n] = level.u
        for name in SMALL:
            value = getattr(level, name)
            if value is not None:
                self.small[name].append(np.asarray(value))
        write, keep, drop = self.chooser.offer(
            level.n, reported_forces(self.problem, level.reaction, level.contact_force))
        for n in drop:
            self.candidates.pop(n, None)
        if write:
            self.series.write(level)
        elif keep:
            self.candidates[level.n] = level
        self.last = level
        self.count = level.n + 1

    def field_levels(self):
        """Write the field levels still pending (the last level and the
        peaks off the grid) and return every field level, increasing."""
        for n in self.chooser.end():
            self.series.write(self.last if n == self.last.n else self.candidates[n])
        self.candidates.clear()
        return np.array(self.chooser.levels(), dtype=np.int64)

    def history(self):
        """The fields of a Solution: small ones as arrays, u read from disk,
        σ (and σ_zz) of the last level only, as (1, ...) arrays."""
        out = {name: (np.stack(values) if values else np.zeros((0, *self.empty[name][0]),
                                                                 dtype=self.empty[name][1]))
               for name, values in self.small.items()}
        if self.problem.gap is None:
            out["gap"] = None
        out["u"] = DiskLevels(self.u, self.count)
        last = self.last
        out["stress"] = None if last is None else last.stress[None]
        out["stress_zz"] = None if last is None or last.stress_zz is None else \
            last.stress_zz[None]
        return out

    def close(self):
        """End the XDMF files and remove the scratch file (u is then gone
        from the Solution: write the npz and plots first)."""
        try:
            self.series.close()
        finally:
            try:
                self.scratch.close()
            finally:
                (self.folder / SCRATCH).unlink(missing_ok=True)


def _empty_shapes(problem):
    boundary, d = problem.boundary, problem.dim
    nc = 0 if boundary is None else boundary.nodes.size
    nf = 0 if boundary is None else boundary.facets.size
    nprobes = 0 if problem.probe_map is None else problem.probe_map.shape[0]
    return {"t": ((), float), "gap": ((nc,), float),
            "beta": ((nf,), float), "contact_force": ((nc, d), float),
            "frame_displacement": ((nc, d), float), "on_wall": ((nc,), bool),
            "stuck": ((nc,), bool), "probes": ((nprobes, d), float),
            "reaction": ((problem.prescribed.fixed.size,), float), "iterations": ((), int),
            "residual": ((), float)}
