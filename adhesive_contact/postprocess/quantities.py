"""Quantities derived from a :class:`~adhesive_contact.Solution`.

Post-processing only, no numerics of the scheme; every function is
vectorised over the time levels n = 0..N and the cells or contact nodes.

Stress. In plane strain ε_zz = 0 but σ_zz = λ tr ε (with the memory's λ
parts) is not; :func:`stress_3x3` puts the solution's σ_zz in the zz entry,
and :func:`von_mises` reads the 3 × 3 tensor.

Contact. The solution carries F_a, the force Γ_C exerts on the body at
contact node a, in the nodal frame R_a = [ν_a, τ_a (, τ'_a)] (columns):
F_a = (F_{a,ν}, F_{a,τ}), F_{a,ν} < 0 in compression. Its global (Cartesian)
components are R_a F_a (:func:`contact_nodal_forces`); a traction is a
nodal force over the lumped nodal weight w_a = ∫_{Γ_C} φ_a
(:func:`contact_traction`).
"""

import numpy as np

from ..fem.foundation import signed_distance
from .states import contact_state_code

FRAMES = ("nodal", "global")


def _levels(array, n):
    return array if n is None else array[n]


def stress_3x3(solution, n=None):
    """σ as full 3 × 3 tensors per cell.

    In 2D (plane strain) the in-plane block is σ_xx, σ_xy, σ_yy and the zz
    entry the solution's σ_zz = λ tr ε (λ of the material and the memory's
    λ parts: ν (σ_xx + σ_yy) when every part has the same ν); the xz and yz
    entries are 0. In 3D σ is returned as it is.

    Parameters
    ----------
    solution : Solution
    n : int, optional
        A time level; all levels when omitted.

    Returns
    -------
    ndarray, (ncells, 3, 3) for one level, else (N+1, ncells, 3, 3)
    """
    s = _levels(solution.stress, n)
    if s.shape[-1] == 3:
        return s
    full = np.zeros(s.shape[:-2] + (3, 3))
    full[..., :2, :2] = s
    full[..., 2, 2] = _levels(solution.stress_zz, n)
    return full


def von_mises(stress):
    """Von Mises equivalent stress σ_vM = sqrt(3/2 s : s), s = σ − (tr σ / 3) I.

    Parameters
    ----------
    stress : array_like, (..., 3, 3)
        Full 3 × 3 tensors (see :func:`stress_3x3`).

    Returns
    -------
    ndarray, (...)
        Uniaxial σ e₁⊗e₁ gives |σ|; pure shear τ (e₁⊗e₂ + e₂⊗e₁) gives √3 |τ|.
    """
    s = np.asarray(stress, dtype=float)
    dev = s - np.trace(s, axis1=-2, axis2=-1)[..., None, None] * np.eye(3) / 3.0
    return np.sqrt(1.5 * np.einsum("...ij,...ij->...", dev, dev))


def cell_von_mises(solution, n=None):
    """Von Mises stress per cell, with the plane-strain σ_zz in 2D.

    Returns (ncells,) for level ``n``, else (N+1, ncells)."""
    return von_mises(stress_3x3(solution, n))


def to_global(problem, nodal):
    """Rotate nodal-frame vectors at the contact nodes to global components.

    v_a = R_a ṽ_a, R_a the frame of contact node a (columns ν_a, τ_a(, τ'_a)).

    Parameters
    ----------
    problem : Problem (with a contact boundary)
    nodal : array_like, (..., nc, d)

    Returns
    -------
    ndarray, (..., nc, d)
    """
    return np.einsum("aic,...ac->...ai", problem.boundary.frame, np.asarray(nodal))


def contact_nodal_forces(solution, frame="global"):
    """F_a: the force Γ_C exerts on the body at each contact node.

    The nodal contact force of the scheme (normal compliance, adhesion,
    friction and the wall's reaction), in the nodal frames
    (F_ν, F_τ(, F_τ')) or in global components R_a F_a. With the global
    ones a reaction is a plain sum: Σ_a F_a is the total force of Γ_C on
    the body.

    Parameters
    ----------
    solution : Solution
    frame : {"global", "nodal"}

    Returns
    -------
    ndarray, (N+1, nc, d)
    """
    if frame not in FRAMES:
        raise ValueError(f"frame must be one of {FRAMES}, got {frame!r}")
    force = solution.contact_force
    return force if frame == "nodal" else to_global(solution.problem, force)


def contact_traction(solution, frame="nodal"):
    """Nodal contact traction σ_a = F_a / w_a, w_a = ∫_{Γ_C} φ_a.

    The traction of Γ_C on the body at the contact nodes (lumped: the
    nodal force over the nodal weight), in the nodal frames (component 0
    the normal one σ_ν, negative in compression) or in global components.

    Parameters
    ----------
    solution : Solution
    frame : {"nodal", "global"}

    Returns
    -------
    ndarray, (N+1, nc, d)
    """
    weights = solution.problem.boundary.node_weights
    return contact_nodal_forces(solution, frame) / weights[:, None]


def normal_traction(solution):
    """Normal traction −σ_ν at the contact nodes, positive in compression, (N+1, nc):
    the contact pressure, −F_{a,ν} / w_a."""
    return -contact_traction(solution)[:, :, 0]


def tangential_traction(solution):
    """Tangential traction σ_τ in the nodal tangent frames [τ (, τ')], (N+1, nc, d−1)."""
    return contact_traction(solution)[:, :, 1:]


def total_contact_force(solution):
    """Σ_a R_a F_a: the total force of Γ_C on the body, global components (N+1, d)."""
    return contact_nodal_forces(solution, "global").sum(axis=1)


def beta_mean(solution):
    """Facet-measure weighted mean of β per level, Σ_f |f| β_f / Σ_f |f|.

    Returns (N+1,), or None without contact facets."""
    boundary = solution.problem.boundary
    if boundary is None or boundary.facets.size == 0:
        return None
    return solution.beta @ boundary.measure / boundary.measure.sum()


def contact_fields(problem, contact_force, frame_displacement, on_wall, stuck, gap=None):
    """The per-node contact quantities of one level, for ParaView:
    ``traction`` (nc, d) global components, ``normal_traction`` (nc,)
    positive in compression, ``tangential_traction`` (nc, d−1) in the nodal
    tangent frames, ``u_normal`` (nc,), ``slip`` |u_τ| (nc,), ``state`` (nc,)
    (:func:`contact_state_code`; ``gap`` (nc,) the level's g, if any)."""
    weights = problem.boundary.node_weights[:, None]
    nodal = np.asarray(contact_force) / weights
    frame_displacement = np.asarray(frame_displacement)
    return {"traction": to_global(problem, nodal),
            "normal_traction": -nodal[:, 0],
            "tangential_traction": nodal[:, 1:],
            "u_normal": frame_displacement[:, 0],
            "slip": np.linalg.norm(frame_displacement[:, 1:], axis=-1),
            "state": contact_state_code(problem, frame_displacement, on_wall, stuck, gap)}


def penetration(solution):
    """max_a of the penetration of the contact nodes per level (M+1,): with
    ``[contact.foundation]`` the depth of the displaced node inside the
    foundation itself, −d_F(x_a + u_a) (d_F the signed distance from its
    surface, :func:`~adhesive_contact.fem.foundation.signed_distance`); with
    a gap expression u_ν − g. Over the nodes whose u_ν is not held
    (−inf without a wall or such nodes); ≤ 0 where every node is outside.

    On a plane u_ν − g = −d_F(x_a + u_a) exactly; on a sphere or cylinder
    the wall u_ν ≤ g is its linearisation at the closest point: a node on
    the wall sits on the tangent there, √(r² + |u_τ|²) − r ≈ |u_τ|²/(2r)
    outside the (convex) foundation."""
    problem = solution.problem
    foundation = problem.scene.contact.foundation
    if foundation is None or solution.gap is None or solution.gap.shape[1] == 0:
        return solution.gap_violation()
    boundary = problem.boundary
    levels, nc, d = solution.frame_displacement.shape
    # u_a = R_a z_a at the contact nodes: every level's, without the fields
    x = problem.mesh.p[:, boundary.nodes].T + to_global(problem, solution.frame_displacement)
    depth = -signed_distance(foundation, x.reshape(-1, d).T).reshape(levels, nc)
    return np.where(boundary.held[:, 0], -np.inf, depth).max(axis=1, initial=-np.inf)
