"""Every warning about a valid scene or a finished run, one line each.

Nothing here raises (refusals are :mod:`.checks`). Before a run,
:func:`problem_warnings` says what the theory does not cover for the scene
(the smallness condition of the error estimate, docs/model.md §3), a step
beyond the explicit Euler bound of the bonding law, and a contact stiffness
many orders of magnitude away from the body's (the step matrix is then
ill-conditioned, or the contact law irrelevant); ``adhcontact solve``,
``check`` and ``sweep`` show them. After a run, :func:`solution_warnings`
says what the result shows: displacements that are not small against the
body (the model is linear, small strain).
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


def smallness_warning(problem):
    """A line when the smallness condition of the error estimate fails."""
    s = problem.smallness
    if s is None or s["holds"]:
        return None
    if s.get("held_by_contact"):
        return (f"only the contact terms hold the body against "
                f"{', '.join(s['held_by_contact'])}: the smallness conditions (which need "
                f"the held sides to stop every rigid motion) do not apply, and a load those "
                f"terms cannot balance has no equilibrium "
                f"(docs/model.md#a-body-held-by-contact)")
    tail = ("each step still has one solution (its energy is convex)"
            if s["step_energy_convex"] else
            "a step may have several solutions and the solver may pick any or fail")
    return (f"the smallness condition of the error estimate does not hold "
            f"(m_A = {s['m_A']:.4g} against (m_tau + m_nu) c_e^2 = {s['rhs']:.4g}): "
            f"the theory does not promise a unique solution or first-order "
            f"convergence here, and {tail}; softer contact laws or a stiffer "
            f"body move the scene inside it "
            f"(docs/model.md#the-three-smallness-conditions)")


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
    return [w for w in (smallness_warning(problem), explicit_bound_warning(problem),
                        stiffness_warning(problem)) if w is not None]


def solution_warnings(solution):
    """The lines of the checks of a finished run that apply."""
    return [w for w in (displacement_warning(solution),) if w is not None]
