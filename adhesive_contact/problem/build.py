"""A scene made discrete: everything built once before the time loop.

:func:`build_problem` turns a :class:`~adhesive_contact.scene.Scene` into
a :class:`Problem`: the mesh and its per-mesh operators, the free dofs,
Γ_C (only if the scene has contact terms), the load map, the gap at the
contact nodes for every t_n, the initial bonding β_0^h = P_B β_0, the laws
and the probes. A Problem is never changed by a run: each run starts its
own memory history (:meth:`Problem.start_memory`). Checks that need the geometry (a probe outside
the mesh, a negative gap) raise :class:`~adhesive_contact.scene.SceneError`.
"""

import time
from dataclasses import dataclass, field

import numpy as np
from skfem import Basis, ElementTetP1, ElementTriP1, FacetBasis

from ..verification.admissibility import check_manufactured
from ..fem.assembly import LOAD_INTORDER, Assembly, LoadMap, is_zero, vector_element, vector_of
from ..fem.contact_boundary import (
    build_contact_boundary,
    facet_normals,
    facet_points,
    tangent_frame,
)
from ..fem.dirichlet import prescribed_displacement
from ..expressions import coordinates
from ..fem.foundation import foundation_gap
from ..laws import make_bonding, make_friction, make_normal_law
from ..verification.manufactured import ManufacturedSolution
from ..scheme.memory import make_memory
from ..fem.meshes import build_mesh, named_facets
from ..scene import SceneError
from .smallness import smallness
from .checks import check_exact, check_kernel, check_loads


@dataclass(kw_only=True)
class Problem:
    """A discretised scene; built once, never changed by a run.

    Absent concepts are None (``boundary``, ``gap``, ``friction``,
    ``bonding``, ``probe_map``, ``exact``, ``beta_source``), except the
    normal law, whose null object :class:`~adhesive_contact.laws.NoNormalLaw`
    contributes nothing, and the memory (:class:`~adhesive_contact.memory.NoMemory`)."""

    scene: object
    mesh: object
    assembly: Assembly
    free: np.ndarray          # free dofs (not held by a side)
    prescribed: object        # PrescribedDisplacement: the held dofs and g_D(t)
    boundary: object          # ContactBoundary, or None
    columns: np.ndarray       # the step's unknowns among the nc·d frame components
    contact_positions: np.ndarray  # positions of those unknowns within ``free``
    loads: LoadMap
    gap: np.ndarray           # (N+1, nc) g(x_a, t_n), or None for no wall
    beta0: np.ndarray         # (nf,) β_0^h
    normal_law: object
    friction: object          # FrictionSum or None
    bonding: object           # bonding law or None (β frozen)
    probe_map: object         # sparse (nprobes, npoints) or None
    times: np.ndarray         # t_n, n = 0..N
    assembly_seconds: float
    exact: object = None      # ManufacturedSolution, for scenes with [exact]
    beta_source: object = None  # s_β(x, y, z, t) at Γ_C (manufactured scenes)
    _smallness: dict = field(default=None, repr=False)

    def start_memory(self):
        """A fresh memory history for one run (the rectangle rule's state)."""
        return make_memory(self.scene.memory)

    @property
    def smallness(self):
        """The terms of docs/model.md §3's condition (None without contact),
        computed on first use (a generalised eigenproblem) and kept."""
        if self._smallness is None and self.boundary is not None:
            self._smallness = smallness(self.scene, self.normal_law, self.friction)
        return self._smallness

    def warnings(self):
        """What the theory does not cover for this scene, one line each."""
        out = []
        s = self.smallness
        if s is not None and not s["holds"]:
            tail = ("each step still has one solution (its energy is convex)"
                    if s["step_energy_convex"] else
                    "a step may have several solutions and the solver may pick any or fail")
            out.append(f"the smallness condition of the error estimate does not hold "
                       f"(m_A = {s['m_A']:.4g} against (m_tau + m_nu) c_e^2 = {s['rhs']:.4g}): "
                       f"the theory does not promise a unique solution or first-order "
                       f"convergence here, and {tail}; softer contact laws or a stiffer "
                       f"body move the scene inside it "
                       f"(docs/model.md#the-three-smallness-conditions)")
        if (self.bonding is not None and self.scene.contact.integrator == "explicit"
                and self.scene.k > self.bonding.stable_step()):
            out.append(f"the time step k = {self.scene.k:.4g} exceeds the explicit Euler bound "
                       f"1/((gamma_nu + gamma_tau) L^2) = {self.bonding.stable_step():.4g} of "
                       f"the bonding law, so beta may leave [0, 1] and the run stop: use more "
                       f"steps or another contact.bonding.integrator "
                       f"(docs/conventions.md#the-explicit-euler-bound-on-the-time-step)")
        return out

    @property
    def dim(self):
        return self.mesh.dim()

    @property
    def ndofs(self):
        return self.assembly.ndofs

    @property
    def normal_columns(self):
        """Positions within the step's unknowns of the normal components."""
        return np.flatnonzero(self.columns % self.dim == 0)

    def upper_bound(self, n):
        """Bounds on z for step n: g at the normal unknowns, +inf elsewhere."""
        upper = np.full(self.columns.size, np.inf)
        if self.gap is not None:
            normal = self.normal_columns
            upper[normal] = self.gap[n][self.columns[normal] // self.dim]
        return upper


def _facet_mean(mesh, boundary, expr, order=4):
    """P_B of an expression: its mean over each contact facet (Gauss rule)."""
    x, weights = facet_points(mesh, boundary.facet_nodes, "gauss", order)
    values = expr(*coordinates(x.reshape(mesh.dim(), -1))).reshape(x.shape[1:])
    return values @ weights


def build_problem(scene):
    """Discretise a scene (see module docstring)."""
    t0 = time.perf_counter()
    mesh = build_mesh(scene.mesh)
    assembly = Assembly(mesh)
    d = mesh.dim()

    dirichlet_facets = named_facets(mesh, scene.dirichlet, "boundary.dirichlet")
    contact_facets = named_facets(mesh, scene.contact_sides, "boundary.contact")
    prescribed = prescribed_displacement(scene, mesh)
    held = np.zeros(assembly.ndofs, dtype=bool)
    held[prescribed.fixed] = True
    free = np.flatnonzero(~held)
    position = np.full(assembly.ndofs, -1)
    position[free] = np.arange(free.size)

    times = scene.k * np.arange(scene.steps + 1)
    if scene.memory is not None and scene.memory.kernel == "function":
        check_kernel("memory.r", scene.memory.function, scene.k, scene.steps)
    friction = make_friction(scene.contact.friction)
    boundary, gap, beta0 = None, None, np.zeros(0)
    columns = contact_positions = np.zeros(0, dtype=np.int64)
    if scene.has_contact_terms:
        # every vertex of Γ_C is a contact node; its held components are no unknowns
        boundary = build_contact_boundary(mesh, contact_facets, prescribed.fixed,
                                          scene.contact.quadrature, scene.contact.order)
        assert np.array_equal(assembly.nodal_dofs[:, boundary.nodes].T, boundary.dofs)
        # without friction only u_ν enters the contact terms (the traces of
        # the tangential components vanish on flat facets): solve for it alone
        tangential = boundary.unknowns(np.arange(1, d))
        normal_only = friction is None and (
            tangential.size == 0
            or abs(boundary.normal_trace[:, tangential]).max() <= 1e-13)
        columns = boundary.unknowns([0] if normal_only else np.arange(d))
        contact_positions = position[boundary.frame_dofs.ravel()[columns]]
        if scene.contact.has_wall:
            gap = _gap(scene, mesh, boundary, times)
        beta0 = np.ones(boundary.facets.size)
        if scene.contact.beta0 is not None and scene.contact.beta0.is_constant:
            beta0 = np.full(boundary.facets.size, float(scene.contact.beta0(0.0)))
        elif scene.contact.beta0 is not None:
            beta0 = _facet_mean(mesh, boundary, scene.contact.beta0)
            if not np.all((beta0 >= 0) & (beta0 <= 1)):
                raise SceneError("contact.bonding.beta0", "must lie in [0, 1] on Γ_C")

    probe_map = None
    if scene.probes:
        scalar = Basis(mesh, ElementTriP1() if d == 2 else ElementTetP1())
        points = np.array(scene.probes, dtype=float).T
        for i in range(points.shape[1]):
            try:
                scalar.probes(points[:, i:i + 1])
            except ValueError:
                raise SceneError(f"output.probes[{i}]", "point "
                                 f"({', '.join(f'{c:g}' for c in points[:, i])}) "
                                 "is outside the mesh") from None
        probe_map = scalar.probes(points).tocsr()

    normal_law = make_normal_law(scene.contact.normal)
    bonding = make_bonding(scene.contact.bonding)
    exact = beta_source = None
    if scene.exact is None:
        body = None if is_zero(scene.body) else vector_of(scene.body)
        surface = [(named_facets(mesh, [side], "loads.traction", indexed=False), vector_of(exprs))
                   for side, exprs in scene.traction.items()]
        checks = ([] if body is None else
                  [[(f"loads.body[{i}]", e) for i, e in enumerate(scene.body)]])
        checks += [[(f"loads.traction.{side}[{i}]", e) for i, e in enumerate(exprs)]
                   for side, exprs in scene.traction.items()]
    else:
        check_exact(scene.exact, mesh.p, times)
        try:
            exact = ManufacturedSolution(scene, normal_law, friction, bonding)
        except (ArithmeticError, ValueError, TypeError, KeyError) as err:
            raise SceneError("exact", "the loads cannot be derived from the exact solution "
                             f"({type(err).__name__}: {err})") from None
        check_manufactured(scene, mesh, exact, times, scene.contact.gap, dirichlet_facets,
                           contact_facets)
        body = exact.body_force
        neumann = np.setdiff1d(mesh.boundary_facets(),
                               np.concatenate([dirichlet_facets, contact_facets]))
        surface = []
        if neumann.size:
            surface.append((neumann, exact.traction(_load_point_normals(mesh, neumann))))
        if contact_facets.size:
            normal = _load_point_normals(mesh, contact_facets)           # (d, npoints)
            tangents = tangent_frame(normal)[:, :, 1:].transpose(2, 1, 0)  # (d-1, d, npoints)
            surface.append((contact_facets, exact.contact_load(normal, tangents)))
        if boundary is not None:
            normals = _side_normals_at(mesh, boundary)
            frames = tangent_frame(normals)                     # (nq, d, d)
            beta_source = exact.beta_source(normals, frames[:, :, 1:].transpose(2, 1, 0))
            beta0 = _facet_mean(mesh, boundary, exact.beta)
    loads = LoadMap(mesh, body, surface)
    if scene.exact is not None:
        checks = [[("exact", field)] for field, _ in loads.parts]
    check_loads(checks, loads, times)
    return Problem(scene=scene, mesh=mesh, assembly=assembly, free=free,
                   prescribed=prescribed, boundary=boundary,
                   columns=columns, contact_positions=contact_positions, loads=loads, gap=gap,
                   beta0=beta0, normal_law=normal_law, friction=friction, bonding=bonding,
                   probe_map=probe_map, times=times,
                   assembly_seconds=time.perf_counter() - t0, exact=exact,
                   beta_source=beta_source)


def _gap(scene, mesh, boundary, times):
    """g(x_a, t_n) (N+1, nc) at the contact nodes: the scene's gap
    expression, or the distance to the foundation along the nodal normal
    ν_a (:mod:`~adhesive_contact.foundation`; +∞ where the normal misses it)."""
    x = mesh.p[:, boundary.nodes]
    if scene.contact.foundation is not None:
        g, depth = foundation_gap(scene.contact.foundation, x, boundary.frame[:, :, 0].T)
        inside = depth < -1e-12 * (1.0 + np.abs(x).max())
        if inside.any():
            a = int(np.argmax(inside))
            raise SceneError("contact.foundation", "the contact node "
                             f"({', '.join(f'{c:g}' for c in x[:, a])}) lies inside the "
                             "foundation; the body must start outside it")
        return np.broadcast_to(g, (times.size, g.size)).copy()
    gap = np.array([scene.contact.gap(*coordinates(x), t=t) for t in times])
    bad = ~(np.isfinite(gap) & (gap >= 0))
    if bad.any():
        n, a = np.argwhere(bad)[0]
        where = ", ".join(f"{c:g}" for c in x[:, a])
        raise SceneError("contact.gap", f"must be finite and >= 0 on Γ_C, got "
                         f"{gap[n, a]:g} at ({where}), t = {times[n]:g}")
    return gap


def _load_point_normals(mesh, facets):
    """Outward unit normals (d, npoints) of the facets at the points where
    :class:`~adhesive_contact.assembly.LoadMap` evaluates a surface load
    (each facet's own normal: the sides may be curved or slanted)."""
    basis = FacetBasis(mesh, vector_element(mesh.dim()), facets=facets,
                       intorder=LOAD_INTORDER)
    return np.asarray(basis.normals).reshape(mesh.dim(), -1)


def _side_normals_at(mesh, boundary):
    """Outward facet normals (d, nq) at the quadrature points of Γ_C."""
    normals, _ = facet_normals(mesh, boundary.facets)
    return normals[:, boundary.facet_of_point]
