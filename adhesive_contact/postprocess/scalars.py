"""The scalar quantities of a run that a study reports: per held side the
peak and final reaction of each held component, the energies at T and the
debonded area at T (docs/outputs.md, ``runs.csv``).

Names: ``reaction_<side>_<x|y|z>_peak`` (the value of largest magnitude
over the levels, with its sign) and ``reaction_<side>_<x|y|z>_T``;
``work_T``, ``stored_T``, ``dissipated_T``, ``viscous_T``,
``debonding_T``, ``numerical_T``, ``balance_T`` (None without an energy
balance, :mod:`.energy`); ``debonded_area_T``, ``damage_T`` and
``glue_energy_per_area_T`` (None without contact facets, :mod:`.fracture`).
"""

import numpy as np

from .energy import energies
from .fracture import debonded_area, energy_per_area
from .reactions import reaction_sides, reactions

AXES = "xyz"
ENERGY_NAMES = ("work_T", "stored_T", "dissipated_T", "viscous_T", "debonding_T",
                "numerical_T", "balance_T")
DEBONDING_NAMES = ("debonded_area_T", "damage_T", "glue_energy_per_area_T")


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
    per = (None if history is None else
           energy_per_area(history.dissipated["debonding"][-1:], area[-1:])[0])
    out.update(debonded_area_T=float(area[-1]), damage_T=float(damage[-1]),
               glue_energy_per_area_T=None if per is None or np.isnan(per) else float(per))
    return out


def quantity_names(problem):
    """Every name :func:`scalar_quantities` gives for a run of ``problem``, in
    its order (a value may still be None: no energy balance, no facets)."""
    return [*reaction_names(problem), *ENERGY_NAMES, *DEBONDING_NAMES]
