"""The contact state of every contact node: one classification.

A contact node a of a level is

- ``separated``: u_ν < 0 (away from the foundation), else touching;
- ``on_wall``: u_ν = g, held by the rigid wall (the step method's set);
- ``compliance``: touching and not on the wall (in the compliant layer);
- with a friction law, ``stick``: touching and held at ξ = 0 by a friction
  kink; ``slip``: touching, not stuck, with u_τ ≠ 0.

A node that sticks or slips may also be on the wall. :func:`state_masks`
is the classification; the masks of every level (:func:`contact_states`),
their counts (:func:`contact_state_counts`) and one integer code per node
(:func:`contact_state_code`, for ParaView and the plots) are read off it.
"""

import numpy as np

#: the integer codes of :func:`contact_state_code`, in the order of STATE_NAMES
SEPARATED, COMPLIANCE, WALL, STICK, SLIP = 0, 1, 2, 3, 4
STATE_NAMES = ("separated", "compliance", "wall", "stick", "slip")


def state_masks(problem, frame_displacement, on_wall, stuck):
    """The states of contact nodes of one level or several, as boolean masks.

    Parameters
    ----------
    problem : Problem (whether it has friction)
    frame_displacement : (..., nc, d) nodal-frame displacements
    on_wall, stuck : (..., nc) bool

    Returns
    -------
    dict of str to ndarray of bool, each (..., nc): ``separated``,
    ``on_wall``, ``compliance``, and with friction ``stick`` and ``slip``.
    """
    frame_displacement = np.asarray(frame_displacement)
    on_wall = np.asarray(on_wall)
    separated = frame_displacement[..., 0] < 0
    touching = ~separated
    out = {"separated": separated, "on_wall": on_wall.copy(),
           "compliance": touching & ~on_wall}
    if problem.friction is not None:
        stuck = np.asarray(stuck)
        moving = np.linalg.norm(frame_displacement[..., 1:], axis=-1) > 0
        out["stick"] = touching & stuck
        out["slip"] = touching & ~stuck & moving
    return out


def contact_states(solution):
    """:func:`state_masks` at every level: each mask (N+1, nc)."""
    return state_masks(solution.problem, solution.frame_displacement, solution.on_wall,
                       solution.stuck)


def contact_state_counts(solution):
    """The number of contact nodes in each state of :func:`contact_states`
    per level: a dict of (N+1,) int arrays."""
    return {key: mask.sum(axis=-1) for key, mask in contact_states(solution).items()}


def contact_state_code(problem, frame_displacement, on_wall, stuck):
    """One integer state per contact node (:func:`state_masks` read in order
    of precedence): 0 separated; for a touching node 3 stick, else 4 slip,
    else 2 wall, else 1 compliance.

    Parameters as :func:`state_masks`. Returns an ndarray of int8 (..., nc).
    """
    masks = state_masks(problem, frame_displacement, on_wall, stuck)
    code = np.where(masks["on_wall"], WALL, COMPLIANCE)
    if "slip" in masks:
        code = np.where(masks["slip"], SLIP, code)
        code = np.where(masks["stick"], STICK, code)
    return np.where(masks["separated"], SEPARATED, code).astype(np.int8)


def contact_state_codes(solution):
    """:func:`contact_state_code` at every level (N+1, nc)."""
    return contact_state_code(solution.problem, solution.frame_displacement,
                              solution.on_wall, solution.stuck)
