"""The wall's gap g(x_a, t) at the contact nodes (docs/model.md, the wall
u_ν ≤ g).

A :class:`Gap` belongs to the Problem and knows the geometry; the times
belong to a run, which asks :meth:`Gap.at` for the gap of each level it
computes (and keeps it with the level: ``Solution.gap``). A gap given by
``[contact.foundation]``, or by an expression of x alone, is one array;
an expression of t is evaluated at each t asked for (nc values).
"""

from dataclasses import dataclass

import numpy as np

from ..expressions import coordinates


@dataclass(frozen=True)
class Gap:
    """g at the contact nodes: ``values`` (nc,) when it does not depend on
    t, else ``expression`` evaluated at the nodes ``x`` (d, nc)."""

    values: np.ndarray = None
    expression: object = None
    x: np.ndarray = None

    def at(self, t):
        """g(x_a, t) (nc,), +inf at a node without a wall."""
        if self.values is not None:
            return self.values
        return np.asarray(self.expression(*coordinates(self.x), t=float(t)), dtype=float) \
            * np.ones(self.x.shape[1])

    def levels(self, times):
        """g at each of ``times``: (len(times), nc)."""
        return np.array([self.at(t) for t in np.asarray(times, dtype=float)]).reshape(
            len(times), -1)

    @property
    def varies(self):
        """Whether g depends on t."""
        return self.values is None

    @property
    def somewhere(self):
        """(nc,) bool: the nodes with a wall at some time (g finite; a
        foundation the frame normal misses is +inf)."""
        if self.values is not None:
            return np.isfinite(self.values)
        return np.ones(self.x.shape[1], dtype=bool)
