"""Files that are never seen half written, and strict JSON.

:func:`write_atomic` writes to a temporary file beside the target and
renames it into place, so a reader (or a rerun after a crash) sees the old
file or the whole new one. JSON has no NaN or infinity: :func:`plain`
turns numpy scalars and containers into JSON types with NaN and ±inf as
``None``, and :func:`write_json` writes the result strictly
(``allow_nan=False``).
"""

import contextlib
import json
import math
import os
import tempfile
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


def write_atomic(path, write, binary=False):
    """Call ``write(file)`` on a temporary file beside ``path``, then rename it
    to ``path`` (replacing it): readers see the old file or the whole new one.

    Parameters
    ----------
    path : str or os.PathLike
    write : callable taking the open file
    binary : open the temporary file in binary mode (else UTF-8 text, no
        newline translation)
    """
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.tmp-", dir=path.parent)
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


def toml_value(value):
    """A value as it is written in TOML (``1000.0``, ``true``, ``"gauss"``)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, list):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    return repr(value)
