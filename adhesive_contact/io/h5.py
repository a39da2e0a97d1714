"""HDF5 files that report a full disk as an ``OSError``.

The HDF5 library writes through its own file driver and, when a write
fails (a full disk, a file-size limit), h5py 3 can crash the process
(a segmentation fault on the next flush or close) instead of raising.
:class:`H5File` opens the HDF5 file on a Python file object (h5py's
"fileobj" driver): every write goes through Python, so a failed write is
an ``OSError`` raised where it happened, and closing the file afterwards
raises too instead of crashing.
"""

import contextlib

#: h5py's mode -> the Python file mode it needs
_MODES = {"w": "w+b", "a": "r+b", "r": "rb"}
#: the Python files under HDF5 files whose close failed: HDF5 still holds
#: them (its objects flush and truncate through them when they are freed,
#: at the latest when the process ends), so they stay open until then; a
#: closed one made that last truncate a segmentation fault on a full disk
_HELD_OPEN = []


def held_open():
    """Whether an HDF5 file failed to close in this process (its Python
    file is held open for the HDF5 library, which may crash when it cleans
    up at exit: a caller may end the process without that clean-up)."""
    return bool(_HELD_OPEN)


class H5File:
    """An ``h5py.File`` (``.file``) on a Python file object; :meth:`close`
    closes both, the HDF5 file first."""

    def __init__(self, path, mode):
        import h5py

        self.raw = open(path, _MODES[mode])
        try:
            self.file = h5py.File(self.raw, mode)
        except BaseException:
            self.raw.close()
            raise

    def close(self):
        """Close the HDF5 file and the Python file under it; the first
        error of the two is raised after both are closed."""
        try:
            self.file.close()
        except BaseException:
            if self.file.id.valid:   # HDF5 still holds the file: leave it open
                _HELD_OPEN.append(self.raw)
                raise
            with contextlib.suppress(OSError):
                self.raw.close()
            raise
        with contextlib.suppress(OSError):
            self.raw.close()
