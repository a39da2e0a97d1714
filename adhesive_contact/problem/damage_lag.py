"""What the one-level lag of the cohesive damage update did to a finished
run, read from the run's own levels (docs/model.md §4.4).

The update β_n = min(β_{n−1}, β*(δ_{n−1})) (:mod:`adhesive_contact.scheme.
bonding.damage`) reads the openings of the previous level, so level n's
bond misses the bond its own opening calls for by the lag error

    e_n = β_n − min(β_n, β*(δ_n)) = β_n − β_{n+1},                     (L.1)

the fall of β at the next level. Along a quasi-static path whose damage
rate is finite e_n ≈ |dβ/dt| k: first order in k. Three readings:

1. **The falls** (:func:`steps_for_drop`). The warning reads the largest
   fall D = max_{n,f} (β_{n−1,f} − β_{n,f}). The steps at which it falls
   below a target are found along the run's own openings, taken linear in
   t within each level (first-order accurate): a run with m times as many
   steps updates β at δ(s), s = j/m in units of this run's levels, so its
   bond is the running minimum

       β̃(s) = min(β_{n−1}, min_{n−1 ≤ s' ≤ s} β*(δ(s'))),            (L.2)

   and its largest fall D̂(m) = max_s [β̃(s) − β̃(s + 1/m)], nonincreasing
   in m, with D̂(1) ≥ D (windows at every offset, not only at the levels)
   and D̂(m) → max |dβ̃/ds| / m, the first-order law, as m → ∞. At a finite
   m it keeps the saturation of β* (a fall is at most the bond left, and
   the bilinear shape loses δ_f x/((1 + x)(δ_f − δ_0)) where the opening
   grows by x δ_0 past δ_0), which is why N·D/0.1 always fell short: a
   uniformly pulled block asked for 168, 259, 513, 839, 989 steps after
   20, 40, 100, 400, 800 and needs 1067; along the openings D̂ asks for
   983 to 1044. The openings themselves carry the lag's first-order
   error: the softening that opens a facet faster acts one level late, so
   where β* is steep a coarse run's openings grow slower than the converged
   ones. One run cannot measure that (it would take a second); on the
   double cantilever beam (150 × 10 cells), which needs 1620 steps, D̂
   asks for 906, 1159, 1116, 1146, 1375, 1551 after 40, 100, 200, 400,
   800, 1384 steps (D = 0.69, 0.56, 0.38, 0.23, 0.16, 0.11): short by
   1.04 to 1.8 times, less than 1 + 2D each time (the delay is one level's
   worth of the fall). The advice aims D̂ at ``DAMAGE_DROP / (1 + 2D)``:
   2284, 2585, 2013, 1756, 1866, 1938 steps there, 2805 to 1299 for the
   block.
2. **A jump** of the quasi-static path (:func:`find_jump`). Where the glue
   softens faster than the body between it and the load can follow (the
   bilinear shape's slope σ_max/(δ_f − δ_0) per area above the body's
   stiffness), no equilibrium near the last one exists past the peak force
   and the opening runs ahead of the load: the path jumps. The lagged
   update follows the jump in a cascade of levels whose falls do not
   shrink with k (at a fixed load each level's opening, found with the bond
   of the one before, damages the glue further). A run shows it as an
   opening that grows in one level by far more than the loading moves,

       J_n = max_f Δδ_{n,f} / ρ_n,   ρ_n = max(|Δg_D,n|_∞, mean_m |Δg_D,m|_∞),   (L.3)

   over the facets past the onset of damage and still bonded at level
   n − 1 (Δδ the facet's r.m.s. effective opening, g_D the held values; a
   run loaded by forces alone takes the contact displacements' mean motion
   per level, mean_m |Δz_m|_∞, for ρ). Without a jump J is the opening's
   rate over the loading's, S/(S − s) for a body of stiffness S on a glue
   softening at s, whatever k: at most 0.18 on the double cantilever beam,
   1.4 on blocks pulled off a glue that softens at a tenth of their
   stiffness or less. At a jump Δδ stays finite while ρ ∝ k, so J grows
   with N: 24, 70, 164, 715, 2080 at 40, 200, 500, 2000, 8000 steps on the
   flat punch of tests/test_damage_lag.py, 1.7, 3.7, 5.9, 7.6, 12.5 at 40,
   200, 400, 800, 1654 on the same punch pulled 100 times faster (∝ N^½
   there). A jump is named when J ≥ :data:`JUMP_RATIO`; a stable path that
   close to one is named too (a block with S/(S − s) ≈ 11: J = 11 from
   400 to 1600 steps, 9.4 at 6400), which is why the line says "or
   nearly". From OPENING_RATIO on, the lines of the other readings say at
   which steps J would pass JUMP_RATIO if it is a jump, (1.2 JUMP_RATIO/J)²
   times the run's.
3. **The glue's energy** (:func:`glue_energy`). A fall of β at fixed
   opening releases (β_{n−1} − β_n) K Ψ(δ_{n−1}) per area (section 6's
   ``debonding``); along a monotone opening the damage D is reached at the
   opening δ(D), where the glue holds ψ(D) = K Ψ(δ(D)), nondecreasing in
   D, so a point that started intact and ends at D_T dissipates
   ∫_0^{D_T} ψ dD ≤ D_T ∫_0^1 ψ dD = D_T G_c. The scheme's sum is an upper
   Riemann sum of it, over by the lag: first order in k without a jump
   (+1.2 % on the double cantilever beam at 3200 steps, +1.3 % on the
   pulled block at 1100), but at a jump the glue takes up the energy the
   body releases (7 to 13 × G_c per area on the flat punch at 200 to 8000
   steps, 956, 57 and 13 × at 40, 400 and 4000 steps pulled fast). The
   ratio R = (the glue's dissipation over the facets bonded at t = 0) /
   (G_c ∫ (β_0 − β_T) over them) is compared with 1 +
   :data:`GLUE_ENERGY_MARGIN`; its excess is first order in k and its
   coefficient falls towards its limit as k does (the pulled block:
   N(R − 1) = 22, 17, 16, 15, 14.5 at 20, 40, 100, 400, 800 steps), so
   N' = ⌈N (R − 1)/margin⌉ brings it below. Mixed mode takes G_c =
   max(G_Ic, G_IIc); facets bonded partly at t = 0 are left out (their
   remaining work per unit of damage can exceed G_c).

Nothing here prints or raises; :mod:`.warnings` words the lines.
"""

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

#: a rate-independent damage update warns when a facet loses more than this
#: fraction of its bond in one level
DAMAGE_DROP = 0.1
#: the glue's dissipation may exceed G_c times the debonded area by this
#: fraction (the lag's excess at resolved steps is 1-2 %) before a run warns
GLUE_ENERGY_MARGIN = 0.1
#: an opening that grows in one level by this many times the loading's
#: motion in it is a jump of the quasi-static path (L.3)
JUMP_RATIO = 10.0
#: an opening that grows in one level by this many times the loading's
#: motion (the body giving energy back to the interface) may be a jump that a
#: run this coarse cannot resolve: the warning says at which steps it would
OPENING_RATIO = 2.0
#: the offsets per level at which the windows of the refined path start (L.2)
SUBLEVELS = 128
#: the most times the run's steps the advice may ask for
MAX_REFINEMENT = 1024
#: a damage ∫ (β_0 − β_T) below this fraction of the glue bonded at t = 0 is
#: round-off, not debonding
ROUND_OFF = 1e-9
#: the levels per block of the openings (bounds the memory to nq times this)
LEVEL_BLOCK = 256
#: the candidate facet-levels per block of (L.2)
CANDIDATE_BLOCK = 4096


@dataclass
class Jump:
    """Where the quasi-static path jumps (L.3): at level ``level`` (time
    ``t``) the facet at ``point`` opened from ``before`` to ``after``,
    ``ratio`` times the loading's motion in that level."""

    level: int
    t: float
    point: np.ndarray
    before: float
    after: float
    ratio: float


@dataclass
class GlueEnergy:
    """The glue's dissipation over the facets bonded at t = 0 (``dissipated``)
    against G_c times their ∫ (β_0 − β_T) (``toughness_work``); ``ratio``
    their quotient (None when nothing debonded)."""

    dissipated: float
    toughness_work: float
    toughness: float

    @property
    def ratio(self):
        return self.dissipated / self.toughness_work if self.toughness_work > 0 else None


@dataclass
class LagReading:
    """The run's falls of β, its jump (or None) and its glue energy."""

    worst: float                # D, the largest fall of β in one level
    drop_levels: tuple          # the levels n whose largest fall exceeds DAMAGE_DROP
    refinement: float           # m: steps m times shorter bring the falls below target
    target: float               # DAMAGE_DROP/(1 + 2D), what the advice aims D̂ at
    jump: Jump                  # a jump of the path (J ≥ JUMP_RATIO), or None
    energy: GlueEnergy
    fastest: Jump = None        # the largest J below JUMP_RATIO, from OPENING_RATIO on

    @property
    def steps_to_tell(self):
        """The factor on the steps at which ``fastest`` would pass JUMP_RATIO
        if it is a jump, or None: J grew as N^0.5 to N^0.9 at the jumps of
        the flat punch, so (1.2 JUMP_RATIO / J)²."""
        return None if self.fastest is None else (1.2 * JUMP_RATIO / self.fastest.ratio) ** 2


def averaging(boundary):
    """P_B as a sparse (nf, nq) matrix: the facet means of point values."""
    fop = boundary.facet_of_point
    return sp.csr_matrix((boundary.weights / boundary.measure[fop],
                          (fop, np.arange(fop.size))), shape=(boundary.facets.size, fop.size))


def level_blocks(count, size=LEVEL_BLOCK):
    """(start, stop) of the blocks of ``count`` levels."""
    return [(a, min(a + size, count)) for a in range(0, count, size)]


def facet_openings(problem, frame_displacement):
    """The r.m.s. openings the update reads, (P_B δ_n²)^½ and (P_B δ_τ²)^½
    per facet and level, two (nf, L) arrays (the second None in mode I or
    without tangential traces), from the contact displacements (L, nc, d)."""
    boundary, law = problem.boundary, problem.bonding
    mean = averaging(boundary)
    levels = frame_displacement.shape[0]
    normal = np.zeros((boundary.facets.size, levels))
    tangential = None
    mixed = bool(boundary.tangential_trace) and getattr(law.normal, "mixed", False)
    if mixed:
        tangential = np.zeros_like(normal)
    for a, b in level_blocks(levels):
        z = np.asarray(frame_displacement[a:b], dtype=float).reshape(b - a, -1).T
        r = boundary.normal_trace @ z                                   # (nq, L)
        normal[:, a:b] = np.sqrt(mean @ np.maximum(-r, 0.0) ** 2)
        if mixed:
            xi2 = sum((t @ z) ** 2 for t in boundary.tangential_trace)
            tangential[:, a:b] = np.sqrt(mean @ xi2)
    return normal, tangential


def glue_energy(problem, beta, frame_displacement):
    """:class:`GlueEnergy`: Σ_n Φ(β_{n−1}, z_{n−1}) − Φ(β_n, z_{n−1}) of the
    contact laws (section 6's ``debonding``, as postprocess/energy.py sums
    it) over the facets with β_0 = 1, against G_c Σ_f |f| (β_{0,f} − β_{T,f})
    over them (module docstring, 3)."""
    boundary, normal = problem.boundary, problem.normal_law
    weights, fop = boundary.weights, boundary.facet_of_point
    nf, levels = boundary.facets.size, beta.shape[0]
    intact = beta[0] >= 1.0 - 1e-12          # P_B of β_0 = 1, to round-off
    per_facet = np.zeros(nf)
    # the friction laws that are potentials of (β, ξ) (a Coulomb bound is none)
    shear = [] if problem.friction is None else [
        law for law in problem.friction.laws if not getattr(law, "pressure_dependent", False)]
    for a, b in level_blocks(levels):
        lo = max(a, 1)
        if lo >= b:
            continue
        z = np.asarray(frame_displacement[lo - 1:b - 1], dtype=float).reshape(b - lo, -1).T
        old, new = beta[lo - 1:b - 1].T[fop], beta[lo:b].T[fop]          # (nq, L)
        r = boundary.normal_trace @ z
        released = normal.potential(old, r) - normal.potential(new, r)
        if shear and boundary.tangential_trace:
            slip = np.sqrt(sum((t @ z) ** 2 for t in boundary.tangential_trace))
            released = released + sum(law.phi(old, slip) - law.phi(new, slip) for law in shear)
        per_facet += np.bincount(fop, weights * released.sum(axis=1), minlength=nf)
    toughness = max(normal.toughness, normal.toughness_shear or 0.0)
    damage = float(boundary.measure[intact] @ (beta[0] - beta[-1])[intact])
    if not damage > ROUND_OFF * float(boundary.measure[intact].sum()):
        damage = 0.0             # no debonding but round-off: no ratio
    return GlueEnergy(float(per_facet[intact].sum()), toughness * damage, toughness)


class RefinedPaths:
    """The openings along two levels' segments, from level n − 2 to n − 1 to
    n, of candidates (level n, facet f), linear in t within each (s in
    units of levels, 0 ≤ s ≤ 2; level −1 has zero opening, u_{−1} = 0),
    and the bond β_{n−1} before them."""

    def __init__(self, law, beta, normal, tangential, levels, facets):
        self.law = law
        self.start = beta[levels - 1, facets]
        self.normal = self.ends(normal, levels, facets)
        self.tangential = None if tangential is None else self.ends(tangential, levels, facets)

    @staticmethod
    def ends(openings, levels, facets):
        padded = np.concatenate([np.zeros((openings.shape[0], 1)), openings], axis=1)
        return np.stack([padded[facets, levels - 1], padded[facets, levels],
                         padded[facets, levels + 1]], axis=1)                   # (c, 3)

    def at(self, ends, s):
        """Openings (c, len(s)) at the positions s."""
        second = s > 1.0
        low = np.where(second, ends[:, 1:2], ends[:, :1])
        high = np.where(second, ends[:, 2:3], ends[:, 1:2])
        frac = np.where(second, s - 1.0, s)
        return low * (1.0 - frac) + high * frac

    def intact(self, s):
        """β* (c, len(s)) of the openings at the positions s."""
        return self.law.target(self.at(self.normal, s),
                               None if self.tangential is None else self.at(self.tangential, s))

    def largest_fall(self, window, offsets):
        """max over the offsets s (≤ 2 − window) of the fall of the running
        minimum (L.2) from s to s + window, per candidate. Within a segment
        the opening is linear and β* monotone in it, so the minimum of β*
        over [s, s + window] is at its ends or at the level between."""
        s = offsets[offsets <= 2.0 - window]
        bond = np.minimum.accumulate(np.minimum(self.intact(s), self.start[:, None]), axis=1)
        later = np.minimum(bond, self.intact(s + window))
        between = (s < 1.0) & (s + window > 1.0)
        later = np.where(between, np.minimum(later, self.intact(np.ones(1))), later)
        return (bond - later).max(axis=1)


def steps_for_drop(law, beta, normal, tangential, target, offsets=SUBLEVELS,
                   finest=MAX_REFINEMENT):
    """m ≥ 1 such that steps m times shorter keep the falls of the
    running minimum (L.2) along the run's openings at most ``target``
    (to 0.1 %); ``inf`` when even ``finest`` times shorter ones do not.

    Only windows of at most one level matter (m ≥ 1); each lies within two
    consecutive levels n, n + 1, so the candidates are the (n, f) whose
    falls at n and n + 1 together exceed the target (:class:`RefinedPaths`),
    their windows starting at ``offsets`` points per level. D̂ is
    nondecreasing in the window: bisection on it."""
    drop = beta[:-1] - beta[1:]                                    # (M, nf), level n = 1..M
    pair = drop + np.concatenate([drop[1:], np.zeros((1, drop.shape[1]))])
    levels, facets = np.nonzero(pair > target)
    if levels.size == 0:
        return 1.0
    levels = levels + 1
    positions = np.linspace(0.0, 2.0, 2 * offsets + 1)
    blocks = [RefinedPaths(law, beta, normal, tangential, levels[a:a + CANDIDATE_BLOCK],
                           facets[a:a + CANDIDATE_BLOCK])
              for a in range(0, levels.size, CANDIDATE_BLOCK)]

    def fall(window):
        return max(float(b.largest_fall(window, positions).max()) for b in blocks)

    low, high = 1.0 / finest, 1.0
    if fall(low) > target:
        return np.inf
    if fall(high) <= target:
        return 1.0
    while high - low > 1e-3 * low:            # fall(low) ≤ target < fall(high)
        mid = 0.5 * (low + high)
        if fall(mid) <= target:
            low = mid
        else:
            high = mid
    return 1.0 / low


def find_jump(problem, t, beta, normal, tangential, frame_displacement):
    """The :class:`Jump` of largest J (L.3) (None when no opening damages a
    bonded facet); a jump of the path when J ≥ JUMP_RATIO."""
    law, boundary = problem.bonding, problem.boundary
    levels = beta.shape[0]
    if levels < 2:
        return None
    effective = normal if tangential is None else np.hypot(normal, tangential)
    intact = law.target(normal.T, None if tangential is None else tangential.T)   # (L, nf)
    # the facets past the onset of damage and still bonded at level n − 1:
    # what they open at level n, their spring-back included
    softening = (beta[:-1] > 0.0) & (intact[:-1] < 1.0)                  # (M, nf)
    growth = np.where(softening, (effective[:, 1:] - effective[:, :-1]).T, 0.0)
    held = problem.prescribed
    grip = np.zeros(levels - 1)
    if held.fixed.size and not held.is_zero:
        values = np.array([held.values(float(s)) for s in t])
        grip = np.abs(np.diff(values, axis=0)).max(axis=1)
    if grip.any():        # the held values move: their motion, a hold at its mean per level
        reference = np.maximum(grip, grip.mean())
    else:                 # a run loaded by forces: the interface's mean motion per level
        z = np.asarray(frame_displacement, dtype=float).reshape(levels, -1)
        reference = np.full(levels - 1, np.abs(np.diff(z, axis=0)).max(axis=1).mean())
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(reference > 0, growth.max(axis=1) / reference, 0.0)
    n = int(np.argmax(ratio))
    if not ratio[n] > 0.0:
        return None
    f = int(np.argmax(growth[n]))
    point = problem.mesh.p[:, boundary.facet_nodes[:, f]].mean(axis=1)
    return Jump(level=n + 1, t=float(t[n + 1]), point=point, before=float(effective[f, n]),
                after=float(effective[f, n + 1]), ratio=float(ratio[n]))


def read_lag(solution):
    """The :class:`LagReading` of a run of a rate-independent bonding law,
    or None (another law, no contact facets, fewer than two levels)."""
    problem = solution.problem
    if (not getattr(problem.bonding, "rate_independent", False) or problem.boundary is None
            or not problem.boundary.facets.size or solution.t.size < 2):
        return None
    beta = np.asarray(solution.beta, dtype=float)
    drop = beta[:-1] - beta[1:]
    per_level = drop.max(axis=1)
    worst = float(per_level.max())
    energy = glue_energy(problem, beta, solution.frame_displacement)
    ratio = energy.ratio
    if worst <= DAMAGE_DROP and (ratio is None or ratio <= 1.0 + GLUE_ENERGY_MARGIN):
        return LagReading(worst, (), 1.0, DAMAGE_DROP, None, energy)
    normal, tangential = facet_openings(problem, solution.frame_displacement)
    fastest = find_jump(problem, np.asarray(solution.t), beta, normal, tangential,
                        solution.frame_displacement)
    jump = fastest if fastest is not None and fastest.ratio >= JUMP_RATIO else None
    if fastest is not None and (jump is not None or fastest.ratio < OPENING_RATIO):
        fastest = None
    target = DAMAGE_DROP / (1.0 + 2.0 * worst)
    refinement = (steps_for_drop(problem.bonding, beta, normal, tangential, target)
                  if worst > DAMAGE_DROP and jump is None else 1.0)
    levels = tuple(int(n) for n in np.flatnonzero(per_level > DAMAGE_DROP) + 1)
    return LagReading(worst, levels, refinement, target, jump, energy, fastest)
