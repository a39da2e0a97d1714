"""The fully discrete scheme of Problem 4.1 as a layer.

- :mod:`.operators`: what a run builds once per mesh and step size (the
  frame rotation and the condensed step matrices, :mod:`.condensed`);
- :mod:`.state`: the state of level n and the functions that advance it,
  one per equation: the bonding step (4.2), the step load with the memory
  history (:mod:`.memory`), the step solve (4.1);
- :mod:`.march`: the one time march, level by level, for any step
  controller (:mod:`.controllers`: uniform steps, step doubling);
- :mod:`.recorder`: what is kept of each level;
- :mod:`.loop`: :func:`solve`, the march with the problem's controller;
- :mod:`.level_checks`: what every level must satisfy (no quiet wrong answers);
- :mod:`.solution`: what a run returns, :class:`Solution`.
"""

from .level_checks import InvalidState
from .loop import solve
from .solution import STEP_FAILED, STOPPED, SUCCESS, Solution, StepFailure

__all__ = ["solve", "Solution", "StepFailure", "InvalidState", "SUCCESS", "STEP_FAILED", "STOPPED"]
