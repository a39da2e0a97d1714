"""Recorders decide what a run keeps of each level.

The loop hands every converged :class:`~adhesive_contact.scheme.state.Level`
to its recorder; :class:`HistoryRecorder` keeps all of them in arrays
indexed by n = 0..N (what :class:`~adhesive_contact.scheme.solution.Solution`
holds). A recorder that streams levels to disk plugs in here.
"""

import numpy as np


class HistoryRecorder:
    """Every level in memory: arrays of shape (N+1, ...) per field."""

    def __init__(self, problem):
        mesh, boundary, d = problem.mesh, problem.boundary, problem.dim
        levels = problem.options.steps + 1
        npoints, ncells = mesh.p.shape[1], mesh.t.shape[1]
        nc = 0 if boundary is None else boundary.nodes.size
        nf = 0 if boundary is None else boundary.facets.size
        nprobes = 0 if problem.probe_map is None else problem.probe_map.shape[0]
        self.arrays = {
            "t": np.zeros(levels),
            "gap": np.zeros((levels, nc)) if problem.gap is not None else None,
            "u": np.zeros((levels, npoints, d)),
            "beta": np.zeros((levels, nf)),
            "stress": np.zeros((levels, ncells, d, d)),
            "stress_zz": np.zeros((levels, ncells)) if d == 2 else None,
            "contact_force": np.zeros((levels, nc, d)),
            "frame_displacement": np.zeros((levels, nc, d)),
            "on_wall": np.zeros((levels, nc), dtype=bool),
            "stuck": np.zeros((levels, nc), dtype=bool),
            "probes": np.zeros((levels, nprobes, d)),
            "reaction": np.zeros((levels, problem.prescribed.fixed.size)),
            "iterations": np.zeros(levels, dtype=int),
            "residual": np.zeros(levels),
        }
        self.count = 0

    def record(self, level):
        """Keep level ``level.n`` (levels arrive in order n = 0, 1, ...);
        the arrays double when an adaptive run has more levels than N + 1."""
        if level.n >= self.arrays["u"].shape[0]:
            self.arrays = {name: None if a is None else
                           np.concatenate([a, np.zeros_like(a)]) for name, a in
                           self.arrays.items()}
        for name, array in self.arrays.items():
            if array is not None:
                array[level.n] = getattr(level, name)
        self.count = level.n + 1

    def history(self):
        """The recorded levels n < count: field name -> array (count, ...),
        None for a field the scene does not have (σ_zz in 3D, the gap
        without a wall)."""
        return {name: None if a is None else a[:self.count] for name, a in self.arrays.items()}
