"""Magnitude checks of a run: what the model assumes and a result may break.

The model is linear (small strain): displacements must stay small against
the body. A contact stiffness many orders of magnitude away from the body's
makes the step matrix ill-conditioned (or the contact law irrelevant).
Each check returns one line per concern; nothing is raised.
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


def displacement_warning(solution):
    """A line when max |u| exceeds DISPLACEMENT_FRACTION of the body's size."""
    size = body_size(solution.problem)
    largest = largest_displacement(solution)
    if largest <= DISPLACEMENT_FRACTION * size:
        return None
    return (f"the largest displacement {largest:.3g} is {100 * largest / size:.0f}% of the "
            f"body's size {size:.3g} (more than {100 * DISPLACEMENT_FRACTION:.0f}%): the "
            "model assumes small strains; the result is outside its range")


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


def magnitude_warnings(solution):
    """The lines of both checks that apply."""
    return [w for w in (displacement_warning(solution), stiffness_warning(solution.problem))
            if w is not None]
