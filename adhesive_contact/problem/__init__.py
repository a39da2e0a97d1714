"""A scene made discrete: everything built once before the time loop.

:func:`build_problem` (:mod:`.build`) runs the stages that turn a
:class:`~adhesive_contact.scene.Scene` into a :class:`Problem`;
:mod:`.checks` holds every check that raises before a run, :mod:`.warnings`
every warning about a scene or a run, :mod:`.smallness` the estimate of the
theory's smallness conditions.
"""

from .build import build_problem
from .problem import Problem

__all__ = ["Problem", "build_problem"]
