"""What a scene will need, estimated from the scene alone (nothing built).

A scene can ask for more than the machine has: a mesh whose factors do
not fit in memory, more time steps than a day holds, a history of every
level larger than the disk. :func:`estimate` counts, from the scene's
numbers only (before any mesh exists), the nodes, dofs, cells, contact
nodes and unknowns, and the time levels, picks the linear backend the run
would use (:func:`~adhesive_contact.linear_solvers.choose` for ``auto``),
and estimates

- memory: the process itself and the working memory of assembly, the
  per-mesh operators (K_λ, K_μ, the strain map: about four
  matrices of the step matrix's pattern), the factors of the step matrix
  (:func:`~adhesive_contact.linear_solvers.factor_bytes`; about three
  copies of the pattern for AMG), the dense Schur complement on the
  contact unknowns (m² doubles, and from 1000 unknowns on its single
  precision copy and two of a Newton system's), and what grows with the
  steps: u at every level (kept for the outputs; a second copy for a
  function kernel's history sum), β per contact facet and the gap per
  contact node at every level;
- time: the set-up (assembly and factorisation) and N steps, each two
  solves with the factors plus a few dense Newton solves on the contact
  unknowns (and, for a function kernel, a history sum over all previous
  levels); with AMG and contact, where the Newton systems are those of
  all free dofs, the hierarchy and a cost per dof and step measured on
  the benchmark;
- disk: the outputs (u and the cell stress per level in solution.h5, u
  in solution.npz).

The constants are rough (order of magnitude) and err on the high side;
:func:`refusal` says when an estimate exceeds what the machine has
(available memory, free disk) or a time limit.
"""

import math
import os
import shutil
from dataclasses import asdict, dataclass

from .fem.meshes.builtin import nodes_of
from .linear_solvers import choose, factor_bytes
from .scene import SceneError
from .scheme.operators import FULL_SYSTEM

#: stored entries per node of a P1 stiffness row block, per component pair
#: (neighbours + 1: 7 on the structured triangle meshes, 15 on the tetrahedra)
PATTERN = {2: 7, 3: 15}
#: cells per structured quadrilateral / hexahedron of the unrefined mesh
CELLS_PER_BLOCK = {("rectangle", "diagonal"): 2, ("rectangle", "cross"): 4,
                   ("box", "diagonal"): 6}
BYTES_PER_ENTRY = 12          # a double and an index of a sparse entry
#: measured on this code (PARDISO, studies/bench/ladder.py): about 1.2 µs
#: per dof for the two solves of a step at 1e5 dofs; set-up (assembly and
#: factorisation) 10–15 µs per dof in 2D (1e5–1e6 dofs), 35 µs at 1e4 and
#: 70 µs at 1.1e5 in 3D, where a factorisation's work per dof grows (the
#: ladder fits set-up ~ n^1.24–1.5): rounded up, the 3D one grown like
#: n^(1/3) from 1e5 dofs
SECONDS_PER_DOF_STEP = 2e-6
SECONDS_PER_DOF_SETUP = {2: 3e-5, 3: 1.5e-4}
SETUP_GROWTH = {2: 0.0, 3: 1.0 / 3.0}
#: seconds per dof and contact unknown of forming S with AMG-CG (measured
#: 3.3–3.6e-6 at 1e4 dofs, 2D and 3D), rounded up: for the "optimizer"
#: step method, the one that needs S with AMG
AMG_SCHUR_SECONDS = 1e-5
#: AMG with contact (Newton on all free dofs, adhesive_contact.scheme.full_system),
#: measured on the 3D full model of studies/bench/ladder.py: set-up (assembly
#: and hierarchy) 5.2e-5 s per dof at 1e6 dofs; a step 2.1e-5 s per dof at
#: 1.1e5 dofs and 3e-5 at 1e6 (12–20 Newton iterations a step); rounded up
AMG_SECONDS_PER_DOF_SETUP = 1e-4
AMG_SECONDS_PER_DOF_STEP = 4e-5
SECONDS_PER_STEP = 5e-3       # the Python work of a step and its Newton iterations
#: dense Newton solves on the contact unknowns: measured 1.3e11 (2D, 4000
#: unknowns) to 2.3e11 (3D, 6336) flop/s in effect, in single precision on
#: two threads (studies/bench/ladder.py); a tenth of that, since a step
#: takes up to 13 iterations against the NEWTON_ITERATIONS counted
FLOPS = 2e10
#: the process with its libraries loaded, and the working memory of assembly
#: per dof (mesh, quadrature arrays, boundary): measured peak resident memory
#: 100 MB at 1e3 dofs, 270–470 MB at 2.6e4–6.6e4 dofs (2D, PARDISO)
BASE_BYTES = 150e6
BYTES_PER_DOF = 4000
#: bytes per m² of the dense Schur complement S (8), its single-precision
#: copy (4) and the two single-precision copies a Newton system takes (8)
DENSE_BYTES = 20
NEWTON_ITERATIONS = 5         # per step, for the dense part of the estimate
DAY = 86400.0


@dataclass(frozen=True)
class Estimate:
    """The size of a run and what it is expected to need (bytes, seconds)."""

    nodes: int
    dofs: int
    cells: int
    contact_nodes: int
    contact_unknowns: int
    levels: int
    backend: str
    backend_reason: str
    memory_bytes: float
    seconds: float
    disk_bytes: float
    #: with [time.adaptive]: the levels, seconds and output when every step
    #: is at k_min (N 2^J + 1 levels, three step solves a pair); the figures
    #: above are then those of the uniform grid k_max, the fewest levels
    levels_at_most: int = None
    seconds_at_most: float = None
    disk_bytes_at_most: float = None

    def record(self):
        """The estimate as a JSON-able dict."""
        return asdict(self)

    def describe(self):
        """One phrase: the size and the estimated memory, time and disk."""
        text = (f"{self.dofs:.3g} dofs, {self.contact_unknowns:.3g} contact unknowns, "
                f"{self.levels:.3g} time levels, {self.backend}: about "
                f"{_bytes(self.memory_bytes)} of memory, {_duration(self.seconds)}, "
                f"{_bytes(self.disk_bytes)} of output")
        if self.levels_at_most is not None:
            text += (f"; adaptive steps: at most {self.levels_at_most:.3g} levels, "
                     f"{_duration(self.seconds_at_most)} and "
                     f"{_bytes(self.disk_bytes_at_most)} of output if every step is at k_min "
                     "(the run checks its pace as it goes)")
        return text


def _bytes(n):
    return f"{n / 1e9:.3g} GB" if n >= 1e8 else f"{n / 1e6:.3g} MB"


def _duration(seconds):
    if seconds >= DAY:
        return f"{seconds / DAY:.3g} days"
    if seconds >= 3600:
        return f"{seconds / 3600:.3g} h"
    return f"{seconds:.3g} s"


def _contact_nodes(scene):
    """Nodes on the contact sides (corners shared by two sides counted twice)."""
    if not scene.has_contact_terms:
        return 0
    n = [c * 2**scene.mesh.refine for c in scene.mesh.cells]
    axis = {"left": 0, "right": 0, "bottom": 1, "top": 1, "front": 2, "back": 2}
    return sum(math.prod(m + 1 for i, m in enumerate(n) if i != axis[side])
               for side in scene.contact_sides)


def _file_counts(scene):
    """(nodes, cells, contact nodes) of a file mesh after its refinements: the
    file's own counts (read by meshio, not built) times 2^d per refinement;
    the contact nodes bounded by a boundary's share, nodes^((d−1)/d) per side."""
    from .fem.meshes.gmsh_file import MeshFileError, _read

    d, spec = scene.dim, scene.mesh
    try:
        data = _read(spec.path)
    except MeshFileError as err:
        raise SceneError("mesh.file", str(err)) from None
    growth = (2**d) ** spec.refine
    nodes = len(data.points) * growth
    cells = sum(len(block.data) for block in data.cells
                if block.dim == d) * growth
    contact = (len(scene.contact_sides) * round(nodes ** ((d - 1) / d))
               if scene.has_contact_terms else 0)
    return nodes, cells, contact


#: peak memory of reading a mesh file over its size (meshio, a 72 MB gmsh 2.2
#: ASCII file of 4.9e5 nodes: 340 MB above the interpreter's, 4.7 times)
MESH_READ_FACTOR = 5


def mesh_file_refusal(scene, memory=None):
    """Why a scene's mesh file is too large to read here (None when it is
    not, or the mesh is not a file): its size times
    :data:`MESH_READ_FACTOR` against ``memory`` (default
    :func:`available_memory`), checked before the file is opened."""
    if scene.mesh.domain != "file":
        return None
    try:
        size = os.stat(scene.mesh.path).st_size
    except OSError:
        return None   # the reader names it
    memory = available_memory() if memory is None else memory
    if memory is not None and size * MESH_READ_FACTOR > memory:
        return (f"the mesh file is {_bytes(size)}; reading it takes about "
                f"{_bytes(size * MESH_READ_FACTOR)}, {_bytes(memory)} available")
    return None


def estimate(scene, memory_limit=None, counts=None):
    """The :class:`Estimate` of a run of ``scene`` (see the module docstring).

    ``memory_limit`` is passed to the backend choice for ``linear = "auto"``
    (default: its own, half the physical memory). ``counts`` (nodes,
    cells, contact nodes, contact unknowns) of the mesh once built replace
    those estimated from the scene (:func:`built_counts`)."""
    d, spec = scene.dim, scene.mesh
    if counts is not None:
        nodes, cells, contact_nodes, unknowns = counts
    else:
        if spec.domain == "file":   # read off the file; refinement ×2^d (nodes ≈ cells/2^(d-1))
            nodes, cells, contact_nodes = _file_counts(scene)
        else:
            nodes = nodes_of(spec.cells, spec.refine, spec.pattern)
            cells = (CELLS_PER_BLOCK[(spec.domain, spec.pattern)] * math.prod(spec.cells)
                     * (2**d) ** spec.refine)
            contact_nodes = _contact_nodes(scene)
        # the normal component per contact node, and the tangential ones with friction
        unknowns = (d if scene.contact is not None and scene.contact.friction
                    else 1) * contact_nodes
    dofs = d * nodes
    nnz = d * d * PATTERN[d] * nodes
    levels = scene.steps + 1
    backend = scene.solver.linear
    reason = f"method {backend!r} was asked for."
    newton = unknowns if scene.solver.method in FULL_SYSTEM else 0
    if backend == "auto":
        backend, reason = choose(dofs, nnz, d, memory_limit, contact_unknowns=newton)
    # with AMG and contact, Newton on all free dofs: no dense S, but the
    # hierarchy, the copies of its level matrices that the contact terms
    # update and their lookup keys (the 3D ladder at 1e6 dofs peaked at
    # 9.2 GB with friction, 11.6 GB frictionless: 12 copies of the pattern
    # cover both)
    full_system = backend == "amg" and newton > 0
    dense = 0 if full_system else unknowns
    factors = ((12 if full_system else 3) * BYTES_PER_ENTRY * nnz if backend == "amg"
               else factor_bytes(dofs, nnz, d, backend))
    if backend == "superlu" and unknowns:
        # S read off a second factorisation, of the whole matrix with Γ_C last
        # (linear_solvers/superlu.py): the ladder's contact cases peaked at
        # 0.85-1.04 times the estimate with one set of factors, 1.26-1.7 with two
        factors *= 2
    history = 8.0 * levels * (dofs * (2 if _function_kernel(scene) else 1) + 2 * contact_nodes)
    memory = (BASE_BYTES + BYTES_PER_DOF * dofs + 4 * BYTES_PER_ENTRY * nnz + factors
              + DENSE_BYTES * dense**2 + history)
    step = (SECONDS_PER_STEP + SECONDS_PER_DOF_STEP * dofs
            + NEWTON_ITERATIONS * dense**3 / (3 * FLOPS)
            + (1e-9 * dofs * levels / 2 if _function_kernel(scene) else 0.0))
    setup = SECONDS_PER_DOF_SETUP[d] * dofs * max(1.0, dofs / 1e5) ** SETUP_GROWTH[d]
    if full_system:
        setup = AMG_SECONDS_PER_DOF_SETUP * dofs
        step += AMG_SECONDS_PER_DOF_STEP * dofs
    elif backend == "amg":   # S formed by one AMG-CG solve per contact unknown
        setup += AMG_SCHUR_SECONDS * dofs * unknowns
    seconds = setup + dense**3 / FLOPS + levels * step
    disk = 8.0 * levels * (2 * dofs + 10 * cells)
    most = {}
    if scene.adaptive is not None:   # every pair at k_min: N 2^J units, 3 solves a pair
        finest = scene.steps * 2 ** scene.adaptive.halvings
        most = {"levels_at_most": finest + 1,
                "seconds_at_most": float(setup + dense**3 / FLOPS + 1.5 * finest * step),
                "disk_bytes_at_most": float(8.0 * (finest + 1) * (2 * dofs + 10 * cells))}
    return Estimate(nodes, dofs, cells, contact_nodes, unknowns, levels, backend, reason,
                    float(memory), float(seconds), float(disk), **most)


class PaceGuard:
    """What an adaptive run will need, judged from its pace as it goes.

    Its number of levels is not known before it runs (N + 1 to N 2^J + 1):
    the estimate gives both ends, and the run is refused only by what it
    needs at k_max. This guard is told, after each level, the time reached
    and the bytes the run's outputs hold so far; each time the levels pass
    the next checkpoint (the estimate's levels, then every doubling) it
    projects the levels still to come at the pace so far, (T − t)/(t/n),
    and their output and memory at the bytes per level so far, and says
    why the run should stop when that passes the free disk or memory
    (:meth:`check`, None while it fits). The library prints nothing: the
    caller decides. A tolerance of 1e-8 at the smallest k_min had been
    estimated at 9 levels and took 97,878, 1.7 GB and 12 minutes."""

    def __init__(self, est, T, folder=None, disk=None, memory=None):
        self.T, self.folder = float(T), folder
        self.next = max(int(est.levels), 2)
        self.disk, self.memory = disk, memory
        self.rss0 = _rss_bytes()

    def check(self, levels, t, written):
        """Why to stop after ``levels`` levels at time ``t`` with ``written()``
        bytes of output so far (a callable, asked at the checkpoints only),
        or None."""
        if levels < self.next or not t > 0.0:
            return None
        self.next *= 2
        written = written()
        to_come = (self.T - t) / (t / max(levels - 1, 1))
        grown = max(_rss_bytes() - self.rss0, 0)
        need_disk = written / levels * to_come
        need_memory = grown / levels * to_come
        pace = (f"after {levels} levels to t = {t:.4g} of T = {self.T:g} the adaptive steps "
                f"need about {to_come:.3g} more")
        disk = free_disk(self.folder) if self.disk is None and self.folder else self.disk
        if disk is not None and need_disk > 0.9 * disk:
            return (f"{pace}, and their output about {_bytes(need_disk)}, more than the "
                    f"{_bytes(disk)} free")
        memory = available_memory() if self.memory is None else self.memory
        if need_memory > 0.9 * memory:
            return (f"{pace}, and about {_bytes(need_memory)} more memory, more than the "
                    f"{_bytes(memory)} available")
        return None


def _rss_bytes():
    """The resident memory of this process now (VmRSS), 0 when unknown."""
    return _status("VmRSS") or 0


def built_counts(problem):
    """(nodes, cells, contact nodes, contact unknowns) of a built problem,
    for :func:`estimate` once the mesh exists (``adhcontact check``)."""
    boundary = problem.boundary
    return (problem.mesh.p.shape[1], problem.mesh.t.shape[1],
            0 if boundary is None else boundary.nodes.size, problem.columns.size)


def _function_kernel(scene):
    return scene.memory is not None and scene.memory.kernel == "function"


def available_memory():
    """Bytes of memory a run may take now: the smallest of
    :func:`memory_limits`."""
    return memory_available()[0]


def memory_available():
    """(bytes, what limits them) of :func:`memory_limits`, the smallest."""
    limits = memory_limits()
    what = min(limits, key=limits.get)
    return max(int(limits[what]), 0), what


def memory_limits():
    """{what: bytes} of every limit on the memory of this process:

    - ``"available memory"``: MemAvailable of /proc/meminfo (else the
      physical memory, else 4 GiB);
    - ``"the address-space limit (ulimit -v)"``: RLIMIT_AS less the address
      space this process already maps (VmSize), when it is set;
    - ``"the cgroup's memory limit"``: memory.max less memory.current
      (cgroup v2; memory.limit_in_bytes less memory.usage_in_bytes in v1),
      when one is set (a container, a systemd slice, a batch job).
    """
    limits = {"available memory": _meminfo("MemAvailable")}
    if limits["available memory"] is None:
        try:
            limits["available memory"] = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
        except (AttributeError, ValueError, OSError):
            limits["available memory"] = 4 * 2**30
    try:
        import resource

        soft = resource.getrlimit(resource.RLIMIT_AS)[0]
        if soft != resource.RLIM_INFINITY and soft > 0:
            limits["the address-space limit (ulimit -v)"] = soft - (_status("VmSize") or 0)
    except (ImportError, OSError, ValueError):
        pass
    cgroup = _cgroup_room()
    if cgroup is not None:
        limits["the cgroup's memory limit"] = cgroup
    return limits


def _meminfo(key, path="/proc/meminfo"):
    """A ``key: N kB`` line of a /proc file, in bytes (None when absent)."""
    try:
        with open(path, encoding="ascii") as f:
            for line in f:
                if line.startswith(key + ":"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return None


def _status(key):
    return _meminfo(key, "/proc/self/status")


def _read_number(path):
    try:
        with open(path, encoding="ascii") as f:
            text = f.read().strip()
    except (OSError, UnicodeDecodeError):
        return None
    return int(text) if text.isdigit() else None


def _cgroup_room(root="/sys/fs/cgroup", membership="/proc/self/cgroup"):
    """Bytes the cgroup of this process may still take, None without a limit."""
    try:
        with open(membership, encoding="ascii") as f:
            lines = f.read().splitlines()
    except OSError:
        lines = []
    for line in lines:   # "0::/path" (v2), "N:memory:/path" (v1)
        _, controllers, path = (line.split(":", 2) + ["", ""])[:3]
        if controllers == "":
            for base in (f"{root}{path}", root):
                limit = _read_number(f"{base}/memory.max")
                if limit is not None:
                    return limit - (_read_number(f"{base}/memory.current") or 0)
        elif "memory" in controllers.split(","):
            for base in (f"{root}/memory{path}", f"{root}/memory"):
                limit = _read_number(f"{base}/memory.limit_in_bytes")
                if limit is not None and limit < 1 << 60:   # v1 "no limit" is ~2^63
                    return limit - (_read_number(f"{base}/memory.usage_in_bytes") or 0)
    return None


def free_disk(folder):
    """Free bytes on the file system of ``folder`` or its nearest existing
    parent (None when it cannot be told)."""
    path = os.path.abspath(folder)
    while not os.path.exists(path) and os.path.dirname(path) != path:
        path = os.path.dirname(path)
    try:
        return shutil.disk_usage(path).free
    except OSError:
        return None


def refusal(est, memory=None, seconds=DAY, disk=None):
    """Why a run of estimate ``est`` should not start, or None.

    Parameters
    ----------
    est : Estimate
    memory : bytes the run may take (default :func:`available_memory`)
    seconds : the longest run allowed without asking (default a day)
    disk : free bytes where the outputs go, or None not to check
    """
    what = "available"
    if memory is None:
        memory, limit = memory_available()
        what = "available" if limit == "available memory" else f"that {limit} leaves"
    if est.memory_bytes > memory:
        return (f"it would need about {_bytes(est.memory_bytes)} of memory, more than the "
                f"{_bytes(memory)} {what}")
    if est.seconds > seconds:
        return f"it would run for about {_duration(est.seconds)}, more than {_duration(seconds)}"
    if disk is not None and est.disk_bytes > disk:
        return (f"its outputs would take about {_bytes(est.disk_bytes)}, more than the "
                f"{_bytes(disk)} free")
    return None
