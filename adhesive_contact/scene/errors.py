"""The error of a scene that cannot be run.

This module imports nothing, so that the layers the scene reader itself
uses (the meshes) can raise :class:`SceneError` without a cycle.
"""


class SceneError(ValueError):
    """A scene that cannot be run; ``str(err)`` is ``"key: what is allowed"``."""

    def __init__(self, key, message):
        self.key = key
        super().__init__(f"{key}: {message}" if key else message)
