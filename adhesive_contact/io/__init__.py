"""Files of a run, as scikit-fem keeps its own in ``skfem.io``.

- :mod:`.xdmf`: the ParaView time series (XDMF + HDF5) of the body and of
  the contact facets, written level by level;
- :mod:`.npz`: ``solution.npz``, written without holding the history;
- :mod:`.streaming`: :class:`StreamingRecorder`, a recorder for
  :func:`adhesive_contact.solve` that writes each level to those files as it
  is computed and keeps in memory only what is small (per contact node or
  facet, per probe): the memory of a run is flat in the number of steps;
- :mod:`.summary`: ``summary.json``, written and read (its one schema);
- :mod:`.folder`: :func:`write_outputs`, a whole output folder written as
  ``adhcontact solve`` writes it (staged, published whole);
- :mod:`.load`: :func:`load_solution`, an output folder read back as the
  Solution that ``solve`` returns.
"""

from .errors import OutputFolderError
from .folder import write_outputs
from .load import load_solution
from .npz import write_npz
from .streaming import StreamingRecorder
from .xdmf import XdmfSeries, write_xdmf

__all__ = ["OutputFolderError", "StreamingRecorder", "XdmfSeries", "load_solution",
           "write_npz", "write_outputs", "write_xdmf"]
