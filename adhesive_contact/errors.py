"""The error of a scene that cannot be run, and how a message names a point.

At the base of the package (it imports nothing of it): the meshes, the
check of a manufactured solution, the scene reader, the problem's checks
and the scheme's check of a level all raise :class:`SceneError`, which
``adhesive_contact`` and ``adhesive_contact.scene`` hand on;
:func:`where` is the one way every check (before a run, of a manufactured
solution, of a level) writes the point it found.
"""

import numpy as np


#: the longest key or listed name a message shows whole; a longer one is
#: cut in the middle (a 10,000-character unknown key made a line as long)
SHOWN_KEY = 80


def shown_key(key):
    """``key`` as a message shows it: whole up to SHOWN_KEY characters, else
    its start and end around "…"."""
    key = str(key)
    if len(key) <= SHOWN_KEY:
        return key
    half = (SHOWN_KEY - 1) // 2
    return f"{key[:half]}…{key[-half:]}"


class SceneError(ValueError):
    """A scene that cannot be run; ``str(err)`` is ``"key: what is allowed"``
    (a long key cut to SHOWN_KEY characters; ``key`` keeps it whole)."""

    def __init__(self, key, message):
        self.key = key
        self.reason = message
        super().__init__(f"{shown_key(key)}: {message}" if key else message)

    def __reduce__(self):   # survive the trip back from a worker process
        return type(self), (self.key, self.reason)


def where(points, index=None, t=None, digits=6):
    """A point of a message: "(x, y)", or "(x, y), t = t" with a time.

    ``points`` is (d,) or (d, n) with ``index`` naming the column; each
    coordinate to ``digits`` significant digits."""
    points = np.asarray(points)
    x = points if index is None else points[:, index]
    text = "(" + ", ".join(f"{c:.{digits}g}" for c in x) + ")"
    return text if t is None else f"{text}, t = {t:g}"
