"""The levels of a convergence study in h, k or both (docs/verification.md).

A study refines a scene level by level — ``"h"``: one uniform (nested)
mesh refinement per level; ``"k"``: the step halved per level; ``"hk"``:
both — and measures at each level the errors of
:mod:`adhesive_contact.verification.errors`, max over the level's time grid,
against

- the scene's exact solution (``reference = "exact"``), or
- a discrete reference run (``"fine"``) refined ``ref_h`` more times in
  space and with ``2**ref_k`` times more steps than the finest level; the
  defaults refine only in what the study varies, so that the other error,
  common to all levels and the reference, cancels.

Their rates are :mod:`adhesive_contact.verification.rates`. Each level
and the reference is a run (the scene built and solved); nothing here is
stored: the study (:mod:`.convergence`) keeps the level records and the
reference and decides what to recompute.
"""

import time
from dataclasses import dataclass, replace

import numpy as np

from ..fem.assembly import stiffness_basis, strain_map
from ..fem.contact_boundary import facet_normals
from ..fem.meshes import mesh_size
from ..problem.build import build_problem
from ..scheme import solve
from ..verification.errors import (
    ExactErrors,
    facet_parents,
    nested_meshes,
    prolongation,
    strain_error_fine,
)

PARAMS = ("h", "k", "hk")


def with_discretisation(scene, refine=None, steps=None):
    """The scene with another mesh refinement and/or number of steps."""
    refine = scene.mesh.refine if refine is None else refine
    steps = scene.steps if steps is None else steps
    return replace(scene, mesh=replace(scene.mesh, refine=refine), steps=steps)


def level_scene(scene, param, level):
    """The scene of one level of a study. With [time.adaptive] a level in k
    halves ``time.adaptive.tol`` instead of the step (k_max stays T/N)."""
    refine = scene.mesh.refine + (level if param in ("h", "hk") else 0)
    if scene.adaptive is not None:
        if param in ("k", "hk"):
            scene = replace(scene, adaptive=replace(scene.adaptive,
                                                    tol=scene.adaptive.tol * 2.0 ** -level))
        return with_discretisation(scene, refine)
    steps = scene.steps * (2 ** level if param in ("k", "hk") else 1)
    return with_discretisation(scene, refine, steps)


def default_reference_refinement(param):
    """(ref_h, ref_k): extra refinements of the reference beyond the finest level.

    Against a reference r refinements finer, a first-order error reads
    C (s_l − s_ref): the last pairwise rate is biased up to
    log2((2 − 2^−r)/(1 − 2^−r)), 1.22 for r = 2 and 1.05 for r = 4. Steps
    are cheap, so k is refined 4 more times; the mesh 2 (16× the cells).
    """
    return (2 if param in ("h", "hk") else 0), (4 if param == "k" else (2 if param == "hk" else 0))


def reference_scene(scene, param, levels, ref_h=None, ref_k=None):
    dh, dk = default_reference_refinement(param)
    ref_h = dh if ref_h is None else ref_h
    ref_k = dk if ref_k is None else ref_k
    finest = level_scene(scene, param, levels - 1)
    if finest.adaptive is not None:   # uniform, of step k_min 2^(4 − ref_k) (k_min by default)
        halvings = max(finest.adaptive.halvings + ref_k - 4, 0) if param != "h" else 0
        return with_discretisation(replace(finest, adaptive=None), finest.mesh.refine + ref_h,
                                   finest.steps * 2 ** halvings)
    return with_discretisation(finest, finest.mesh.refine + ref_h, finest.steps * 2 ** ref_k)


@dataclass
class Reference:
    """A fine discrete solution: its scene and the history its errors need.

    ``u`` and ``beta`` hold the reference levels ``kept`` (increasing; None:
    every level n = 0..N): :meth:`level_u` and :meth:`level_beta` read a
    level by its index n."""

    scene: object
    t: np.ndarray        # (N+1,) every level's time
    u: np.ndarray        # (len(kept), npoints, d)
    beta: np.ndarray     # (len(kept), nf)
    facets: np.ndarray   # contact facets of the fine mesh, in Γ_C order
    seconds: float
    quantities: dict = None   # its scalar quantities (postprocess.scalars), None if not kept
    kept: np.ndarray = None   # the levels u and beta hold, None: every level

    def _position(self, n):
        if self.kept is None:
            return n
        position = int(np.searchsorted(self.kept, n))
        if position == len(self.kept) or self.kept[position] != n:
            raise ValueError(f"the reference keeps no level {n}")
        return position

    def level_u(self, n):
        """u of reference level n."""
        return self.u[self._position(n)]

    def level_beta(self, n):
        """β of reference level n."""
        return self.beta[self._position(n)]


def needed_levels(scene, param, levels, reference):
    """The reference levels the errors of a study's levels read (None:
    every one). A uniform level of N_l steps reads the reference at its
    t_n = n T/N_l, the levels n·(N_ref/N_l); the finest level's steps divide
    every other's, so those of the finest are all (a k-study with the
    default 16 times the finest steps keeps one level in 16). An adaptive
    level's times are known only once it runs: every level is kept."""
    finest = level_scene(scene, param, levels - 1)
    if finest.adaptive is not None or reference.adaptive is not None:
        return None
    ratio = reference.steps // finest.steps
    if ratio * finest.steps != reference.steps or ratio == 1:
        return None
    return np.arange(0, reference.steps + 1, ratio)


def run_reference(scene, param, levels, ref_h=None, ref_k=None, progress=None, measure=None):
    """Solve the reference run of a study (``progress(n, N)`` per step);
    ``measure(solution)``, optional, gives its ``quantities`` (a dict). The
    Reference keeps the levels its errors read (:func:`needed_levels`)."""
    ref = reference_scene(scene, param, levels, ref_h, ref_k)
    t0 = time.perf_counter()
    problem = build_problem(ref)
    solution = solve(problem, progress, raise_on_failure=True)
    facets = problem.boundary.facets if problem.boundary is not None else np.zeros(0, int)
    quantities = None if measure is None else measure(solution)
    seconds = time.perf_counter() - t0
    kept = needed_levels(scene, param, levels, ref)
    u, beta = solution.u, solution.beta
    if kept is not None:
        u, beta = np.ascontiguousarray(u[kept]), np.ascontiguousarray(beta[kept])
    return Reference(ref, solution.t, u, beta, facets, seconds, quantities, kept)


def _errors_against_reference(problem, solution, reference):
    """Per level t_n of the level's grid: (e_u, e_β, ‖ε(u_ref)‖, ‖β_ref‖), the
    norms those of the reference at t_n, all on the reference's mesh."""
    scene = problem.scene
    meshes = nested_meshes(scene.mesh, reference.scene.mesh.refine - scene.mesh.refine)
    fine = meshes[-1]
    P = prolongation(meshes)
    B = strain_map(stiffness_basis(fine))
    if scene.adaptive is None:
        ratio = reference.scene.steps // scene.steps
        if ratio * scene.steps != reference.scene.steps:
            raise ValueError("the reference steps are not a multiple of the level's steps")
        at = [((n * ratio, 1.0),) for n in range(scene.steps + 1)]
    else:   # an adaptive level's t_n: the reference interpolated linearly in time
        at = reference_at(solution.t, reference.scene.k, reference.scene.steps)
    parents = None
    if problem.boundary is not None and problem.boundary.facets.size:
        parents = facet_parents(meshes, problem.boundary.facets, reference.facets)
    lengths = _facet_lengths(fine, reference.facets)
    err_u, err_b, norm_u, norm_b = [], [], [], []
    for n, weights in enumerate(at):
        ref_u = _combine(reference.level_u, weights)
        uf = P @ solution.u[n]                                   # (npoints_f, d)
        du = (uf - ref_u).ravel()
        err_u.append(strain_error_fine(fine, B, du))
        norm_u.append(strain_error_fine(fine, B, ref_u.ravel()))
        if parents is None:
            err_b.append(0.0)
            norm_b.append(0.0)
        else:
            ref_beta = _combine(reference.level_beta, weights)
            db = solution.beta[n][parents] - ref_beta
            err_b.append(float(np.sqrt(np.sum(lengths * db * db))))
            norm_b.append(float(np.sqrt(np.sum(lengths * ref_beta * ref_beta))))
    return np.array(err_u), np.array(err_b), np.array(norm_u), np.array(norm_b)


def reference_at(t, k, steps):
    """Per time of ``t`` the reference levels and weights that interpolate a
    uniform reference (step ``k``, ``steps`` steps) linearly there:
    ((m, 1),) where t is a reference level, else ((m, 1 − w), (m + 1, w))."""
    out = []
    for s in np.asarray(t, dtype=float) / k:
        m = int(np.floor(s + 1e-9))
        w = s - m
        out.append(((min(m, steps), 1.0),) if abs(w) <= 1e-9 or m >= steps
                   else ((m, 1.0 - w), (m + 1, w)))
    return out


def _combine(level, weights):
    """Σ w_i level(m_i) (the level itself for one weight 1)."""
    if len(weights) == 1:
        return level(weights[0][0])
    (m0, w0), (m1, w1) = weights
    return w0 * level(m0) + w1 * level(m1)


def _facet_lengths(mesh, facets):
    if len(facets) == 0:
        return np.zeros(0)
    return facet_normals(mesh, facets)[1]


def _errors_against_exact(problem, solution):
    """Per level t_n: (e_u, e_β, ‖ε(u*)‖, ‖β*‖), each norm with the
    quadrature of its error (the error of a zero field)."""
    exact = problem.exact
    errors = ExactErrors(problem, exact.strain,
                         exact.beta if problem.boundary is not None else None)
    err_u = np.array([errors.strain(solution.u[n].ravel(), t)
                      for n, t in enumerate(solution.t)])
    err_b = np.array([errors.bonding(solution.beta[n], t)
                      for n, t in enumerate(solution.t)])
    zero_u, zero_b = np.zeros_like(solution.u[0]).ravel(), np.zeros_like(solution.beta[0])
    norm_u = np.array([errors.strain(zero_u, t) for t in solution.t])
    norm_b = np.array([errors.bonding(zero_b, t) for t in solution.t])
    return err_u, err_b, norm_u, norm_b


def relative(error, norm):
    """max_n error(t_n) / max_n norm(t_n): an error relative to the size of
    the solution over the time grid (NaN when that size is 0). The maxima
    are taken apart so that a solution that starts at 0 (u(0) = 0) does
    not divide by 0 at t_0."""
    size = float(np.max(norm))
    return float(np.max(error)) / size if size > 0 else float("nan")


def run_level(scene, param, level, reference=None, progress=None, measure=None):
    """Solve one level and measure its errors: a JSON-able record.

    ``reference`` is a :class:`Reference`, or None to use the scene's exact
    solution; ``progress(n, N)`` is called per step. ``seconds`` is the
    wall time of building the problem and solving it (errors excluded):
    ``stepping_seconds`` of the time loop and ``setup_seconds`` of the rest
    (mesh, assembly, loads, factorisations, Schur complements).

    Errors, with u, β the exact solution or the reference (docs/verification.md):
    ``err_u`` = max_n ‖ε(u(t_n)) − ε(u_h^n)‖_{L²(Ω)}, ``err_beta`` =
    max_n ‖β(t_n) − β_h^n‖_{L²(Γ_C)}, ``E`` = max_n of their sum; and each
    relative to the same norm of u, β (:func:`relative`): ``rel_u`` =
    err_u / max_n ‖ε(u(t_n))‖, ``rel_beta`` = err_beta / max_n ‖β(t_n)‖,
    ``rel_E`` = E / max_n (‖ε(u(t_n))‖ + ‖β(t_n)‖). ``h`` is the largest
    edge length of the level's mesh (its largest cell diameter), ``k`` = T/N.
    With ``measure``, a callable of the solution giving a dict of scalars
    (the studies pass
    :func:`~adhesive_contact.postprocess.scalars.scalar_quantities`), the
    record has them as ``quantities``, from which a study of a quantity
    measures |Q_h − Q_ref|.
    """
    lscene = level_scene(scene, param, level)
    t0 = time.perf_counter()
    problem = build_problem(lscene)
    solution = solve(problem, progress, raise_on_failure=True)
    seconds = time.perf_counter() - t0
    if reference is None:
        if problem.exact is None:
            raise ValueError("the scene has no [exact] solution; use a fine reference")
        err_u, err_b, norm_u, norm_b = _errors_against_exact(problem, solution)
    else:
        err_u, err_b, norm_u, norm_b = _errors_against_reference(problem, solution, reference)
    E = err_u + err_b
    # adaptive: the accepted steps M and their mean T/M
    steps = lscene.steps if lscene.adaptive is None else solution.steps
    record = {
        "level": level, "h": mesh_size(problem.mesh), "k": lscene.T / steps,
        "dofs": int(problem.ndofs), "steps": steps, "refine": lscene.mesh.refine,
        "err_u": float(err_u.max()), "err_beta": float(err_b.max()), "E": float(E.max()),
        "rel_u": relative(err_u, norm_u), "rel_beta": relative(err_b, norm_b),
        "rel_E": relative(E, norm_u + norm_b),
        "seconds": seconds, "setup_seconds": seconds - solution.timings["stepping"],
        "stepping_seconds": solution.timings["stepping"],
        "newton_iterations": int(solution.iterations.sum()),
    }
    if solution.adaptive is not None:
        record["adaptive"] = {key: solution.adaptive[key] for key in (
            "tol", "accepted_steps", "rejected_pairs", "forced_pairs", "step_solves")}
    if measure is not None:
        record["quantities"] = measure(solution)
    return record
