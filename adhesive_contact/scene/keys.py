"""The keys of a scene, each declared once: its kind, default, range and meaning.

:data:`KEYS` maps each dotted name (``"solver.tol"``; the keys of a list's
tables are named without the index: ``"memory.terms.tau"``) to its
:class:`Key`. The table readers take a key's default, choices and bounds
from here (:meth:`~.reader.Table.read`), the dataclasses of :mod:`.spec`
their defaults, the unknown-key message the keys it offers
(:func:`offered`), and docs/scenes.md lists them (checked by the tests).
The parameters of a law are declared by its registry in
:mod:`adhesive_contact.laws`, which the law keys name.
"""

import re
from dataclasses import dataclass

from ..laws import BONDING_LAWS, FRICTION_LAWS, NORMAL_LAWS
from ..linear_solvers import METHODS as LINEAR_METHODS
from ..bonding import INTEGRATORS
from ..step_methods import METHODS as STEP_METHODS


class _Required:
    def __repr__(self):
        return "REQUIRED"


#: the default of a key that must be given (where its table's reader asks for it)
REQUIRED = _Required()


@dataclass(frozen=True)
class Interval:
    """The numbers from ``lo`` to ``hi``, ends included when ``closed``."""

    lo: float
    hi: float
    closed: bool = True

    def __contains__(self, value):
        if self.closed:
            return self.lo <= value <= self.hi
        return self.lo < value < self.hi


@dataclass(frozen=True)
class Key:
    """The declaration of one key of a scene.

    Parameters
    ----------
    name : str
        The dotted name, e.g. ``"solver.tol"``; ``""`` is the document.
    kind : str
        What the value must be: ``"number"``, ``"int"``, ``"str"``,
        ``"list"``, ``"expr"`` (a number or an expression string) or
        ``"table"``.
    default : object
        The value of an absent key; :data:`REQUIRED` when it must be given;
        None when an absent key sets nothing (no wall, no units), its
        meaning says what that means.
    meaning : str
        One line: what the key is.
    choices : tuple or dict, optional
        The allowed values, or ``{dim: allowed values}``.
    bounds : str or Interval, optional
        ``"positive"``, ``"nonnegative"`` or an :class:`Interval` (of the
        number, or of each entry of a list).
    reason : str, optional
        Why the bounds are what they are, appended to the message of a value
        outside them.
    laws : dict, optional
        For a law key, the registry of :mod:`adhesive_contact.laws` whose
        names are its choices and whose laws name their parameters.
    offer_all : bool
        For a table (or a list of tables): whether an unknown key's message offers every key
        declared in it, or only those its reader asked for (the keys of
        the domain, kernel or law given).
    """

    name: str
    kind: str
    default: object
    meaning: str
    choices: object = None
    bounds: object = None
    reason: str = None
    laws: dict = None
    offer_all: bool = True

    @property
    def required(self):
        """Whether the key has no default."""
        return self.default is REQUIRED

    @property
    def table(self):
        """The dotted name of the table the key is in (``""``: the document)."""
        return self.name.rpartition(".")[0]

    def allowed(self, dim=None):
        """The choices of the key in dimension ``dim``."""
        return self.choices[dim] if isinstance(self.choices, dict) else self.choices


def _law_key(table, laws, meaning):
    return Key(f"{table}.law", "str", REQUIRED, meaning, choices=tuple(laws), laws=laws)


def _pair(table, tensor):
    """The keys of an isotropic tensor given by exactly one pair: (E, nu) or (lam, mu)."""
    return (
        Key(f"{table}.E", "number", REQUIRED, f"Young's modulus of {tensor}",
            bounds="positive"),
        Key(f"{table}.nu", "number", REQUIRED, f"Poisson's ratio of {tensor}",
            bounds=Interval(-1.0, 0.5, closed=False)),
        Key(f"{table}.lam", "number", REQUIRED, f"Lamé's λ of {tensor} (with λ + 2μ/d > 0)"),
        Key(f"{table}.mu", "number", REQUIRED, f"Lamé's μ (the shear modulus) of {tensor}",
            bounds="positive"),
    )


#: the limits the readers check in their own words (a length of text, a count of nodes)
MAX_TITLE = 500             # characters of the title (it heads every plot)
MAX_CELL_ASPECT = 1e3       # longest over shortest edge of the structured cells
MAX_NODES = 10**8           # nodes of the refined mesh
MAX_UNIT = 16               # characters of a unit name in output.units
MAX_MODULUS = 1e100         # |λ|, μ of a tensor (and of the sums of a memory kernel)
MIN_MODULUS = 1e-100        # μ of an elastic tensor, and the bulk modulus λ + 2μ/d
MIN_STEP = 1e-100           # k = T/N: the time levels n k keep their precision
MAX_HALVINGS = 20           # k_min ≥ k_max 2^-20 (time.adaptive.k_min)

#: the fields a run may write at its field levels (``output.fields``):
#: u (solution.xdmf and solution.npz), the cell stress and its von Mises
#: value (solution.xdmf), the contact fields (contact.xdmf)
OUTPUT_FIELDS = ("u", "stress", "von_mises", "contact")

_DECLARATIONS = (
    Key("title", "str", "untitled", "the scene's title (it heads every plot)"),
    Key("dim", "int", REQUIRED, "the space dimension: 2 (plane strain) or 3", choices=(2, 3)),
    Key("mesh", "table", REQUIRED, "the mesh", offer_all=False),
    Key("boundary", "table", REQUIRED, "the parts of the boundary"),
    Key("material", "table", REQUIRED, "the elasticity tensor C (not with a relaxation "
        "kernel, which gives it)"),
    Key("memory", "table", None, "the memory kernel R (none when absent)", offer_all=False),
    Key("loads", "table", None, "the body force and the tractions (none when absent)"),
    Key("contact", "table", None, "the contact terms on Γ_C (none when absent)"),
    Key("time", "table", REQUIRED, "the time grid"),
    Key("solver", "table", None, "the step method and the linear backend"),
    Key("output", "table", None, "the probes, the levels and fields written, the units"),
    Key("exact", "table", None, "a manufactured solution (none when absent)"),

    Key("mesh.domain", "str", REQUIRED, "the domain: a rectangle, a box or a mesh file",
        choices={2: ("rectangle", "file"), 3: ("box", "file")}),
    # below 1e-6 or above 1e6 the element volumes (h^d, refined up to 4096
    # times) underflow or the stiffness overflows: rescale the units outside
    Key("mesh.size", "list", REQUIRED, "the lengths of the rectangle or box along each axis",
        bounds=Interval(1e-6, 1e6)),
    Key("mesh.cells", "list", REQUIRED, "the cells of the rectangle or box along each axis"),
    Key("mesh.pattern", "str", "diagonal", "how a rectangle's cells are cut into triangles",
        choices={2: ("diagonal", "cross"), 3: ("diagonal",)}),
    Key("mesh.refine", "int", 0, "the uniform refinements after building",
        bounds=Interval(0, 12)),
    Key("mesh.file", "str", REQUIRED, "the mesh file, relative to the scene file's folder"),

    Key("boundary.dirichlet", "list", (), "the clamped sides (u = 0), Γ_D"),
    Key("boundary.contact", "list", (), "the contact sides, Γ_C"),
    Key("boundary.displacement", "table", None, "the prescribed displacement of each side "
        "(none when absent)"),

    *_pair("material", "C"),

    Key("memory.kernel", "str", REQUIRED, "the kind of memory kernel",
        choices=("prony", "function", "relaxation")),
    Key("memory.terms", "list", REQUIRED, "the terms of a Prony series or relaxation modulus",
        offer_all=False),
    Key("memory.long_term", "table", REQUIRED, "the long-term tensor C_∞ of a relaxation "
        "modulus", offer_all=False),
    Key("memory.r", "expr", REQUIRED, "r(t) of the kernel R(t) = r(t) C_0"),
    *_pair("memory", "the kernel's C_0"),
    *_pair("memory.terms", "a term's tensor"),
    Key("memory.terms.tau", "number", REQUIRED, "a term's relaxation time τ",
        bounds="positive"),
    *_pair("memory.long_term", "C_∞"),

    Key("loads.body", "list", None, "the body force f_0 per unit volume (zero when absent)"),
    Key("loads.traction", "table", None, "the traction f_N per unit area of each Neumann "
        "side (none when absent)"),

    Key("contact.gap", "expr", None, "the distance g to the rigid wall (no wall when absent)",
        bounds="nonnegative"),
    Key("contact.foundation", "table", None, "the rigid wall's geometry, instead of a gap"),
    Key("contact.quadrature", "str", "nodal", "the quadrature of the contact terms on Γ_C",
        choices=("nodal", "gauss")),
    Key("contact.order", "int", 4, "the degree the Gauss rule on Γ_C integrates exactly",
        bounds=Interval(1, 10)),
    Key("contact.normal", "table", None, "the normal law (law none when absent)",
        offer_all=False),
    Key("contact.friction", "table", None, "a friction law, or a list of them whose "
        "potentials sum (none when absent)", offer_all=False),
    Key("contact.bonding", "table", None, "the bonding law and β_0 (β frozen at 1 when "
        "absent)"),

    Key("contact.foundation.shape", "str", "plane", "the shape of the foundation",
        choices={2: ("plane", "sphere"), 3: ("plane", "sphere", "cylinder")}),
    Key("contact.foundation.point", "list", REQUIRED, "a point of the plane, the sphere's "
        "centre or a point of the cylinder's axis"),
    Key("contact.foundation.normal", "list", REQUIRED, "the plane's normal, towards the body"),
    Key("contact.foundation.radius", "number", REQUIRED, "the radius of the sphere or "
        "cylinder", bounds="positive"),
    Key("contact.foundation.axis", "list", REQUIRED, "the direction of the cylinder's axis"),

    _law_key("contact.normal", NORMAL_LAWS, "the normal law"),
    _law_key("contact.friction", FRICTION_LAWS, "the friction law"),
    _law_key("contact.bonding", BONDING_LAWS, "the bonding law (none: β frozen at β_0)"),
    Key("contact.bonding.beta0", "expr", 1, "the bonding β_0 at t = 0, in [0, 1]",
        bounds=Interval(0.0, 1.0)),
    Key("contact.bonding.integrator", "str", "explicit", "the integrator of the bonding ODE",
        choices=tuple(INTEGRATORS)),

    Key("time.T", "number", REQUIRED, "the final time", bounds="positive"),
    Key("time.steps", "int", REQUIRED, "the number N of time steps, k = T/N",
        bounds=Interval(1, 10**8)),
    Key("time.scheme", "str", "paper", "the time discretisation: the paper's (right "
        "rectangle memory, first order) or the second-order one (trapezoidal memory, "
        "exponential midpoint bonding)", choices=("paper", "second-order")),
    Key("time.adaptive", "table", None, "adaptive time steps by step doubling, k_max = T/N "
        "(uniform steps k = T/N when absent)"),
    # below 1e-8 the steps reach k_min everywhere; above 1 nothing is controlled
    Key("time.adaptive.tol", "number", REQUIRED, "the time lag a pair of steps may make "
        "(its local error over its rate of change, u relative plus β rms), in units of T/64",
        bounds=Interval(1e-8, 1.0)),
    Key("time.adaptive.rate_floor", "number", 1e-3, "the smallest change per unit time "
        "the tolerance is relative to (a quiet stretch counts as changing at this rate)",
        bounds="positive"),
    Key("time.adaptive.k_min", "number", None, "the smallest step (k_max/1024 when absent), "
        "rounded down to k_max 2^-J", bounds="positive"),
    Key("time.adaptive.growth", "number", 2.0, "the largest factor a step may grow by after "
        "an accepted step", bounds=Interval(1.0, 16.0)),
    Key("time.adaptive.shrink", "number", 0.25, "the smallest factor a step may shrink by "
        "after a rejected one", bounds=Interval(0.01, 0.5)),
    Key("time.adaptive.safety", "number", 0.9, "the safety factor of the step controller",
        bounds=Interval(0.1, 1.0)),

    Key("solver.method", "str", "newton", "the step method", choices=tuple(STEP_METHODS)),
    Key("solver.tol", "number", 1e-10, "the step's residual, relative to its force scale",
        bounds=Interval(1e-14, 1e-3),
        # a tol near 1 accepts the starting point as the solution (no Newton
        # iteration, a quiet wrong answer); below 1e-14 round-off keeps the
        # residual from reaching it
        reason="it is relative to the force scale of a step, so a larger tol accepts the "
               "start as the solution and a smaller one is below round-off"),
    Key("solver.max_iter", "int", 50, "the iterations allowed per step",
        bounds=Interval(1, 10_000)),
    Key("solver.linear", "str", "auto", "the linear backend", choices=LINEAR_METHODS),
    Key("solver.linear_tol", "number", 1e-10, "the relative residual of each solve of the "
        "iterative backend",
        # below: round-off; above: a solve that barely acts
        bounds=Interval(1e-14, 1e-2),
        reason="the relative residual of each iterative linear solve"),
    Key("solver.penalty", "number", 1e4, "the penalty method's wall stiffness, relative to "
        "max_i S_ii", bounds="positive"),
    Key("solver.smoothing", "number", 1e-6, "the penalty method's rounding of the friction "
        "kink, relative to the body's diameter", bounds="positive"),

    Key("output.probes", "list", (), "the points whose displacement is recorded"),
    Key("output.plot_times", "list", "auto", "the times the figures draw: a list of times "
        "in [0, T], or \"auto\" (where the run's activity is, and T)"),
    Key("output.every", "int", 1, "fields are written at every N-th level (and at the "
        "first, the last and the peaks of the reported forces)", bounds=Interval(1, 10**9)),
    Key("output.fields", "list", OUTPUT_FIELDS, "the fields written at those levels, out of "
        "u, stress, von_mises, contact (an empty list: the scalars only)"),
    Key("output.units", "table", None, "the names of the units the scene's numbers are in "
        "(none when absent)"),
    Key("output.units.length", "str", None, "the unit of length, on the plots' axes"),
    Key("output.units.stress", "str", None, "the unit of stress, on the plots' axes"),
    Key("output.units.time", "str", None, "the unit of time, on the plots' axes"),
    Key("output.units.force", "str", None, "the unit of force, on the plots' axes"),

    Key("exact.u", "list", REQUIRED, "the exact displacement u*"),
    Key("exact.beta", "expr", 1, "the exact bonding β*"),
    Key("exact.multiplier", "expr", None, "the wall's exact reaction λ* where u*_ν = g "
        "(none when absent)"),
)

#: every declared key by its dotted name
KEYS = {key.name: key for key in _DECLARATIONS}


def declared(name):
    """The declaration of the key ``name``, indices of lists dropped
    (``"memory.terms[2].tau"`` is ``"memory.terms.tau"``)."""
    return KEYS[re.sub(r"\[\d+\]", "", name)]


def default(name):
    """The default of the key ``name``."""
    return KEYS[name].default


def keys_in(table):
    """The names (last part) of the keys declared in ``table``, in order."""
    return tuple(key.name.rpartition(".")[2] for key in _DECLARATIONS if key.table == table)


def offered(table):
    """The keys an unknown key's message in ``table`` offers besides those
    read: every key declared in it with the parameters of every law of its
    law key, or none for a table read whole for its domain, kernel or law
    (see :attr:`Key.offer_all`)."""
    name = re.sub(r"\[\d+\]", "", table)
    if name and (name not in KEYS or not KEYS[name].offer_all):
        return set()
    names = set(keys_in(name))
    law = KEYS.get(f"{name}.law")
    if law is not None:
        names.update(p for _, params in law.laws.values() for p in params)
    return names
