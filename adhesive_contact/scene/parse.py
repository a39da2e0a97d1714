"""A scene from a file, a TOML document or the dictionary it decodes to.

``base_dir`` is where a relative ``mesh.file`` is found. Every key is
checked: a missing, unknown or wrongly typed key, or a value outside its
range, raises :class:`~.errors.SceneError` whose message is one line that
names the key and says what is allowed. Nothing is computed here;
geometry-dependent checks (a probe outside the mesh, a negative gap, side
names that a mesh file does not have) are made when the problem is built.
"""

import errno
import os
import stat
import tomllib
from dataclasses import replace
from pathlib import Path

from .contact import read_contact
from ..errors import SceneError
from .keys import MAX_TITLE, declared
from .materials import (check_elastic, check_relaxation_step, instantaneous, read_material,
                        read_memory)
from .reader import Table
from .spec import Scene
from .tables import (check_something_holds, read_boundary, read_exact, read_loads, read_mesh, read_output,
                     read_solver, read_time)


def scene_from_dict(data, base_dir=None):
    """Validate a decoded scene document and return a :class:`Scene`;
    ``base_dir`` is the folder a relative ``mesh.file`` is taken in
    (default: the working directory)."""
    top = Table(data, "")
    title = top.read("title")
    if len(title) > MAX_TITLE:
        raise SceneError("title", f"must have at most {MAX_TITLE} characters, got {len(title)}")
    dim = top.get("dim", "int")   # its choices with a message of their own
    if dim not in declared("dim").choices:
        raise SceneError("dim", f"must be 2 (plane strain) or 3, got {dim}")
    mesh = read_mesh(top.table("mesh"), dim, base_dir)
    by_file = mesh.domain == "file"
    dirichlet, contact_sides, displacement = read_boundary(
        top.table("boundary"), dim, by_file)
    memory = read_memory(top.table("memory"), dim)
    if memory is not None and memory.kernel == "relaxation":
        if top.has("material"):
            raise SceneError("material", "a relaxation kernel ([memory] kernel = "
                             "\"relaxation\") gives the material; remove [material]")
        top.used.add("material")
        material = instantaneous(memory)
        check_elastic("memory.long_term", memory.long_term, dim,
                      "the long-term tensor of the relaxation kernel")
    else:
        material = read_material(top.table("material"), dim)
    body, traction = read_loads(top.table("loads"), dim, dirichlet, contact_sides, by_file)
    contact = read_contact(top.table("contact"), dim, contact_sides)
    T, steps, scheme, adaptive = read_time(top.table("time"))
    contact = scheme_integrator(contact, scheme, data)
    solver = read_solver(top.table("solver"))
    probes, units, plot_times, every, fields = read_output(top.table("output"), dim, T)
    exact = read_exact(top.table("exact"), dim, contact, top.has("loads"))
    top.finish()
    if memory is not None and memory.kernel == "relaxation":
        check_relaxation_step(memory, dim, T / steps)   # k_max: the largest step
    scene = Scene(title, dim, mesh, dirichlet, contact_sides, material, memory, body,
                  traction, contact, T, steps, solver, probes, exact, displacement, units,
                  plot_times, scheme, adaptive, every, fields)
    check_something_holds(scene, by_file)
    return scene


#: the bonding integrator of the second-order scheme (docs/scheme.md)
SECOND_ORDER_INTEGRATOR = "midpoint"


def scheme_integrator(contact, scheme, data):
    """``contact`` with the bonding integrator of ``scheme``: the second-order
    scheme integrates β by the exponential midpoint rule (its default there);
    a first-order integrator named with it is refused."""
    if scheme != "second-order":
        return contact
    if contact.bonding.law == "cohesive":
        raise SceneError("time.scheme", "\"second-order\" has no second-order update for "
                         "the cohesive law (its damage follows the previous level: first "
                         "order); use \"paper\"")
    bonding = (data.get("contact") or {}).get("bonding") or {}
    given = bonding.get("integrator") if isinstance(bonding, dict) else None
    if given is not None and given != SECOND_ORDER_INTEGRATOR:
        raise SceneError("contact.bonding.integrator",
                         f"time.scheme = \"second-order\" integrates β by the exponential "
                         f"midpoint rule: give \"{SECOND_ORDER_INTEGRATOR}\" or leave the key "
                         f"out, got {given!r} (first order)")
    return replace(contact, integrator=SECOND_ORDER_INTEGRATOR)


def parse_scene(text, base_dir=None):
    """Parse a TOML scene document; TOML syntax errors become SceneError.
    ``base_dir``: the folder a relative ``mesh.file`` is taken in."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise SceneError("", f"not valid TOML: {err}") from None
    except RecursionError:
        raise SceneError("", "not a usable TOML document: arrays or tables nested too "
                         "deeply") from None
    return scene_from_dict(data, base_dir)


#: the largest scene file read: a scene is a page of TOML (the largest
#: committed one is under 4 KiB); anything past this is not a scene
MAX_SCENE_BYTES = 1 << 20


def read_scene_text(path):
    """The text of the scene file ``path``. Only a regular file of at most
    MAX_SCENE_BYTES is read: a FIFO would block the read, a device such as
    /dev/zero never ends, so anything else is refused before it is opened
    (OSError with a sentence as its ``strerror``); UnicodeDecodeError for
    a file that is not UTF-8."""
    path = Path(path)
    mode = os.stat(path).st_mode   # FileNotFoundError for a missing file
    if not stat.S_ISREG(mode):
        kind = ("a folder" if stat.S_ISDIR(mode) else "a named pipe (FIFO)"
                if stat.S_ISFIFO(mode) else "a device" if stat.S_ISCHR(mode) or
                stat.S_ISBLK(mode) else "a socket" if stat.S_ISSOCK(mode) else "not a file")
        raise OSError(errno.EINVAL, f"{kind}, not a regular file; give a scene file (TOML)")
    with open(path, "rb") as f:
        data = f.read(MAX_SCENE_BYTES + 1)
    if len(data) > MAX_SCENE_BYTES:
        raise OSError(errno.EFBIG, f"larger than {MAX_SCENE_BYTES >> 20} MiB, which no scene "
                      "is; give a scene file (TOML)")
    return data.decode("utf-8")


def load_scene(path):
    """Read and parse the scene file ``path`` (:func:`read_scene_text`); a
    relative ``mesh.file`` is taken in the scene file's folder. OSError if
    the file cannot be read or is no regular file of scene size."""
    path = Path(path)
    return parse_scene(read_scene_text(path), base_dir=path.parent)
