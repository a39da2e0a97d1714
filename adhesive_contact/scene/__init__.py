"""Scenes: the validated description of one problem (docs/scenes.md).

A scene is read from a file (``load_scene(path)``), a TOML document
(``parse_scene(text, base_dir)``) or the dictionary it decodes to
(``scene_from_dict``); ``base_dir`` is where a relative ``mesh.file`` is
found. Every key is checked: a missing, unknown or wrongly typed key, or a
value outside its range, raises :class:`SceneError` whose message is one
line that names the key and says what is allowed.

- :class:`SceneError` (of :mod:`adhesive_contact.errors`, at the base of
  the package, so that the meshes below the scene raise it too);
- :mod:`.spec`: the dataclasses of a validated scene, :class:`Scene` and
  one per table;
- :mod:`.record`: the resolved record (:attr:`Scene.resolved`);
- :mod:`.keys`: every key declared once (kind, default, choices, bounds,
  meaning);
- :mod:`.reader`: typed access to a TOML table and the checks the table
  readers share;
- :mod:`.tables`, :mod:`.materials`, :mod:`.contact`: the table readers;
- :mod:`.parse`: the scene from a file, a TOML text or a dictionary.
"""

from ..errors import SceneError, where
from .materials import relaxation_step_definite
from .parse import load_scene, parse_scene, scene_from_dict
from .spec import (ContactSpec, ExactSpec, FoundationSpec, Isotropic, LawSpec, MemorySpec,
                   MeshSpec, PronyTerm, Scene, SolverSpec)

__all__ = ["SceneError", "where", "relaxation_step_definite", "load_scene", "parse_scene", "scene_from_dict", "Scene", "MeshSpec",
           "Isotropic", "PronyTerm", "MemorySpec", "LawSpec", "FoundationSpec", "ContactSpec",
           "ExactSpec", "SolverSpec"]
