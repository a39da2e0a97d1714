"""Which levels of a run get their fields written (``[output] every``).

Every level keeps its scalars (summary.json, scalars.csv, the per-level
arrays of solution.npz); the fields (u, the cell stress, the contact
fields of ParaView) are written at the *field levels*:

- level 0 and every N-th level after it (n ≡ 0 mod N);
- the last level;
- for each reported force, the level where it peaks: the first level of
  largest |value| of each component of each held side's reaction
  (:func:`~adhesive_contact.postprocess.reaction_sides`) and of the total
  normal and tangential contact force (:func:`reported_forces`).

:class:`FieldLevels` decides as a run goes, level by level, without
knowing its end: a level of the grid is written at once; a level that is
the largest so far of some force is kept as a candidate until a later one
passes it, and the candidates left at the end are written then. Fed a
whole run, it gives the same levels (:func:`field_levels`).
"""

import numpy as np


def reported_forces(problem, reaction, contact_force):
    """The forces whose peaks are field levels, flat: (..., m).

    ``reaction`` (..., nD) the supports' force per held dof and
    ``contact_force`` (..., nc, d) the force of Γ_C per contact node in
    the nodal frames, of one level or of several. The entries are each
    held side's reaction components (global), then Σ_a of the normal and
    of each tangential component of the contact force."""
    sides = problem.prescribed.side_reactions(reaction)            # (..., nsides, d)
    parts = [sides.reshape(*sides.shape[:-2], -1)]
    contact_force = np.asarray(contact_force, dtype=float)
    if contact_force.shape[-2]:
        parts.append(contact_force.sum(axis=-2))                   # (..., d)
    return np.concatenate(parts, axis=-1)


class FieldLevels:
    """The field levels of a run, chosen as its levels arrive (module docstring).

    :meth:`offer` each level in turn; :meth:`end` once after the last.
    ``written`` lists the levels written so far, in order of writing."""

    def __init__(self, every):
        self.every = int(every)
        self.written = []
        self.peak = None          # (m,) the largest |force| so far
        self.peak_level = None    # (m,) the first level that reached it
        self.last = None
        self.candidates = set()   # levels kept until a later one passes their peak

    def offer(self, n, forces):
        """Level ``n`` with its :func:`reported_forces` (m,).

        Returns (write, keep, drop): whether to write its fields now,
        whether to keep it as a candidate peak, and the candidate levels
        no force peaks at any more (their kept fields can go)."""
        size = np.abs(np.asarray(forces, dtype=float))
        write = n % self.every == 0
        if self.peak is None:
            self.peak, self.peak_level = size.copy(), np.full(size.shape, n)
            passed = np.ones(size.shape, dtype=bool)
        else:
            passed = size > self.peak
            self.peak = np.where(passed, size, self.peak)
            self.peak_level = np.where(passed, n, self.peak_level)
        if write:
            self.written.append(n)
        peaks = set(self.peak_level.tolist())
        drop = sorted(m for m in self.candidates if m not in peaks)
        self.candidates.difference_update(drop)
        keep = bool(passed.any()) and not write
        if keep:
            self.candidates.add(n)
        self.last = n
        return write, keep, drop

    def end(self):
        """The levels still to write after the last one was offered (the
        last level and the peaks not on the grid), in increasing order;
        they count as written."""
        pending = set(self.candidates)
        if self.last is not None and self.last not in self.written:
            pending.add(self.last)
        pending = sorted(pending)
        self.written.extend(pending)
        self.candidates.clear()
        return pending

    def levels(self):
        """Every field level, in increasing order."""
        return sorted(set(self.written))


def field_levels(problem, reaction, contact_force, every):
    """The field levels of a finished run (:class:`FieldLevels` fed every
    level): an int array, increasing. ``reaction`` (M+1, nD) and
    ``contact_force`` (M+1, nc, d) of every level."""
    chooser = FieldLevels(every)
    forces = reported_forces(problem, reaction, contact_force)
    for n in range(forces.shape[0]):
        chooser.offer(n, forces[n])
    chooser.end()
    return np.array(chooser.levels(), dtype=np.int64)
