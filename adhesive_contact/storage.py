"""Files that are never seen half written, and strict JSON.

:func:`write_atomic` writes to a temporary file beside the target and
renames it into place, so a reader (or a rerun after a crash) sees the old
file or the whole new one. JSON has no NaN or infinity: :func:`plain`
turns numpy scalars and containers into JSON types with NaN and ±inf as
``None``, and :func:`write_json` writes the result strictly
(``allow_nan=False``).
"""

import contextlib
import csv
import json
import math
import os
import re
import tempfile
from collections.abc import Mapping
from pathlib import Path

import numpy as np


def json_number(value):
    """A finite float, or None for NaN and ±inf (JSON has neither); −0.0 is 0.0."""
    value = float(value) + 0.0
    return value if math.isfinite(value) else None


def plain(value):
    """``value`` with JSON types only.

    Dicts (keys made str), lists and tuples are converted item by item; numpy
    booleans and integers become bool and int; floats go through
    :func:`json_number` (NaN and ±inf become None); numpy arrays become
    nested lists. Anything else is returned as it is.
    """
    if isinstance(value, dict):
        return {str(k): plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    if isinstance(value, np.ndarray):
        return plain(value.tolist())
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return json_number(value)
    return value


#: between a file's name and the writer's pid in its temporary name
TEMPORARY = ".tmp-"
_TEMPORARY_NAME = re.compile(r"\.(?P<name>.+)\.tmp-(?P<pid>[0-9]+)-[A-Za-z0-9_]+")


def write_atomic(path, write, binary=False):
    """Call ``write(file)`` on a temporary file beside ``path``, then rename it
    to ``path`` (replacing it): readers see the old file or the whole new one.

    The temporary file is ``.<name>.tmp-<pid>-XXXXXXXX``, removed when
    ``write`` raises; one a killed process left is removed by
    :func:`remove_stale_temporaries`.

    Parameters
    ----------
    path : str or os.PathLike
    write : callable taking the open file
    binary : open the temporary file in binary mode (else UTF-8 text, no
        newline translation)
    """
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}{TEMPORARY}{os.getpid()}-", dir=path.parent)
    try:
        with (os.fdopen(fd, "wb") if binary else
              os.fdopen(fd, "w", encoding="utf-8", newline="")) as f:
            write(f)
        os.chmod(tmp, 0o644)   # mkstemp makes it private
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def remove_stale_temporaries(folder):
    """Remove the temporary files of :func:`write_atomic` in ``folder`` whose
    writer is no longer alive (a killed process); return their names.

    Only a regular file named ``.<name>.tmp-<pid>-<suffix>`` whose process
    ``pid`` does not exist goes; a live writer's file, or any other, stays."""
    removed = []
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return removed
    for entry in entries:
        match = _TEMPORARY_NAME.fullmatch(entry.name)
        if match and entry.is_file(follow_symlinks=False) and not pid_alive(int(match["pid"])):
            with contextlib.suppress(OSError):
                os.unlink(entry.path)
                removed.append(entry.name)
    return removed


def pid_alive(pid):
    """Whether a process ``pid`` exists (one of another user counts; a
    number no system gives as a pid counts as alive, so that what it names
    is left alone)."""
    if pid <= 0 or pid > 1 << 22:
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:
        return True
    return True


def dumps(document):
    """Strict JSON text of :func:`plain` ``(document)``, indented by 1, newline-terminated."""
    return json.dumps(plain(document), indent=1, allow_nan=False) + "\n"


def write_json(path, document):
    """Write ``document`` as strict JSON (NaN and ±inf as null), atomically."""
    text = dumps(document)
    write_atomic(path, lambda f: f.write(text))


def read_json(path):
    """The JSON document at ``path``, or None when it is missing or unreadable."""
    try:
        return json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None


def saved_or_computed(path, compute):
    """The JSON record at ``path`` when a run saved it, else ``compute()``
    saved there whole (:func:`write_json`: a killed run leaves no half
    record) and returned: how a study script resumes."""
    record = read_json(path)
    if record is not None:
        return record
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    record = compute()
    write_json(path, record)
    return record


def csv_cell(value, digits=None):
    """A value as a cell of the package's CSV files: a float as ``repr``
    (it reads back to the same float) or to ``digits`` significant digits
    when given, None (and a NaN) as an empty cell, a list or table as its
    text."""
    if value is None:
        return ""
    if isinstance(value, (float, np.floating)):
        value = float(value)
        if value != value:
            return ""
        return repr(value) if digits is None else f"{value:.{digits}g}"
    if isinstance(value, np.integer):
        return str(int(value))
    return str(value)


def write_csv(path, columns, rows, digits=None):
    """A CSV table written atomically: a header of ``columns``, then one
    line per row (a sequence of cells in column order, or a mapping by
    column name), each cell :func:`csv_cell` (floats exact by default)."""
    def write(f):
        writer = csv.writer(f, lineterminator="\n")
        writer.writerow(columns)
        for row in rows:
            cells = [row.get(c) for c in columns] if isinstance(row, Mapping) else row
            writer.writerow([csv_cell(v, digits) for v in cells])
    write_atomic(path, write)


def toml_value(value):
    """A value as it is written in TOML (``1000.0``, ``true``, ``"gauss"``)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, list):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    return repr(value)
