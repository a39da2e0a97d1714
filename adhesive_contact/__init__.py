"""adhesive_contact: quasistatic adhesive contact of a viscoelastic body with
long memory, solved with the fully discrete scheme of Cheng & Xiao
(P1 displacements, P0 bonding on Γ_C, right rectangle memory, explicit
Euler bonding) on scikit-fem. See docs/model.md for the mathematics."""

from .expressions import ExpressionError, compile_expression
from .io import OutputFolderError, load_solution, write_xdmf
from .postprocess import (STATE_NAMES, contact_state_codes, contact_traction, reaction_sides,
                          reactions, total_contact_force)
from .problem import Problem, build_problem
from .scene import Scene, SceneError, load_scene, parse_scene, scene_from_dict
from .scheme import Solution, StepFailure, solve

__version__ = "0.1.0"

__all__ = ["ExpressionError", "compile_expression", "Problem", "build_problem", "Scene",
           "SceneError", "load_scene", "parse_scene", "scene_from_dict", "Solution", "StepFailure",
           "solve", "contact_traction", "total_contact_force", "contact_state_codes",
           "STATE_NAMES", "reactions", "reaction_sides", "write_xdmf", "load_solution",
           "OutputFolderError", "__version__"]
