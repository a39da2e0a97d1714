"""ParaView time series of a run, at its field levels
(:mod:`.field_levels`), with the fields of ``[output] fields``:
``solution.xdmf`` (+ ``.h5``) with point data u (3 components) and cell
data stress (3 × 3 flattened, the plane strain σ_zz included) and
von_mises; ``contact.xdmf`` (+ ``.h5``) on the
contact facets (only with contact facets), whose points are the facets'
vertices alone (:func:`contact_points`, in increasing mesh index), with
cell data beta and point data u, and at the contact nodes (0 at a clamped
vertex, which carries no contact unknown): traction (global, 3
components), normal_traction (positive in compression),
tangential_traction (nodal tangent frames, padded to 3), u_normal, slip
|u_τ|, on_wall (0/1) and state, an integer: 0 separated, 1 compliance,
2 wall, 3 stick, 4 slip (:func:`adhesive_contact.postprocess.contact_state_code`).
Without h5py the data is written inline in the XDMF files."""

from pathlib import Path

import meshio
from meshio._common import write_xml
import numpy as np

from ..postprocess.quantities import contact_fields, stress_3x3, von_mises
from .h5 import H5File

CELL_TYPES = {2: "triangle", 3: "tetra"}
REOPEN = 100   # levels between reopenings of the HDF5 file
FACET_TYPES = {2: "line", 3: "triangle"}


class _SeriesWriter(meshio.xdmf.TimeSeriesWriter):
    """meshio's XDMF time-series writer with the HDF5 file beside the XDMF.

    meshio 5.3 opens ``Path(filename).stem + ".h5"`` relative to the current
    directory, not to the XDMF file; this writer opens it next to the XDMF
    file (the XDMF refers to it by base name, as the reader expects). It
    also closes and reopens the HDF5 file every ``REOPEN`` levels: HDF5
    keeps about 4 KB per dataset written until the file is closed (meshio
    writes 2–3 datasets a level: +26 MB over 1000 levels, flat with this)."""

    def __enter__(self):
        self.levels = 0
        self.h5 = None
        if self.data_format != "HDF":
            return super().__enter__()
        self.h5_filename = str(self.filename.with_suffix(".h5"))
        self.h5 = H5File(self.h5_filename, "w")   # a full disk raises (io/h5.py)
        self.h5_file = self.h5.file
        return self

    def write_data(self, t, point_data=None, cell_data=None):
        super().write_data(t, point_data=point_data, cell_data=cell_data)
        self.levels += 1
        if self.data_format == "HDF" and self.levels % REOPEN == 0:
            self.h5.close()
            self.h5 = H5File(self.h5_filename, "a")
            self.h5_file = self.h5.file

    def sort_by_time(self):
        """Order the collection's levels by their time: a level written late
        (a peak kept until the run's end) takes its place in the series."""
        grids = list(self.collection)
        grids.sort(key=lambda grid: float(grid.find("Time").get("Value")))
        for grid in list(self.collection):
            self.collection.remove(grid)
        self.collection.extend(grids)

    def __exit__(self, *_):
        """Write the XDMF file, its levels in order of time, and close the
        HDF5 file (both, even when the first raises)."""
        try:
            self.sort_by_time()
            write_xml(self.filename, self.xdmf_file)
        finally:
            if self.h5 is not None:
                self.h5.close()


def data_format():
    """"HDF" when h5py is installed (meshio needs it), else inline "XML"."""
    try:
        import h5py  # noqa: F401
    except ImportError:
        return "XML"
    return "HDF"


def pad_vectors(v):
    """Vectors (..., d) padded with zeros to (..., 3), as ParaView expects."""
    v = np.asarray(v, dtype=float)
    return np.pad(v, [(0, 0)] * (v.ndim - 1) + [(0, 3 - v.shape[-1])])


def contact_facets(problem):
    """Node indices (nf, d) of the contact facets ((0, d) without Γ_C)."""
    if problem.boundary is None:
        return np.zeros((0, problem.dim), dtype=np.int64)
    return problem.boundary.facet_nodes.T.astype(np.int64)


def contact_points(problem):
    """The mesh points of ``contact.xdmf``: the vertices of the contact
    facets, sorted. Writing the contact fields there only, not at every
    mesh point, keeps ``contact.h5`` the size of Γ_C (a 2D strip of 1e5
    dofs, 50 steps: 298 MB of mostly zeros before)."""
    return np.unique(contact_facets(problem))


#: the fields of ``solution.xdmf`` among those of ``output.fields``
BODY_FIELDS = ("u", "stress", "von_mises")


class XdmfSeries:
    """The open time series of one run in ``folder``: :meth:`write` one
    level at a time (anything with ``t``, ``u`` (npoints, d), ``stress``,
    ``stress_zz``, ``beta``, ``contact_force``, ``frame_displacement``,
    ``on_wall`` and ``stuck``, e.g. a :class:`~adhesive_contact.scheme.state.Level`),
    in any order of time, then :meth:`close`. ``fields`` names what is
    written (``output.fields``: ``u``, ``stress`` and ``von_mises`` in
    ``solution.xdmf``, which is left out without any of them, and
    ``contact``, ``contact.xdmf``); ``names`` lists the files."""

    def __init__(self, problem, folder, fields=("u", "stress", "von_mises", "contact")):
        mesh, d = problem.mesh, problem.dim
        self.problem, self.fields = problem, tuple(fields)
        folder = Path(folder)
        fmt = data_format()
        h5 = fmt == "HDF"
        self.names = []
        self.body = None
        if any(name in self.fields for name in BODY_FIELDS):
            self.names += ["solution.xdmf"] + ["solution.h5"] * h5
            self.body = _SeriesWriter(folder / "solution.xdmf", fmt).__enter__()
            self.body.write_points_cells(mesh.p.T, [(CELL_TYPES[d], mesh.t.T)])
        self.contact = None
        if ("contact" in self.fields and problem.boundary is not None
                and problem.boundary.facets.size):
            self.names += ["contact.xdmf"] + ["contact.h5"] * h5
            self.points = contact_points(problem)
            self.contact_nodes = np.searchsorted(self.points, problem.boundary.nodes)
            self.contact = _SeriesWriter(folder / "contact.xdmf", fmt).__enter__()
            self.contact.write_points_cells(
                mesh.p.T[self.points],
                [(FACET_TYPES[d], np.searchsorted(self.points, contact_facets(problem)))])

    def write(self, level):
        u = pad_vectors(level.u)
        if self.body is not None:
            point_data, cell_data = {}, {}
            if "u" in self.fields:
                point_data["u"] = u
            if "stress" in self.fields or "von_mises" in self.fields:
                stress = stress_3x3(level)
                if "stress" in self.fields:
                    cell_data["stress"] = [stress.reshape(-1, 9)]
                if "von_mises" in self.fields:
                    cell_data["von_mises"] = [von_mises(stress)]
            self.body.write_data(float(level.t), point_data=point_data, cell_data=cell_data)
        if self.contact is not None:
            self.contact.write_data(float(level.t),
                                    point_data={"u": u[self.points], **self._nodal(level)},
                                    cell_data={"beta": [np.asarray(level.beta)]})

    def _nodal(self, level):
        """The contact fields of a level at the points of ``contact.xdmf``
        (every vertex of Γ_C is a contact node; along a held component
        the force is the contact laws' there)."""
        gap = getattr(level, "gap", None)
        fields = contact_fields(self.problem, level.contact_force, level.frame_displacement,
                                level.on_wall, level.stuck, gap)
        fields["on_wall"] = np.asarray(level.on_wall, dtype=float)
        out = {}
        for name, values in fields.items():
            values = np.asarray(values, dtype=float)
            if values.ndim == 2:
                values = pad_vectors(values)
            full = np.zeros((self.points.size, *values.shape[1:]))
            full[self.contact_nodes] = values
            out[name] = full
        return out

    def close(self):
        """End both series; the first error is raised once both are closed."""
        error = None
        for writer in (self.body, self.contact):
            if writer is not None:
                try:
                    writer.__exit__(None, None, None)
                except OSError as err:
                    error = error or err
        if error is not None:
            raise error


class _LevelOf:
    """Level n of a solution, as :meth:`XdmfSeries.write` reads it."""

    def __init__(self, solution, n):
        self.n, self.t, self.u, self.beta = n, solution.t[n], solution.u[n], solution.beta[n]
        self.contact_force = solution.contact_force[n]
        self.frame_displacement = solution.frame_displacement[n]
        self.on_wall, self.stuck = solution.on_wall[n], solution.stuck[n]
        self.gap = None if solution.gap is None else solution.gap[n]
        self.stress = solution.stress[n]
        self.stress_zz = None if solution.stress_zz is None else solution.stress_zz[n]


def write_xdmf(solution, folder, levels=None):
    """Write the ParaView time series of a finished solution into ``folder``:
    the fields of its problem's ``output.fields`` at ``levels`` (default:
    every level); return the names of the files written."""
    output = solution.problem.output
    fields = output.fields if output is not None else BODY_FIELDS + ("contact",)
    series = XdmfSeries(solution.problem, folder, fields)
    try:
        for n in (range(solution.t.size) if levels is None else levels):
            series.write(_LevelOf(solution, int(n)))
    finally:
        series.close()
    return series.names
