"""The error of a scene that cannot be run, and how a message names a point.

This module imports nothing of the package, so that the layers the scene
reader itself uses (the meshes) can raise :class:`SceneError` without a
cycle; :func:`where` is the one way every check (before a run, of a
manufactured solution, of a level) writes the point it found.
"""

import numpy as np


class SceneError(ValueError):
    """A scene that cannot be run; ``str(err)`` is ``"key: what is allowed"``."""

    def __init__(self, key, message):
        self.key = key
        super().__init__(f"{key}: {message}" if key else message)


def where(points, index=None, t=None, digits=6):
    """A point of a message: "(x, y)", or "(x, y), t = t" with a time.

    ``points`` is (d,) or (d, n) with ``index`` naming the column; each
    coordinate to ``digits`` significant digits."""
    points = np.asarray(points)
    x = points if index is None else points[:, index]
    text = "(" + ", ".join(f"{c:.{digits}g}" for c in x) + ")"
    return text if t is None else f"{text}, t = {t:g}"
