"""What debonded, and where the debond front is (docs/model.md §6.3).

With β_f the P0 bonding of contact facet f and |f| its measure (a length
in 2D, per unit thickness; an area in 3D):

- the debonded area A_½ = Σ_f |f| [β_f < ½], and the damage integral
  A_D = ∫_{Γ_C} (1 − β) = Σ_f |f| (1 − β_f) (β_0 = 1: the area that would
  have debonded if the damage were gathered in one place);
- those of the run alone, a pre-crack (β_0 < ½) left out:
  A_½^new = Σ_f |f| [β_f < ½ ≤ β_{0,f}] and ∫_{Γ_C} (β_0 − β);
- the glue's dissipated energy per unit area the run debonded,
  D^b_n / A_½^new and D^b_n / ∫ (β_0 − β), D^b the debonding dissipation
  of :mod:`.energy`;
- the debond front: where β crosses ½ between two adjacent facets (sharing
  a vertex in 2D, an edge in 3D), placed by linear interpolation of β
  between their midpoints.

All functions are vectorised over the levels and facets.
"""

import numpy as np


def debonded_area(solution, threshold=0.5):
    """(A_½, A_D) per level: the measure of the facets with β < ``threshold``
    and ∫_{Γ_C} (1 − β). Two (M+1,) arrays (zeros without contact facets)."""
    boundary = solution.problem.boundary
    if boundary is None or boundary.facets.size == 0:
        zeros = np.zeros(solution.t.size)
        return zeros, zeros.copy()
    beta = np.asarray(solution.beta)
    return (beta < threshold) @ boundary.measure, (1.0 - beta) @ boundary.measure


def new_debonding(solution):
    """(debonded, damage) per level (M+1,): the measure of the facets that
    debonded during the run (β_f < ½, β_{0,f} ≥ ½) and ∫_{Γ_C} (β₀ − β).
    Zeros without contact facets."""
    boundary = solution.problem.boundary
    if boundary is None or boundary.facets.size == 0:
        zeros = np.zeros(solution.t.size)
        return zeros, zeros.copy()
    beta = np.asarray(solution.beta)
    beta0 = np.asarray(solution.problem.beta0)
    debonded = ((beta < 0.5) & (beta0 >= 0.5)) @ boundary.measure
    return debonded, (beta0 - beta) @ boundary.measure


def adjacent_facets(problem):
    """Pairs (2, npairs) of contact facets that share a vertex (2D) or an
    edge (3D)."""
    nodes = problem.boundary.facet_nodes                 # (d, nf)
    d, nf = nodes.shape
    if d == 2:
        keys = nodes.T.reshape(-1, 1)                    # the vertices
        owner = np.repeat(np.arange(nf), 2)
    else:
        edges = np.stack([nodes[[0, 1]], nodes[[1, 2]], nodes[[2, 0]]], axis=1)  # (2, 3, nf)
        keys = np.sort(edges, axis=0).reshape(2, -1).T   # (3 nf, 2), edge (a < b)
        owner = np.tile(np.arange(nf), 3)
    _, inverse = np.unique(keys, axis=0, return_inverse=True)
    inverse = inverse.ravel()
    order = np.argsort(inverse, kind="stable")
    same = inverse[order][1:] == inverse[order][:-1]
    # a vertex or edge shared by exactly two facets gives one pair
    return np.stack([owner[order][:-1][same], owner[order][1:][same]])


def debond_front(problem, beta, threshold=0.5, pairs=None):
    """The points (npoints, d) where β of one level (nf,) crosses
    ``threshold`` between adjacent contact facets."""
    pairs = adjacent_facets(problem) if pairs is None else pairs
    beta = np.asarray(beta, dtype=float)
    a, b = pairs
    crossing = (beta[a] - threshold) * (beta[b] - threshold) < 0
    a, b = a[crossing], b[crossing]
    mid = problem.mesh.p[:, problem.boundary.facet_nodes].mean(axis=1)   # (d, nf)
    s = (threshold - beta[a]) / (beta[b] - beta[a])
    return (mid[:, a] + s * (mid[:, b] - mid[:, a])).T


def debond_fronts(solution, threshold=0.5):
    """:func:`debond_front` at every level: a list of (npoints, d) arrays
    (empty lists without contact facets)."""
    problem = solution.problem
    boundary = problem.boundary
    if boundary is None or boundary.facets.size == 0:
        return [np.zeros((0, problem.dim)) for _ in solution.t]
    pairs = adjacent_facets(problem)
    return [debond_front(problem, beta, threshold, pairs) for beta in solution.beta]


def energy_per_area(dissipated, area):
    """``dissipated / area`` per level, NaN where the area is 0."""
    area = np.asarray(area, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(area > 0, np.asarray(dissipated) / np.where(area > 0, area, 1.0),
                        np.nan)
