"""The error of an output folder that cannot be read back."""

from pathlib import Path


class OutputFolderError(ValueError):
    """A folder that cannot be read back: ``path`` names the file at fault,
    ``str(err)`` is ``"<path>: what is wrong"``."""

    def __init__(self, path, message):
        self.path = Path(path)
        super().__init__(f"{self.path}: {message}")
