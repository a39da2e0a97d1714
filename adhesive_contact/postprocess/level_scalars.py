"""The scalars of every level of a run: the rows of ``scalars.csv``.

One column per quantity, one row per level (docs/outputs.md,
"scalars.csv"); each column has a *kind* (:mod:`.units`) that gives its
unit. In order:

- ``t``;
- per held side and held component c: ``reaction_<side>_<c>``, the force
  of the side's support on the body (:mod:`.reactions`), and
  ``displacement_<side>_<c>``, the side's mean nodal displacement (the
  grip's, for a prescribed component);
- per side with a traction: ``force_<side>_<c>`` (the applied total
  force ∫ f_N) and ``displacement_<side>_<c>``;
- with contact nodes: ``contact_force_<c>`` (Σ_a R_a F_a, the total force
  of Γ_C on the body, global), ``normal_force`` (Σ_a −F_{a,ν}, positive
  in compression), ``tangential_force`` (2D; ``tangential_force_1``,
  ``_2`` in 3D: Σ_a F_{a,τ} in the nodal tangent frames),
  ``contact_width`` (2D) or ``contact_area`` (3D): the measure of Γ_C in
  contact (:func:`~.states.contact_measure`), ``peak_pressure`` (the
  largest nodal pressure −F_{a,ν}/w_a) and its place
  ``peak_pressure_<c>`` (the node's reference coordinates), and with
  friction ``stick_width``/``slip_width`` (``_area`` in 3D), the measure
  of the sticking and slipping nodes;
- with contact facets: ``beta_mean``, ``beta_min``, ``debonded_length``
  (2D) or ``debonded_area`` (3D), the measure of the facets that debonded
  during the run (β < ½ now, β₀ ≥ ½: a pre-crack is not counted), and
  ``damage``, ∫_{Γ_C} (β₀ − β);
- with a wall: ``max_penetration`` (:func:`~.quantities.penetration`);
- with an energy balance (:mod:`.energy`): ``external_work``, ``stored``,
  ``dissipated``, ``balance`` and each part ``stored_<part>``,
  ``dissipated_<part>``;
- ``iterations``, ``residual`` of the step solve.

A solution whose fields are kept at some levels only (``solution.scalars``
read back from solution.npz) gives the columns it recorded.
"""

from dataclasses import dataclass

import numpy as np

from .energy import DISSIPATED, STORED, energies
from .fracture import new_debonding
from .quantities import beta_mean, normal_traction, penetration, total_contact_force
from .reactions import applied_traction, reaction_sides, reactions, side_displacements
from .states import contact_measure, contact_states

AXES = "xyz"


@dataclass(frozen=True)
class Column:
    """One column of scalars.csv: its ``name``, ``kind`` (:mod:`.units`)
    and ``values`` (M+1,)."""

    name: str
    kind: str
    values: np.ndarray


def _boundary_columns(solution):
    problem = solution.problem
    d = problem.dim
    held = reactions(solution)
    traction_sides = list(problem.scene.traction)
    sides = reaction_sides(problem)
    moved = side_displacements(solution, list(dict.fromkeys([*sides, *traction_sides])))
    columns = []
    for i, side in enumerate(sides):
        for c in sorted(problem.prescribed.side_dofs(side)):
            columns.append(Column(f"reaction_{side}_{AXES[c]}", "force", held[:, i, c]))
        for c in sorted(problem.prescribed.side_dofs(side)):
            columns.append(Column(f"displacement_{side}_{AXES[c]}", "length",
                                  moved[side][:, c]))
    for side in traction_sides:
        force = applied_traction(problem, side, solution.t)
        columns += [Column(f"force_{side}_{AXES[c]}", "force", force[:, c]) for c in range(d)]
        columns += [Column(f"displacement_{side}_{AXES[c]}", "length", moved[side][:, c])
                    for c in range(d)]
    return columns


def _contact_columns(solution):
    problem = solution.problem
    boundary, d = problem.boundary, problem.dim
    if boundary is None or boundary.nodes.size == 0:
        return []
    measure = "width" if d == 2 else "area"
    total = total_contact_force(solution)
    columns = [Column(f"contact_force_{AXES[c]}", "force", total[:, c]) for c in range(d)]
    columns.append(Column("normal_force", "force", solution.total_normal_force()))
    tangential = solution.total_tangential_force()
    names = ["tangential_force"] if d == 2 else ["tangential_force_1", "tangential_force_2"]
    columns += [Column(name, "force", tangential[:, i]) for i, name in enumerate(names)]
    columns.append(Column(f"contact_{measure}", "measure", contact_measure(solution)))
    pressure = normal_traction(solution)                               # (M+1, nc)
    at = np.argmax(pressure, axis=1)
    columns.append(Column("peak_pressure", "stress",
                          pressure[np.arange(pressure.shape[0]), at]))
    where = problem.mesh.p[:, boundary.nodes[at]]                      # (d, M+1)
    columns += [Column(f"peak_pressure_{AXES[c]}", "length", where[c]) for c in range(d)]
    if problem.friction is not None:
        states = contact_states(solution)
        for state in ("stick", "slip"):
            columns.append(Column(f"{state}_{measure}", "measure",
                                  states[state] @ boundary.node_weights))
    return columns


def _bonding_columns(solution):
    boundary = solution.problem.boundary
    if boundary is None or boundary.facets.size == 0:
        return []
    name = "debonded_length" if solution.problem.dim == 2 else "debonded_area"
    debonded, damage = new_debonding(solution)
    return [Column("beta_mean", "1", beta_mean(solution)),
            Column("beta_min", "1", np.asarray(solution.beta).min(axis=1)),
            Column(name, "measure", debonded), Column("damage", "measure", damage)]


def _energy_columns(history):
    if history is None:
        return []
    columns = [Column("external_work", "energy", history.external_work),
               Column("stored", "energy", history.stored_total),
               Column("dissipated", "energy", history.dissipated_total),
               Column("balance", "energy", history.balance)]
    columns += [Column(f"stored_{part}", "energy", history.stored[part]) for part in STORED]
    columns += [Column(f"dissipated_{part}", "energy", history.dissipated[part])
                for part in DISSIPATED]
    return columns


def level_scalars(solution, history=None):
    """The columns of scalars.csv (module docstring): a list of :class:`Column`.
    ``history``: the run's :func:`~.energy.energies`, when the caller has it."""
    recorded = getattr(solution, "scalars", None)
    if recorded is not None:   # read back from a folder: the columns it kept
        return [Column(name, kind, np.asarray(values)) for name, (kind, values)
                in recorded.items()]
    history = energies(solution) if history is None else history
    columns = [Column("t", "time", np.asarray(solution.t, dtype=float))]
    columns += _boundary_columns(solution)
    columns += _contact_columns(solution)
    columns += _bonding_columns(solution)
    if solution.problem.gap is not None:
        columns.append(Column("max_penetration", "length", penetration(solution)))
    columns += _energy_columns(history)
    columns += [Column("iterations", "count", np.asarray(solution.iterations)),
                Column("residual", "1", np.asarray(solution.residual, dtype=float))]
    return columns
