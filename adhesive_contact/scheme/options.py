"""What a run of the scheme is told, and what it keeps, resolved once from
its scene.

:func:`~adhesive_contact.problem.build.build_problem` fills a
:class:`SchemeOptions` (``problem.options``) from the validated scene; the
scheme, the step methods and the linear backends read it and never the
scene itself, so a step can be set up from these few numbers alone.

Its attribute names are those of the scene for what they share (``T``,
``steps``, ``k``, ``scheme``, ``adaptive``, ``memory``, ``material``,
``dim``, ``solver``), so the step-size controller
(:mod:`.adaptive`) takes either.
"""

from dataclasses import dataclass


@dataclass(frozen=True)
class SolverOptions:
    """The step method and the linear backend (the scene's ``[solver]``).

    ``method`` the step method (:mod:`adhesive_contact.step_methods`),
    ``tol`` and ``max_iter`` its relative tolerance and Newton iterations,
    ``penalty`` and ``smoothing`` the "penalty" method's relative penalty
    and kink rounding; ``linear`` the backend
    (:mod:`adhesive_contact.linear_solvers`, or ``"auto"``) and
    ``linear_tol`` the relative residual of the iterative one."""

    method: str
    tol: float
    max_iter: int
    penalty: float
    smoothing: float
    linear: str
    linear_tol: float


@dataclass(frozen=True)
class SchemeOptions:
    """The time grid and scheme, the bonding integrator, the memory and the
    elastic tensor of a run, and its :class:`SolverOptions`.

    ``T`` and ``steps`` N give the uniform step k = T/N (for
    ``[time.adaptive]``, ``adaptive`` the AdaptiveSpec, k = k_max);
    ``scheme`` "paper" or "second-order"; ``integrator`` the bonding step's
    (4.2); ``memory`` the MemorySpec or None; ``material`` the elastic
    tensor C (its ``lam``, ``mu``); ``dim`` d."""

    T: float
    steps: int
    scheme: str
    integrator: str
    adaptive: object
    memory: object
    material: object
    dim: int
    solver: SolverOptions

    @property
    def k(self):
        """The uniform time step k = T/N (k_max of an adaptive run)."""
        return self.T / self.steps

    @property
    def second_order(self):
        """Whether the trapezoidal memory and the midpoint bonding step run."""
        return self.scheme == "second-order"


@dataclass(frozen=True)
class OutputOptions:
    """What a run writes (the scene's ``[output]``).

    ``every`` N: the field levels are every N-th level, the first, the
    last and each level where a reported force peaks
    (:class:`adhesive_contact.io.StreamingRecorder`); ``fields`` the
    fields written there, out of ``u``, ``stress``, ``von_mises`` and
    ``contact`` (none: the scalars only, which every level keeps);
    ``units`` {quantity: unit name} of ``[output.units]``, for the
    column names of scalars.csv and the plots' axes."""

    every: int = 1
    fields: tuple = ("u", "stress", "von_mises", "contact")
    units: dict = None

    def writes(self, name):
        """Whether field ``name`` is written at the field levels."""
        return name in self.fields
