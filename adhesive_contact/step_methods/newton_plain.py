"""Step method "newton-plain": the projected semismooth Newton iteration of
:mod:`.newton` with the full step every iteration, no line search and no
gradient fallback (what many contact codes do), so that its failures can
be seen: on a nonconvex step energy it may cycle between active sets
(MAX_ITERATIONS) or run away (DIVERGED).

The Newton system is the same as in "newton": where S + ∂²Φ is indefinite
its factorisation floors |eigenvalues| (a modified Cholesky), so a step is
always defined; only the globalisation is removed.
"""

from .newton import minimise_step


def minimise(S, c, energy, upper, z0, options, kink=None):
    """The step method interface (:mod:`adhesive_contact.step_methods`)."""
    return minimise_step(S, c, energy, upper, z0, options.tol, options.max_iter, kink,
                         globalised=False)
