"""Every warning about a valid scene or a finished run, one line each.

Nothing here raises (refusals are :mod:`.checks`). Before a run,
:func:`problem_warnings` says what the scene's numbers make likely to go
wrong: a step beyond the explicit Euler bound of the bonding law, a step
beyond an accuracy guide of :mod:`.accuracy` (the bonding law's time scale
with another integrator, the memory's quadrature error), a
contact stiffness many orders of magnitude away from the body's (the step
matrix is then ill-conditioned, or the contact law irrelevant), a curved
foundation pressed where a symmetry side cuts the built-in "diagonal"
pattern (the pressure at the node there reads several per cent off), and the
material data the discretisation or physics cannot bear (:mod:`.plausibility`:
ν near ½ with P1 elements, a modulus no solid has in the named units);
``adhcontact solve``, ``check`` and ``sweep`` show them. The theory's
smallness conditions (docs/model.md §3) are no warning: they are
sufficient conditions that realistic adhesive scenes miss by orders of
magnitude, so they are recorded (``summary.json``, ``adhcontact check``)
and a run warns only when it shows a reason itself. After a run,
:func:`solution_warnings` says what the result shows: steps whose energy
is not locally strictly convex at the solution found, steps where two
starts reached two solutions, and strains or rotations beyond what the
linear, small-strain model represents.
"""

import numpy as np

from ..fem.foundation import signed_distance
from ..fem.meshes.builtin import SIDES
from ..laws.bonding import BEYOND_TIME_SCALE
from .accuracy import (MEMORY_GUIDE, bonding_time_scale, memory_error, shortest_relaxation_time,
                       steps_for_memory, steps_for_time_scale)
from .damage_lag import DAMAGE_DROP, GLUE_ENERGY_MARGIN, JUMP_RATIO, MAX_REFINEMENT, read_lag
from .plausibility import plausibility_warnings

#: the largest principal strain |ε| the small-strain model is taken to represent
STRAIN_LIMIT = 0.1
#: the largest gap between the linear strain ε(u) and the Green–Lagrange strain
#: ε(u) + ½ ∇uᵀ∇u (its quadratic part; 1 − cos θ for a rotation by θ: 18°)
GREEN_LAGRANGE_GAP = 0.05
#: the share of the body's volume beyond either limit that makes a warning
#: (a single cell at a singular corner or a debonding front makes none)
VOLUME_SHARE = 0.01
#: the orders of magnitude between the contact stiffness and the body's
STIFFNESS_ORDERS = 6


def body_size(problem):
    """The diagonal of the body's bounding box."""
    p = problem.mesh.p
    return float(np.linalg.norm(p.max(axis=1) - p.min(axis=1)))


def gradient_measures(problem, u):
    """Per cell of the P1 displacement ``u`` (npoints, d): the largest
    principal strain |ε|, the rotation angle θ = asin(min(|ω|, 1)) of the
    skew part ω of ∇u (|ω| its axial vector's length), and the largest
    eigenvalue of the quadratic part ½ ∇uᵀ∇u of the Green–Lagrange strain.
    Returns three (ncells,) arrays.

    The eigenvalues are computed only in the cells whose Frobenius bounds
    (|ε| ≤ ‖ε‖_F, λ_max(½ GᵀG) ≤ ½ ‖G‖_F²) exceed STRAIN_LIMIT or
    GREEN_LAGRANGE_GAP; elsewhere the bound is returned, below the limit
    (a run inside them costs two norms per cell and level)."""
    grad_lambda, _ = problem.geometry
    # G_eab = Σ_i u_{t_ie, a} ∂λ_i/∂x_b, a batched product (e, a, i) @ (e, i, b)
    G = np.matmul(u[problem.mesh.t].transpose(1, 2, 0), grad_lambda)   # ∂u_a/∂x_b
    eps = 0.5 * (G + G.transpose(0, 2, 1))
    omega = 0.5 * (G - G.transpose(0, 2, 1))
    rotation = np.arcsin(np.minimum(np.sqrt(0.5 * (omega ** 2).sum(axis=(1, 2))), 1.0))
    strain = np.sqrt((eps ** 2).sum(axis=(1, 2)))
    quadratic = 0.5 * (G ** 2).sum(axis=(1, 2))
    near = strain > STRAIN_LIMIT
    low, high = symmetric_extremes(eps[near])
    strain[near] = np.maximum(np.abs(low), np.abs(high))
    near = quadratic > GREEN_LAGRANGE_GAP
    Gn = G[near]
    quadratic[near] = symmetric_extremes(0.5 * np.matmul(Gn.transpose(0, 2, 1), Gn))[1]
    return strain, rotation, quadratic


def symmetric_extremes(M):
    """The smallest and the largest eigenvalue of each symmetric 2 × 2 or
    3 × 3 matrix of M (n, d, d), in closed form (7 times faster than
    numpy's batched eigvalsh for d = 2, twice for d = 3): for d = 2, m ∓ r with m = tr/2 and
    r = ((M_00 − M_11)²/4 + M_01²)^½; for d = 3 the trigonometric
    solution of the characteristic cubic, q + 2p cos(φ + 2πj/3) with q =
    tr/3, p = (‖M − qI‖_F²/6)^½, φ = acos(det((M − qI)/p)/2)/3."""
    n, d = M.shape[0], M.shape[-1]
    if n == 0:
        return np.zeros(0), np.zeros(0)
    if d == 1:
        return M[:, 0, 0].copy(), M[:, 0, 0].copy()
    if d == 2:
        m = 0.5 * (M[:, 0, 0] + M[:, 1, 1])
        r = np.hypot(0.5 * (M[:, 0, 0] - M[:, 1, 1]), M[:, 0, 1])
        return m - r, m + r
    q = np.trace(M, axis1=1, axis2=2) / 3.0
    shifted = M - q[:, None, None] * np.eye(3)
    p = np.sqrt((shifted ** 2).sum(axis=(1, 2)) / 6.0)
    scaled = shifted / np.where(p > 0, p, 1.0)[:, None, None]
    phi = np.arccos(np.clip(0.5 * np.linalg.det(scaled), -1.0, 1.0)) / 3.0
    return q + 2.0 * p * np.cos(phi + 2.0 * np.pi / 3.0), q + 2.0 * p * np.cos(phi)


#: the most levels the geometry is checked at (evenly spread, the last included)
GEOMETRY_LEVELS = 64


def geometry_warning(solution):
    """A line when, at some level, more than VOLUME_SHARE of the body has
    strains above STRAIN_LIMIT or a linear strain that misses the
    Green–Lagrange strain by more than GREEN_LAGRANGE_GAP (rotations above
    about 18°): what the small-strain model cannot represent."""
    problem = solution.problem
    _, volume = problem.geometry
    total = volume.sum()
    worst = None
    held = solution.levels_with_fields()
    count = held.size
    picks = np.unique(np.round(np.linspace(0, count - 1, min(count, GEOMETRY_LEVELS))))
    for n in held[picks.astype(int)]:   # one level at a time (a streamed u is on disk)
        strain, rotation, quadratic = gradient_measures(problem, solution.displacement(n))
        beyond = (strain > STRAIN_LIMIT) | (quadratic > GREEN_LAGRANGE_GAP)
        share = volume[beyond].sum() / total
        if share > VOLUME_SHARE and (worst is None or share > worst[0]):
            worst = (share, n, strain, rotation, quadratic)
    if worst is None:
        return None
    share, n, strain, rotation, quadratic = worst
    cell = int(np.argmax(np.maximum(strain / STRAIN_LIMIT, quadratic / GREEN_LAGRANGE_GAP)))
    centre = problem.mesh.p[:, problem.mesh.t[:, cell]].mean(axis=1)
    point = "(" + ", ".join(f"{c:.3g}" for c in centre) + ")"
    reasons, cannot = [], []
    if strain.max() > STRAIN_LIMIT:
        reasons.append(f"strains up to {strain.max():.3g} (more than {STRAIN_LIMIT:g})")
        cannot.append("large strains")
    if quadratic.max() > GREEN_LAGRANGE_GAP:
        reasons.append(f"rotations up to {np.degrees(rotation.max()):.0f}°, where the linear "
                       f"strain misses the Green–Lagrange strain by up to "
                       f"{quadratic.max():.3g} (more than {GREEN_LAGRANGE_GAP:g})")
        cannot.insert(0, "finite rotations (a rotated part stretches instead: a lifted arm "
                         "is drawn stretched straight up)")
    return (f"at t = {solution.t[n]:.4g}, {100 * share:.0f}% of the body is beyond the "
            f"small-strain model, with {' and '.join(reasons)}, worst near {point}: the "
            f"model is linear in the displacement and cannot represent "
            f"{' nor '.join(cannot)}; the result is outside its range "
            "(docs/conventions.md#the-model-is-small-strain)")


def step_list(steps, times, most=8):
    """"steps 3–5, 9 (t = 0.3–0.5, 0.9)" for the sorted step numbers ``steps``."""
    runs = []
    for n in steps:
        if runs and n == runs[-1][1] + 1:
            runs[-1][1] = n
        else:
            runs.append([n, n])
    shown = runs[:most]
    numbers = ", ".join(str(a) if a == b else f"{a}–{b}" for a, b in shown)
    at = ", ".join(f"{times[a]:.4g}" if a == b else f"{times[a]:.4g}–{times[b]:.4g}"
                   for a, b in shown)
    more = f" and {len(runs) - most} more ranges" if len(runs) > most else ""
    return f"step{'s' if len(steps) > 1 else ''} {numbers}{more} (t = {at})"


def nonconvex_step_warning(solution):
    """A line naming the steps whose Newton matrix at the solution was
    indefinite and had to be modified (the step energy is not locally
    strictly convex there: the solution found may be a saddle, or one of
    several)."""
    steps = tuple(getattr(solution, "indefinite_steps", ()))
    if not steps:
        return None
    return (f"the step energy is not locally strictly convex at the solution of "
            f"{step_list(steps, solution.t)}: its Newton matrix there was indefinite and "
            "had to be modified, so the solution found may be one of several; softer "
            "contact laws (a smaller friction nonconvexity) or a stiffer body make the "
            "step convex (docs/model.md#the-three-smallness-conditions)")


def two_solutions_warning(solution):
    """A line naming the steps where a second start (z = 0) reached another
    converged solution than the start from the previous level."""
    found = dict(getattr(solution, "two_solution_steps", {}))
    if not found:
        return None
    steps = sorted(found)
    return (f"{step_list(steps, solution.t)} {'have' if len(steps) > 1 else 'has'} "
            f"more than one solution: a second start "
            f"from Γ_C at rest reached another one (differing by up to "
            f"{100 * max(found.values()):.2g}% of the largest contact displacement); "
            "the run follows the one continued from the previous level (the quasistatic "
            "path) (docs/model.md#the-three-smallness-conditions)")


def held_by_contact_warning(problem):
    """A line when only the contact terms hold the body against some rigid
    motion (``problem.held_by_contact``)."""
    motions = getattr(problem, "held_by_contact", ())
    if not motions:
        return None
    return (f"only the contact terms hold the body against {', '.join(motions)}: the "
            f"smallness conditions (which need the held sides to stop every rigid motion) "
            f"do not apply, and a load those terms cannot balance has no equilibrium "
            f"(docs/model.md#a-body-held-by-contact)")


def explicit_bound_warning(problem):
    """A line when the step exceeds the explicit Euler bound of the bonding law."""
    scene = problem.scene
    if (problem.bonding is None or scene.contact.integrator != "explicit"
            or scene.k <= problem.bonding.stable_step()):
        return None
    return (f"the time step k = {scene.k:.4g} exceeds the explicit Euler bound "
            f"1/((gamma_nu + gamma_tau) L^2) = {problem.bonding.stable_step():.4g} of "
            f"the bonding law, so beta may leave [0, 1] and the run stop: use at least "
            f"time.steps = {steps_for_time_scale(problem)} or [time.adaptive] tol; "
            f"{BEYOND_TIME_SCALE} "
            f"(docs/scheme.md#accuracy-guides-of-the-time-step)")


def time_scale_warning(problem):
    """A line when an integrator other than explicit Euler (which has
    :func:`explicit_bound_warning`) runs at a step beyond the bonding law's
    time scale 1/((γ_ν + γ_τ) L²): stable, but the debonding front lags
    (:mod:`.accuracy`)."""
    scale = bonding_time_scale(problem)
    scene = problem.scene
    if scale is None or scene.contact.integrator == "explicit" or scene.k <= scale:
        return None
    return (f"the time step k = {scene.k:.4g} is {scene.k / scale:.3g} times the explicit "
            f"Euler bound 1/((gamma_nu + gamma_tau) L^2) = {scale:.4g} of the bonding law: "
            f"{BEYOND_TIME_SCALE}; use at least time.steps = "
            f"{steps_for_time_scale(problem)}, or [time.adaptive] tol "
            f"(docs/scheme.md#accuracy-guides-of-the-time-step)")


#: the memory's quadrature rule by time.scheme
MEMORY_RULES = {"paper": "right rectangle rule", "second-order": "trapezoidal rule"}


def memory_step_warning(problem):
    """A line when the memory's quadrature at the scene's k puts the stress
    of a strain held from t = 0 off by more than MEMORY_GUIDE at T
    (:func:`.accuracy.memory_error`)."""
    scene = problem.scene
    error = memory_error(scene)
    if error is None or error <= MEMORY_GUIDE:
        return None
    tau = shortest_relaxation_time(scene)
    ratio = "" if tau is None else f", k/tau = {scene.k / tau:.3g} for its shortest tau = {tau:.4g}"
    need = steps_for_memory(scene)
    advice = "" if need is None else f"use at least time.steps = {need}"
    if scene.scheme == "paper" and scene.contact.bonding.law != "cohesive":
        second = memory_error(scene, scheme="second-order")
        advice += (f", or time.scheme = \"second-order\" ({100 * second:.2g} % at this k; "
                   f"second order in k where the contact sets do not switch, not the "
                   f"paper's scheme)")
    return (f"the memory's {MEMORY_RULES[scene.scheme]} at k = {scene.k:.4g}{ratio} puts "
            f"the stress of a strain held from t = 0 off by {100 * error:.2g} % at "
            f"t = T, more than the guide's {100 * MEMORY_GUIDE:g} %"
            + (f": {advice}" if advice else "")
            + " (docs/scheme.md#accuracy-guides-of-the-time-step)")


#: where docs/model.md describes the cohesive damage update and its lag
COHESIVE_DOCS = "docs/model.md#44-the-cohesive-law-law--cohesive-in-both-tables"


def steps_advice(problem, refinement):
    """"use at least time.steps = N'" for steps ``refinement`` times shorter
    (an adaptive run: a smaller tol, its k_max being T/steps)."""
    scene = problem.scene
    if scene.adaptive is not None:
        return (f"steps about {refinement:.3g} times shorter where it debonds (a smaller "
                f"time.adaptive.tol, or more time.steps: k_max = T/steps)")
    return f"use at least time.steps = {int(np.ceil(scene.steps * refinement - 1e-9))}"


def toughness_name(problem):
    """G_c, or max(G_Ic, G_IIc) of a mixed-mode law (:mod:`.damage_lag`, 3)."""
    return "max(G_Ic, G_IIc)" if getattr(problem.normal_law, "mixed", False) else "G_c"


def glue_energy_phrase(problem, energy):
    """"the glue dissipated R × G_c per debonded area (...)"."""
    name = toughness_name(problem)
    return (f"the glue dissipated {energy.ratio:.3g} × {name} per debonded area "
            f"({energy.dissipated:.4g} against {name} ∫(β_0 − β) = "
            f"{energy.toughness_work:.4g} over the glue bonded at t = 0)")


def jump_warning(solution, reading):
    """The line of a jump of the quasi-static path (:func:`.damage_lag.find_jump`):
    where and when, what the run shows of it, why no step count helps and
    what does."""
    jump, problem = reading.jump, solution.problem
    point = "(" + ", ".join(f"{c:.3g}" for c in jump.point) + ")"
    shown = []
    if reading.worst > DAMAGE_DROP:
        shown.append(f"the damage update lost up to {reading.worst:.2g} of a facet's bond in "
                     f"one level at {step_list(reading.drop_levels, solution.t)}")
    ratio = reading.energy.ratio
    if ratio is not None and ratio > 1.0 + GLUE_ENERGY_MARGIN:
        shown.append(glue_energy_phrase(problem, reading.energy))
    return (f"the quasi-static path jumps at step {jump.level} (t = {jump.t:.4g}), or nearly "
            f"does: the glue near {point} opened from {jump.before:.3g} to {jump.after:.3g} in "
            f"that step, {jump.ratio:.3g} times what the loading moved in it, the body "
            f"springing back into a glue that softens faster than the body between it and "
            f"the load can follow; "
            + ("; ".join(shown) + "; " if shown else "")
            + "the cohesive damage update follows a jump one level late, in steps whose "
            "falls of the bond do not shrink with k, so more steps do not silence this (near "
            "a jump, only very many do). Prescribe the opening itself (a displacement at the "
            "crack mouth, next to the glue) or load the glue through a stiffer grip (a stiffer "
            f"or shorter body between the load and the glue) ({COHESIVE_DOCS})")


def damage_drop_warning(solution, reading):
    """The line of falls of β above DAMAGE_DROP in one level along a path
    without a jump, with the steps that bring them below
    (:func:`.damage_lag.steps_for_drop`)."""
    problem = solution.problem
    if np.isfinite(reading.refinement):
        advice = (f"along this run's openings, {steps_advice(problem, reading.refinement)} "
                  f"to keep the falls below {reading.target:.2g} ({DAMAGE_DROP:g}, with a "
                  f"margin for the lag's own error in the openings)")
    else:
        advice = (f"along this run's openings even steps {MAX_REFINEMENT} times shorter leave "
                  f"falls above {reading.target:.2g}: "
                  + steps_advice(problem, float(MAX_REFINEMENT)).replace("at least", "more than"))
    return (f"the cohesive damage update lags the opening by one level and lost up to "
            f"{reading.worst:.2g} of a facet's bond in one level at "
            f"{step_list(reading.drop_levels, solution.t)}, so the peak traction is "
            f"overshot and the glue dissipates more than the toughness (first order in k): "
            f"{advice}{jump_hint(solution, reading)} ({COHESIVE_DOCS})")


def jump_hint(solution, reading):
    """"; the glue near x opened J times ..." when an opening outran the
    loading (J ≥ OPENING_RATIO) without reaching JUMP_RATIO, else ""."""
    fast = reading.fastest
    if fast is None:
        return ""
    problem = solution.problem
    point = "(" + ", ".join(f"{c:.3g}" for c in fast.point) + ")"
    tell = (f"time.steps = {int(np.ceil(problem.scene.steps * reading.steps_to_tell))}"
            if problem.scene.adaptive is None else
            f"steps {reading.steps_to_tell:.3g} times shorter")
    return (f"; at step {fast.level} (t = {fast.t:.4g}) the glue near {point} opened "
            f"{fast.ratio:.3g} times what the loading moved in it, the body springing back "
            f"into it: if the path jumps there, more steps do not silence this, and a run at "
            f"{tell} would show it (more than {JUMP_RATIO:g} times)")


def glue_energy_warning(solution, reading, hint=True):
    """The line of a glue that dissipated more than (1 + GLUE_ENERGY_MARGIN)
    G_c per debonded area along a path without a jump, with the steps that
    bring the excess (first order in k) below the margin; ``hint``: with
    :func:`jump_hint`."""
    problem, energy = solution.problem, reading.energy
    refinement = (energy.ratio - 1.0) / GLUE_ENERGY_MARGIN
    return (f"{glue_energy_phrase(problem, energy)}, more than the {100 * GLUE_ENERGY_MARGIN:g} % "
            f"the one-level lag of the cohesive damage update adds at resolved steps: the "
            f"excess is first order in k and falls faster than k at coarse steps, so "
            f"{steps_advice(problem, refinement).replace('use at least ', '')} brings it "
            f"below{jump_hint(solution, reading) if hint else ''} ({COHESIVE_DOCS})")


def damage_lag_warnings(solution):
    """The lines of :func:`.damage_lag.read_lag` for a run of a rate-independent
    bonding law (the cohesive one): a jump of the quasi-static path, named,
    in place of the others (no step count silences them); else falls of β
    above DAMAGE_DROP in one level and a glue energy above (1 +
    GLUE_ENERGY_MARGIN) G_c per debonded area, each with the steps that
    bring it below."""
    reading = read_lag(solution)
    if reading is None:
        return []
    ratio = reading.energy.ratio
    excess = ratio is not None and ratio > 1.0 + GLUE_ENERGY_MARGIN
    if reading.worst <= DAMAGE_DROP and not excess:
        return []
    if reading.jump is not None:
        return [jump_warning(solution, reading)]
    drops = reading.worst > DAMAGE_DROP
    return ([damage_drop_warning(solution, reading)] if drops else []) \
        + ([glue_energy_warning(solution, reading, hint=not drops)] if excess else [])


def stiffness_warning(problem):
    """A line when the normal compliance stiffness c times the body's size
    lies more than STIFFNESS_ORDERS orders of magnitude from E."""
    c = problem.scene.contact.normal.params.get("c")
    material = problem.scene.material
    E = material.E if material.E is not None else (
        material.mu * (3 * material.lam + 2 * material.mu) / (material.lam + material.mu))
    if c is None or not problem.scene.contact_sides:
        return None
    ratio = c * body_size(problem) / E
    if abs(np.log10(ratio)) <= STIFFNESS_ORDERS:
        return None
    return (f"contact.normal.c = {c:g} times the body's size is {ratio:.1e} times its "
            f"Young's modulus {E:g}: the contact stiffness is more than "
            f"{STIFFNESS_ORDERS} orders of magnitude from the body's "
            + ("(the foundation acts as a wall; the step matrix is ill-conditioned)"
               if ratio > 1 else "(the foundation barely holds the body)"))


#: the closest nodes of Γ_C to a foundation: within this fraction of the
#: body's size of the closest (a cylinder's closest points are a line)
CLOSEST = 1e-9
#: what studies/validation/symmetry_side.py measured at the node on a symmetry
#: side under a rigid cylinder or sphere against Hertz's pressure at the
#: computed force, and the advice, by dimension
SYMMETRY_SIDE_FIGURES = {
    2: ("reads 3.5–9 % off Hertz's pressure at 5–12 elements across the contact "
        "half-width (1.9–2.8 % at 23), where its neighbours read within 2.1 %",
        'use mesh.pattern = "cross", whose cells are mirror-symmetric about every grid '
        "line (that node then reads like the others, within about 2 %), or model the "
        "whole body"),
    3: ("reads 8.7–13.5 % above Hertz's pressure at 3.5–6 elements across the contact "
        "half-width, where the nodes beside the side read within 3 %",
        "model the whole body (the box has no pattern symmetric about its sides)"),
}


def symmetry_sides(scene):
    """The sides of the built-in mesh held along their normal only (rollers:
    the normal component prescribed, every tangential one free), the sides
    a half or quarter model mirrors the body at."""
    names = SIDES[scene.dim]
    out = []
    for side, components in scene.displacement.items():
        if side not in names:
            continue
        axis = names.index(side) // 2
        held = [c is not None for c in components]
        if held[axis] and sum(held) == 1:
            out.append(side)
    return out


def along_axis(foundation, side, dim):
    """Whether the normal of a side of the built-in mesh lies along the axis
    of a cylinder foundation: the pressure does not vary across that side
    (a plane-strain section's ends), so its mirror changes nothing there
    (the box's nodes on it read within 1 % of those mid-length)."""
    if foundation.shape != "cylinder":
        return False
    axis = np.asarray(foundation.axis, dtype=float)
    return abs(axis[SIDES[dim].index(side) // 2]) > (1.0 - 1e-9) * np.linalg.norm(axis)


def symmetry_side_warning(problem):
    """A line when a sphere or cylinder foundation's closest point on Γ_C
    lies on a symmetry side of the built-in "diagonal" pattern (rectangle
    or box).

    A side held along its normal only mirrors the body there: the run is
    the whole body on the mesh and its mirror image, whose cells meet at
    the side in a chevron (the diagonals of the two halves point apart or
    together) where the pattern's own cells continue unchanged. The node
    at the foundation's closest point (Hertz's peak) is then unlike its
    neighbours, and its nodal pressure −F_{a,ν}/w_a reads several per cent
    off Hertz's while theirs do not (:data:`SYMMETRY_SIDE_FIGURES`). The
    "cross" cells are mirror-symmetric about every grid line, so its half
    model is its whole body; a file mesh is left to its maker. A side
    across a cylinder's axis is no such side (:func:`along_axis`)."""
    scene = problem.scene
    contact = scene.contact
    if (scene.mesh.domain == "file" or scene.mesh.pattern != "diagonal"
            or problem.boundary is None or contact is None or contact.foundation is None
            or contact.foundation.shape == "plane"):
        return None
    sides = symmetry_sides(scene)
    if not sides:
        return None
    mesh, nodes = problem.mesh, problem.boundary.nodes
    distance = signed_distance(contact.foundation, mesh.p[:, nodes])
    closest = nodes[distance <= distance.min() + CLOSEST * body_size(problem)]
    on = [side for side in sides if not along_axis(contact.foundation, side, scene.dim)
          and np.isin(closest, mesh.facets[:, mesh.boundaries[side]]).any()]
    if not on:
        return None
    error, advice = SYMMETRY_SIDE_FIGURES[scene.dim]
    named = ", ".join(repr(side) for side in on)
    return (f"the {contact.foundation.shape} foundation's closest point on Γ_C is on the "
            f"symmetry side{'s' if len(on) > 1 else ''} {named} (held along the normal "
            f"only), about which the \"diagonal\" pattern's cells are not mirror-symmetric: "
            f"the contact pressure at the node there {error}; {advice} "
            "(docs/conventions.md#a-symmetry-side-of-the-diagonal-pattern)")


#: the warnings on the uniform step k = T/N; a scene with ``[time.adaptive]``
#: gets none of them: its steps are chosen by its tol and kept below the
#: explicit Euler bound, k = T/N is only the largest
STEP_WARNINGS = (explicit_bound_warning, time_scale_warning, memory_step_warning)


def problem_warnings(problem):
    """The lines of the checks of a scene that apply, before a run."""
    steps = STEP_WARNINGS if problem.scene.adaptive is None else ()
    return [w for w in (held_by_contact_warning(problem),
                        *(warning(problem) for warning in steps),
                        stiffness_warning(problem), symmetry_side_warning(problem))
            if w is not None] + plausibility_warnings(problem.scene)


def solution_warnings(solution):
    """The lines of the checks of a finished run that apply."""
    return [w for w in (nonconvex_step_warning(solution), two_solutions_warning(solution),
                        geometry_warning(solution))
            if w is not None] + damage_lag_warnings(solution)
