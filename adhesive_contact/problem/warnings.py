"""Every warning about a valid scene or a finished run, one line each.

Nothing here raises (refusals are :mod:`.checks`). Before a run,
:func:`problem_warnings` says what the scene's numbers make likely to go
wrong: a step beyond the explicit Euler bound of the bonding law, and a
contact stiffness many orders of magnitude away from the body's (the step
matrix is then ill-conditioned, or the contact law irrelevant);
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

#: the largest displacement allowed, as a fraction of the body's size
DISPLACEMENT_FRACTION = 0.1
#: the orders of magnitude between the contact stiffness and the body's
STIFFNESS_ORDERS = 6


def body_size(problem):
    """The diagonal of the body's bounding box."""
    p = problem.mesh.p
    return float(np.linalg.norm(p.max(axis=1) - p.min(axis=1)))


def largest_displacement(solution):
    """max over levels and nodes of |u| (read one level at a time)."""
    return max((float(np.linalg.norm(solution.u[n], axis=1).max())
                for n in range(solution.t.size)), default=0.0)


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
            "had to be modified, so the solution found may be one of several; more time "
            "steps or a stiffer body near Γ_C make the step convex "
            "(docs/model.md#the-three-smallness-conditions)")


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


def explicit_bound_warning(problem):
    """A line when the step exceeds the explicit Euler bound of the bonding law."""
    scene = problem.scene
    if (problem.bonding is None or scene.contact.integrator != "explicit"
            or scene.k <= problem.bonding.stable_step()):
        return None
    return (f"the time step k = {scene.k:.4g} exceeds the explicit Euler bound "
            f"1/((gamma_nu + gamma_tau) L^2) = {problem.bonding.stable_step():.4g} of "
            f"the bonding law, so beta may leave [0, 1] and the run stop: use more "
            f"steps or another contact.bonding.integrator "
            f"(docs/conventions.md#the-explicit-euler-bound-on-the-time-step)")


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


def displacement_warning(solution):
    """A line when max |u| exceeds DISPLACEMENT_FRACTION of the body's size."""
    size = body_size(solution.problem)
    largest = largest_displacement(solution)
    if largest <= DISPLACEMENT_FRACTION * size:
        return None
    return (f"the largest displacement {largest:.3g} is {100 * largest / size:.0f}% of the "
            f"body's size {size:.3g} (more than {100 * DISPLACEMENT_FRACTION:.0f}%): the "
            "model assumes small strains; the result is outside its range")


def problem_warnings(problem):
    """The lines of the checks of a scene that apply, before a run."""
    return [w for w in (explicit_bound_warning(problem), stiffness_warning(problem))
            if w is not None]


def solution_warnings(solution):
    """The lines of the checks of a finished run that apply."""
    return [w for w in (nonconvex_step_warning(solution), two_solutions_warning(solution),
                        displacement_warning(solution)) if w is not None]
