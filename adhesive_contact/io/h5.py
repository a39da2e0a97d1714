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
        finally:
            with contextlib.suppress(OSError):
                self.raw.close()
