"""``scalars.csv``: one row per level of a run, one column per scalar
(:mod:`adhesive_contact.postprocess.level_scalars`), written whatever
``[output] every`` and ``fields`` say.

A column's name carries its unit in brackets where ``[output.units]``
names it (``reaction_right_y [N/mm]``; :mod:`adhesive_contact.postprocess.units`);
floats are written exactly (:func:`adhesive_contact.storage.write_csv`).
"""

import numpy as np

from ..postprocess.units import with_unit
from ..storage import write_csv


def column_names(problem, columns):
    """The header of scalars.csv: each column's name with its unit."""
    units = problem.output.units if problem.output is not None else problem.scene.units
    return [with_unit(c.name, c.kind, units, problem.dim) for c in columns]


def write_scalars_csv(path, problem, columns):
    """Write ``scalars.csv`` of ``columns`` (a list of
    :class:`~adhesive_contact.postprocess.level_scalars.Column`) at ``path``."""
    values = np.column_stack([np.asarray(c.values, dtype=float) for c in columns]) \
        if columns else np.zeros((0, 0))
    rows = ([int(v) if c.kind == "count" else float(v) for c, v in zip(columns, row)]
            for row in values)
    write_csv(path, column_names(problem, columns), rows)
