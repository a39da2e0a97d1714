"""The scalar quantities of a run that a study reports: the state of Γ_C
at T, per held side the peak and final reaction of each held component,
the energies at T and the debonded area at T (docs/outputs.md,
``runs.csv``); a sweep's row and a convergence study's ``--quantity`` read
the same names.

State at T (:func:`state_quantities`): ``beta_min_T``, ``beta_mean_T``
(None without contact facets), ``max_un_minus_g`` (over every level and
contact node; None without a wall), the contact-node counts
``separated_T``, ``on_wall_T``, ``compliance_T``, ``stick_T``, ``slip_T``
(None without friction) and ``normal_force_T`` (positive in compression).

Names: ``reaction_<side>_<x|y|z>_peak`` (the value of largest magnitude
over the levels, with its sign) and ``reaction_<side>_<x|y|z>_T``;
``work_T``, ``stored_T``, ``dissipated_T``, ``viscous_T``,
``debonding_T``, ``numerical_T``, ``balance_T`` (None without an energy
balance, :mod:`.energy`); ``debonded_area_T``, ``damage_T`` and
``glue_energy_per_area_T`` (per area the run debonded, a pre-crack left
out; None without contact facets, :mod:`.fracture`).
"""

import numpy as np

from .energy import energies, energy_unavailable
from .fracture import debonded_area, energy_per_area, new_debonding
from .quantities import beta_mean
from .reactions import reaction_sides, reactions
from .states import contact_state_counts

AXES = "xyz"
ENERGY_NAMES = ("work_T", "stored_T", "dissipated_T", "viscous_T", "debonding_T",
                "numerical_T", "balance_T")
DEBONDING_NAMES = ("debonded_area_T", "damage_T", "glue_energy_per_area_T")
STATE_NAMES = ("beta_min_T", "beta_mean_T", "max_un_minus_g", "separated_T", "on_wall_T",
               "compliance_T", "stick_T", "slip_T", "normal_force_T")


def state_quantities(solution):
    """{name: value or None} of the state of Γ_C at T (module docstring)."""
    states = {key: counts[-1] for key, counts in contact_state_counts(solution).items()}
    mean = beta_mean(solution)
    out = {"beta_min_T": float(solution.beta[-1].min()) if solution.beta.shape[1] else None,
           "beta_mean_T": None if mean is None else float(mean[-1]),
           "max_un_minus_g": _number(solution.gap_violation().max())}
    out.update({f"{key}_T": _number(states.get(key))
                for key in ("separated", "on_wall", "compliance", "stick", "slip")})
    out["normal_force_T"] = float(solution.total_normal_force()[-1])
    return out


def _number(value):
    if value is None:
        return None
    value = value.item() if hasattr(value, "item") else value
    return value if isinstance(value, int) else float(value)


def reaction_names(problem):
    """The reaction quantities of a problem's held sides, in order."""
    names = []
    for side in reaction_sides(problem):
        for c in sorted(problem.prescribed.side_dofs(side)):
            names += [f"reaction_{side}_{AXES[c]}_peak", f"reaction_{side}_{AXES[c]}_T"]
    return names


def peak(values):
    """The entry of largest magnitude of ``values`` (n,), with its sign."""
    values = np.asarray(values, dtype=float)
    return float(values[np.argmax(np.abs(values))])


def scalar_quantities(solution):
    """{name: float or None} of the module docstring, in a fixed order."""
    problem = solution.problem
    out = {}
    held = reactions(solution)
    for i, side in enumerate(reaction_sides(problem)):
        for c in sorted(problem.prescribed.side_dofs(side)):
            out[f"reaction_{side}_{AXES[c]}_peak"] = peak(held[:, i, c])
            out[f"reaction_{side}_{AXES[c]}_T"] = float(held[-1, i, c])
    history = energies(solution)
    values = (None,) * len(ENERGY_NAMES) if history is None else (
        history.external_work[-1], history.stored_total[-1], history.dissipated_total[-1],
        history.dissipated["viscous"][-1], history.dissipated["debonding"][-1],
        history.dissipated["numerical"][-1], history.balance[-1])
    out.update({name: None if v is None else float(v) for name, v in zip(ENERGY_NAMES, values)})
    boundary = problem.boundary
    if boundary is None or boundary.facets.size == 0:
        out.update(dict.fromkeys(DEBONDING_NAMES))
        return out
    area, damage = debonded_area(solution)
    new_area = new_debonding(solution)[0]
    per = (None if history is None else
           energy_per_area(history.dissipated["debonding"][-1:], new_area[-1:])[0])
    out.update(debonded_area_T=float(area[-1]), damage_T=float(damage[-1]),
               glue_energy_per_area_T=None if per is None or np.isnan(per) else float(per))
    return out


def quantity_names(problem):
    """Every name a study may converge for a run of ``problem``: those of
    :func:`state_quantities` and :func:`scalar_quantities`, in order (a
    value may still be None: no energy balance, no facets, no wall)."""
    return [*STATE_NAMES, *reaction_names(problem), *ENERGY_NAMES, *DEBONDING_NAMES]


#: the kind (:mod:`.units`) of each quantity that is no reaction
KINDS = {"beta_min_T": "1", "beta_mean_T": "1", "max_un_minus_g": "length",
         "separated_T": "count", "on_wall_T": "count", "compliance_T": "count",
         "stick_T": "count", "slip_T": "count", "normal_force_T": "force",
         **dict.fromkeys(ENERGY_NAMES, "energy"), "debonded_area_T": "measure",
         "damage_T": "measure", "glue_energy_per_area_T": "toughness"}


def quantity_kind(name):
    """The kind of quantity ``name`` of :func:`quantity_names` (a force, an
    energy, ...: :mod:`.units`); None for a name that is none of them."""
    if name.startswith("reaction_") and name.endswith(("_peak", "_T")):
        return "force"
    return KINDS.get(name)


def quantity_unavailable(problem, name):
    """Why quantity ``name`` of :func:`quantity_names` has no value in a run of
    ``problem`` (a sentence), or None when it has one."""
    boundary = problem.boundary
    facets = boundary is not None and boundary.facets.size > 0
    energy = energy_unavailable(problem) if name in ENERGY_NAMES + (
        "glue_energy_per_area_T",) else None
    if energy is not None:
        return f"the run has no energy balance: {energy}"
    if not facets and (name in DEBONDING_NAMES or name.startswith("beta_")):
        return "the scene has no contact facets"
    if name == "max_un_minus_g" and problem.gap is None:
        return "the scene has no wall (no contact.gap or [contact.foundation])"
    if name in ("stick_T", "slip_T") and problem.friction is None:
        return "the scene has no friction law"
    return None


def study_quantities(solution):
    """:func:`state_quantities` and :func:`scalar_quantities` in one dict:
    what a convergence study measures of each run."""
    return state_quantities(solution) | scalar_quantities(solution)
