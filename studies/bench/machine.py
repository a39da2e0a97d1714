"""What a benchmark ran on: recorded beside its figures."""

import datetime
import os
import platform
import shutil
import sys
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

PACKAGES = ("numpy", "scipy", "scikit-fem", "pyamg", "pypardiso")


def describe(packages=PACKAGES):
    """The platform, processor, core count, Python, the versions of
    ``packages`` (None where not installed) and the date."""
    found = {}
    for name in packages:
        try:
            found[name] = version(name)
        except PackageNotFoundError:
            found[name] = None
    return {"platform": platform.platform(), "processor": platform.processor(),
            "cpus": os.cpu_count(), "python": platform.python_version(), "versions": found,
            "date": datetime.datetime.now().astimezone().isoformat(timespec="seconds")}


def adhcontact():
    """The ``adhcontact`` command of this Python's environment (else the
    one on PATH), for benchmarks that run it as a user does."""
    return shutil.which("adhcontact", path=str(Path(sys.executable).parent)) or "adhcontact"
