"""Quantities derived from a solution: stresses, contact tractions and
forces, β means (:mod:`.quantities`), the contact state of every node
(:mod:`.states`), the reactions of the held sides (:mod:`.reactions`), the
energy balance (:mod:`.energy`), what debonded (:mod:`.fracture`) and the
scalars a study reports (:mod:`.scalars`).
Their figures are :mod:`adhesive_contact.visuals`."""

from .energy import DISSIPATED, STORED, EnergyHistory, energies, energy_unavailable
from .fracture import (debond_front, debond_fronts, debonded_area, energy_per_area,
                       new_debonding)
from .quantities import (FRAMES, beta_mean, cell_von_mises, contact_fields,
                         contact_nodal_forces, contact_traction, normal_traction, penetration,
                         stress_3x3, tangential_traction, to_global, total_contact_force,
                         von_mises)
from .reactions import (applied_traction, prescribed_history, reaction_sides, reactions,
                        side_mean_displacement, side_reactions)
from .scalars import quantity_names, scalar_quantities
from .states import (COMPLIANCE, SEPARATED, SLIP, STATE_NAMES, STATE_TOLERANCE, STICK, WALL,
                     contact_measure, contact_state_code, contact_state_codes,
                     contact_state_counts, contact_states, state_masks, state_tolerance)

__all__ = ["DISSIPATED", "STORED", "EnergyHistory", "energies", "energy_unavailable",
           "debond_front", "debond_fronts", "debonded_area", "energy_per_area", "new_debonding",
           "FRAMES",
           "beta_mean", "cell_von_mises", "contact_fields", "contact_nodal_forces",
           "contact_traction", "normal_traction", "penetration", "stress_3x3",
           "tangential_traction", "to_global", "total_contact_force", "von_mises",
           "applied_traction", "prescribed_history", "reaction_sides", "reactions",
           "side_mean_displacement", "side_reactions", "scalar_quantities", "quantity_names",
           "COMPLIANCE",
           "SEPARATED", "SLIP", "STATE_NAMES", "STATE_TOLERANCE", "STICK", "WALL",
           "contact_measure", "contact_state_code", "contact_state_codes", "contact_state_counts",
           "contact_states", "state_masks", "state_tolerance"]
