"""The contact state of every contact node: one classification.

A contact node a of a level is, with the tolerance
tol = STATE_TOLERANCE × the body's size (the diagonal of its bounding box;
:func:`state_tolerance`),

- with a compliant layer (a normal law other than ``none``): ``separated``
  where u_ν < −tol (away from the foundation), else touching;
- without one (``[contact.normal] law = "none"``) and with a wall: touching
  where it is on the wall (u_ν ≥ g − tol, or in the step method's wall set),
  else ``separated`` (short of the wall: nothing acts on it but friction);
  without a wall either, as with a layer;
- ``on_wall``: held by the rigid wall (the step method's set);
- ``compliance``: touching and not on the wall (in the compliant layer;
  none without a layer);
- with a friction law, ``stick``: touching and held at ξ = 0 by a friction
  kink; ``slip``: touching, not stuck, with |u_τ| > tol.

A node that sticks or slips may also be on the wall. :func:`state_masks`
is the classification; the masks of every level (:func:`contact_states`),
their counts (:func:`contact_state_counts`), one integer code per node
(:func:`contact_state_code`, for ParaView and the plots) and the measure
of Γ_C in contact (:func:`contact_measure`) are read off it.
"""

import numpy as np

#: the integer codes of :func:`contact_state_code`, in the order of STATE_NAMES
SEPARATED, COMPLIANCE, WALL, STICK, SLIP = 0, 1, 2, 3, 4
STATE_NAMES = ("separated", "compliance", "wall", "stick", "slip")

#: the state tolerance relative to the body's size: a displacement below
#: it is no separation (nor slip)
STATE_TOLERANCE = 1e-8


def state_tolerance(problem):
    """tol = STATE_TOLERANCE × the diagonal of the mesh's bounding box."""
    p = problem.mesh.p
    return STATE_TOLERANCE * float(np.linalg.norm(p.max(axis=1) - p.min(axis=1)))


def state_masks(problem, frame_displacement, on_wall, stuck, gap=None):
    """The states of contact nodes of one level or several, as boolean masks.

    Parameters
    ----------
    problem : Problem (its normal law, friction, mesh size)
    frame_displacement : (..., nc, d) nodal-frame displacements
    on_wall, stuck : (..., nc) bool
    gap : (..., nc), optional
        g at the same levels (without a compliant layer, a node at
        u_ν ≥ g − tol is on the wall also outside the step method's set).

    Returns
    -------
    dict of str to ndarray of bool, each (..., nc): ``separated``,
    ``on_wall``, ``compliance``, and with friction ``stick`` and ``slip``.
    """
    frame_displacement = np.asarray(frame_displacement)
    on_wall = np.asarray(on_wall)
    tol = state_tolerance(problem)
    un = frame_displacement[..., 0]
    if problem.normal_law.active or problem.gap is None:
        touching = un >= -tol
        compliance = touching & ~on_wall
    else:
        touching = on_wall.copy()
        if gap is not None:
            touching |= un >= np.asarray(gap) - tol
        compliance = np.zeros_like(touching)
    out = {"separated": ~touching, "on_wall": on_wall.copy(), "compliance": compliance}
    if problem.friction is not None:
        stuck = np.asarray(stuck)
        moving = np.linalg.norm(frame_displacement[..., 1:], axis=-1) > tol
        out["stick"] = touching & stuck
        out["slip"] = touching & ~stuck & moving
    return out


def _gap_of(solution):
    return solution.gap


def contact_states(solution):
    """:func:`state_masks` at every level: each mask (N+1, nc)."""
    return state_masks(solution.problem, solution.frame_displacement, solution.on_wall,
                       solution.stuck, _gap_of(solution))


def contact_state_counts(solution):
    """The number of contact nodes in each state of :func:`contact_states`
    per level: a dict of (N+1,) int arrays."""
    return {key: mask.sum(axis=-1) for key, mask in contact_states(solution).items()}


def contact_measure(solution):
    """The measure of Γ_C in contact per level (N+1,): Σ_a w_a over the
    touching (not separated) contact nodes, w_a = ∫_{Γ_C} φ_a; a width in
    2D, an area in 3D. For a contact zone of m consecutive nodes spaced h
    on a straight side it is m h: the distance between its outer nodes
    plus h."""
    weights = solution.problem.boundary.node_weights
    return (~contact_states(solution)["separated"]) @ weights


def contact_state_code(problem, frame_displacement, on_wall, stuck, gap=None):
    """One integer state per contact node (:func:`state_masks` read in order
    of precedence): 0 separated; for a touching node 3 stick, else 4 slip,
    else 2 wall, else 1 compliance.

    Parameters as :func:`state_masks`. Returns an ndarray of int8 (..., nc).
    """
    masks = state_masks(problem, frame_displacement, on_wall, stuck, gap)
    code = np.where(masks["on_wall"], WALL, COMPLIANCE)
    if "slip" in masks:
        code = np.where(masks["slip"], SLIP, code)
        code = np.where(masks["stick"], STICK, code)
    return np.where(masks["separated"], SEPARATED, code).astype(np.int8)


def contact_state_codes(solution):
    """:func:`contact_state_code` at every level (N+1, nc)."""
    return contact_state_code(solution.problem, solution.frame_displacement,
                              solution.on_wall, solution.stuck, _gap_of(solution))
