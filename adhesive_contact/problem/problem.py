"""The discretised scene, :class:`Problem`: what a run reads, built once
by :func:`~adhesive_contact.problem.build.build_problem` and never changed
by a run."""

from dataclasses import dataclass, field

import numpy as np

from ..fem.assembly import Assembly, LoadMap
from ..fem.p1 import gradients
from .smallness import smallness
from .warnings import problem_warnings


@dataclass(kw_only=True)
class Problem:
    """A discretised scene; built once, never changed by a run.

    Absent concepts are None (``boundary``, ``gap``, ``friction``,
    ``bonding``, ``probe_map``, ``exact``, ``beta_source``), except the
    normal law, whose null object :class:`~adhesive_contact.laws.NoNormalLaw`
    contributes nothing, and the memory (:class:`~adhesive_contact.scheme.memory.NoMemory`)."""

    scene: object
    mesh: object
    assembly: Assembly
    free: np.ndarray          # free dofs (not held by a side)
    prescribed: object        # PrescribedDisplacement: the held dofs and g_D(t)
    boundary: object          # ContactBoundary, or None
    columns: np.ndarray       # the step's unknowns among the nc·d frame components
    contact_positions: np.ndarray  # positions of those unknowns within ``free``
    loads: LoadMap
    gap: object               # Gap: g(x_a, t) at the contact nodes (.at(t)), or None: no wall
    beta0: np.ndarray         # (nf,) β_0^h
    normal_law: object
    friction: object          # FrictionSum or None
    bonding: object           # bonding law or None (β frozen)
    probe_map: object         # sparse (nprobes, npoints) or None
    assembly_seconds: float
    exact: object = None      # ManufacturedSolution, for scenes with [exact]
    beta_source: object = None  # s_β(x, y, z, t) at Γ_C (manufactured scenes)
    held_by_contact: tuple = ()  # the rigid motions only the contact terms hold, in words
    options: object = None    # SchemeOptions: what the scheme reads of the scene
    output: object = None     # OutputOptions: what a run writes ([output])
    _smallness: dict = field(default=None, repr=False)
    _geometry: tuple = field(default=None, repr=False)

    @property
    def smallness(self):
        """The terms of docs/model.md §3's condition (None without contact),
        computed on first use (a generalised eigenproblem) and kept."""
        if self._smallness is None and self.boundary is not None:
            self._smallness = smallness(self.scene, self.normal_law, self.friction,
                                        self.held_by_contact)
        return self._smallness

    @property
    def geometry(self):
        """(grad λ (ncells, d+1, d), volume (ncells,)): the barycentric
        gradients and measures of the cells, computed on first use and kept
        (:func:`~adhesive_contact.fem.p1.gradients`)."""
        if self._geometry is None:
            self._geometry = gradients(self.mesh)
        return self._geometry

    def warnings(self):
        """What the theory does not cover for this scene, and magnitudes it
        should not have, one line each (:func:`.warnings.problem_warnings`)."""
        return problem_warnings(self)

    @property
    def dim(self):
        return self.mesh.dim()

    @property
    def ndofs(self):
        return self.assembly.ndofs

    @property
    def normal_columns(self):
        """Positions within the step's unknowns of the normal components."""
        return np.flatnonzero(self.columns % self.dim == 0)

    def upper_bound(self, gap):
        """Bounds on z for a step whose gap at the contact nodes is ``gap``
        (nc,) (None: no wall): g at the normal unknowns, +inf elsewhere."""
        upper = np.full(self.columns.size, np.inf)
        if gap is not None:
            normal = self.normal_columns
            upper[normal] = gap[self.columns[normal] // self.dim]
        return upper
