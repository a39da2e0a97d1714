"""A scene made discrete: :func:`build_problem`, a pipeline of named stages.

Each stage reads the scene and what the stages before it built, checks
what it can check once the geometry is known (:mod:`.checks`: each raises
:class:`~adhesive_contact.scene.SceneError` naming the key) and returns
its part of the :class:`~.problem.Problem`:

1. :func:`mesh_and_dofs`: the mesh and its per-mesh operators;
2. :func:`held_dofs`: the prescribed displacements, the free dofs;
3. :func:`contact_laws`: the normal law, the friction and the bonding law;
4. :func:`manufactured_solution`: for a scene with [exact], its derived data;
5. :func:`contact`: Γ_C (only if the scene has contact terms), the step's
   unknowns and the gap at the contact nodes (:class:`~.gap.Gap`, checked
   at every time of the run's grid);
   :func:`restraint`: no rigid motion left free by the held sides and the
   contact terms together;
6. :func:`initial_bonding`: β_0^h = P_B β_0 (and the source s_β of a
   manufactured solution);
7. :func:`loads`: the load map of f_0 and f_N (or of a manufactured
   solution's loads);
8. :func:`probes`: the probe map.

A Problem is never changed by a run: each run starts its own memory
history (:func:`adhesive_contact.scheme.memory.start_memory`).
"""

import time
from dataclasses import dataclass

import numpy as np
from skfem import Basis, ElementTetP1, ElementTriP1, FacetBasis

from ..expressions import coordinates
from ..fem.assembly import LOAD_INTORDER, Assembly, LoadMap, is_zero, vector_element, vector_of
from ..fem.contact_boundary import (
    build_contact_boundary,
    facet_normals,
    facet_points,
    tangent_frame,
)
from ..fem.dirichlet import prescribed_displacement, rigid_modes
from ..scheme.options import OutputOptions, SchemeOptions, SolverOptions
from ..fem.foundation import foundation_gap, foundation_normal, signed_distance
from ..fem.meshes import build_mesh, named_facets
from ..laws import make_bonding, make_friction, make_normal_law
from ..scene import SceneError
from ..verification.admissibility import check_manufactured
from ..verification.manufactured import ManufacturedSolution
from .checks import (
    check_beta0,
    check_exact,
    check_gap,
    check_kernel,
    check_loads,
    check_adaptive_bound,
    check_foundation_beside_body,
    check_outside_foundation,
    check_prescribed,
    check_probes,
    check_rigid_motions,
    describe_motions,
    free_rigid_motions,
    restraining_rows,
)
from .gap import Gap
from .problem import Problem


def build_problem(scene, bulk="auto"):
    """Discretise a scene: the stages of the module docstring, in order.

    ``bulk`` says how the bulk operators are built: "auto" (the vectorised
    P1 kernels wherever they apply, every scene today), "kernels" or
    "forms" (scikit-fem's assembly of :mod:`adhesive_contact.fem.forms`,
    the reference: the same numbers to round-off);
    :func:`~adhesive_contact.fem.assembly.choose_path`."""
    t0 = time.perf_counter()
    times = time_grid(scene)
    mesh, assembly = mesh_and_dofs(scene, bulk)
    held = held_dofs(scene, mesh, assembly)
    if scene.memory is not None and scene.memory.kernel == "function":
        check_kernel("memory.r", scene.memory.function, times[1], times.size - 1)
    laws = contact_laws(scene)
    check_adaptive_bound(scene, laws.bonding)
    exact = manufactured_solution(scene, mesh, laws, times, held)
    on_contact = contact(scene, mesh, assembly, held, laws, times)
    held_by_contact = restraint(scene, mesh, held, laws, on_contact)
    beta0, beta_source = initial_bonding(scene, mesh, on_contact.boundary, exact)
    probe_map = probes(scene, mesh)
    return Problem(scene=scene, mesh=mesh, assembly=assembly, free=held.free,
                   prescribed=held.prescribed, boundary=on_contact.boundary,
                   columns=on_contact.columns, contact_positions=on_contact.positions,
                   loads=loads(scene, mesh, exact, held, times, assembly), gap=on_contact.gap,
                   beta0=beta0, normal_law=laws.normal, friction=laws.friction,
                   bonding=laws.bonding, probe_map=probe_map,
                   assembly_seconds=time.perf_counter() - t0, exact=exact,
                   beta_source=beta_source, held_by_contact=held_by_contact,
                   options=scheme_options(scene),
                   output=OutputOptions(every=scene.every, fields=scene.fields,
                                        units=dict(scene.units)))


def scheme_options(scene):
    """The :class:`~adhesive_contact.scheme.options.SchemeOptions` of a
    validated scene: all the scheme reads of it, resolved once."""
    s = scene.solver
    return SchemeOptions(
        T=scene.T, steps=scene.steps, scheme=scene.scheme,
        integrator=scene.contact.integrator, adaptive=scene.adaptive, memory=scene.memory,
        material=scene.material, dim=scene.dim,
        solver=SolverOptions(method=s.method, tol=s.tol, max_iter=s.max_iter,
                             penalty=s.penalty, smoothing=s.smoothing, linear=s.linear,
                             linear_tol=s.linear_tol))


def time_grid(scene):
    """t_n = n k, n = 0..N; with [time.adaptive] the finest grid its steps
    lie on, t_m = m k_min, m = 0..N 2^J (docs/scheme.md, "Adaptive time
    steps"): every accepted level is one of these times."""
    if scene.adaptive is None:
        return scene.k * np.arange(scene.steps + 1)
    return scene.adaptive.k_min * np.arange(scene.steps * 2 ** scene.adaptive.halvings + 1)


# ---------------------------------------------------------------- 1. mesh and dofs


def mesh_and_dofs(scene, bulk="auto"):
    """The mesh with its named sides, and the operators assembled once on
    it, by the path ``bulk`` (:class:`~adhesive_contact.fem.assembly.Assembly`)."""
    mesh = build_mesh(scene.mesh)
    return mesh, Assembly(mesh, path=bulk)


# ---------------------------------------------------------------- 2. held dofs


@dataclass(frozen=True)
class HeldDofs:
    """The prescribed displacements and what they leave free."""

    prescribed: object        # PrescribedDisplacement
    free: np.ndarray          # the free dofs
    position: np.ndarray      # (ndofs,) position of a dof within ``free``, −1 if held
    dirichlet_facets: np.ndarray
    contact_facets: np.ndarray


def held_dofs(scene, mesh, assembly):
    """The held dofs of ``[boundary]`` (checked consistent) and the free
    dofs, numbered."""
    dirichlet_facets = named_facets(mesh, scene.dirichlet, "boundary.dirichlet")
    contact_facets = named_facets(mesh, scene.contact_sides, "boundary.contact")
    prescribed = prescribed_displacement(scene, mesh)
    check_prescribed(prescribed, scene, mesh)
    held = np.zeros(assembly.ndofs, dtype=bool)
    held[prescribed.fixed] = True
    free = np.flatnonzero(~held)
    position = np.full(assembly.ndofs, -1)
    position[free] = np.arange(free.size)
    return HeldDofs(prescribed, free, position, dirichlet_facets, contact_facets)


# ---------------------------------------------------------------- 3. laws


@dataclass(frozen=True)
class ContactLaws:
    """The laws of ``[contact]``, made once."""

    normal: object            # a normal law (NoNormalLaw when none)
    friction: object          # FrictionSum or None
    bonding: object           # a bonding law or None (β frozen)


def contact_laws(scene):
    """The law objects of the scene's ``[contact]`` tables."""
    normal = make_normal_law(scene.contact.normal)
    return ContactLaws(normal, make_friction(scene.contact.friction, normal),
                       make_bonding(scene.contact.bonding, normal))


# ---------------------------------------------------------------- 4. manufactured solution


def manufactured_solution(scene, mesh, laws, times, held):
    """The :class:`~adhesive_contact.verification.manufactured.ManufacturedSolution`
    of a scene with [exact] (None without), its u*, β*, λ* checked finite
    and admissible."""
    if scene.exact is None:
        return None
    check_exact(scene.exact, mesh.p, times)
    try:
        exact = ManufacturedSolution(scene, laws.normal, laws.friction, laws.bonding)
    except (ArithmeticError, ValueError, TypeError, KeyError) as err:
        raise SceneError("exact", "the loads cannot be derived from the exact solution "
                         f"({type(err).__name__}: {err})") from None
    check_manufactured(scene, mesh, exact, times, scene.contact.gap, held.dirichlet_facets,
                       held.contact_facets)
    return exact


# ---------------------------------------------------------------- 5. contact


@dataclass(frozen=True)
class Contact:
    """Γ_C and the step's unknowns on it (empty without contact terms)."""

    boundary: object          # ContactBoundary, or None
    columns: np.ndarray       # the step's unknowns among the nc·d frame components
    positions: np.ndarray     # positions of those unknowns within ``free``
    gap: object               # the Gap at the contact nodes, or None for no wall


def contact(scene, mesh, assembly, held, laws, times):
    """Γ_C with its frames and quadrature, the step's unknowns on it and
    the gap; nothing without contact terms."""
    d = mesh.dim()
    empty = np.zeros(0, dtype=np.int64)
    if not scene.has_contact_terms:
        return Contact(None, empty, empty, None)
    # every vertex of Γ_C is a contact node; its held components are no unknowns.
    # On a foundation ν is the foundation's normal at the closest point
    foundation = scene.contact.foundation
    normal_field = (None if foundation is None else
                    (lambda x: foundation_normal(foundation, x)[0]))
    boundary = build_contact_boundary(mesh, held.contact_facets, held.prescribed.fixed,
                                      scene.contact.quadrature, scene.contact.order,
                                      normal_field)
    if boundary.facets.size and boundary.has_held and boundary.held.all():
        raise SceneError("boundary.contact", f"every node of the contact sides "
                         f"({', '.join(scene.contact_sides)}) is held in every component by a "
                         f"held side ({', '.join(scene.held_sides)}): nothing on Γ_C is free; "
                         "use a finer mesh (mesh.cells) or hold fewer sides")
    assert np.array_equal(assembly.nodal_dofs[:, boundary.nodes].T, boundary.dofs)
    # without friction only u_ν enters the contact terms (the traces of
    # the tangential components vanish on flat facets): solve for it alone
    tangential = boundary.unknowns(np.arange(1, d))
    normal_only = laws.friction is None and (
        tangential.size == 0
        or abs(boundary.normal_trace[:, tangential]).max() <= 1e-13)
    columns = boundary.unknowns([0] if normal_only else np.arange(d))
    positions = held.position[boundary.frame_dofs.ravel()[columns]]
    gap = gap_at_nodes(scene, mesh, boundary, times) if scene.contact.has_wall else None
    return Contact(boundary, columns, positions, gap)


def restraint(scene, mesh, held, laws, on_contact):
    """Refuse a rigid motion that neither the held sides nor the contact
    terms restrain (:func:`~.checks.check_rigid_motions`): a normal law
    restrains a motion that moves Γ_C along its normal somewhere, the wall
    one that moves a node with a wall along its normal, friction one that
    moves Γ_C tangentially (docs/model.md, 'A body held by contact').

    Returns the rigid motions the held sides leave free, which the contact
    terms hold alone, in words (() when the held sides hold every one)."""
    fixed, sides = held.prescribed.fixed, held.prescribed.sides
    boundary = on_contact.boundary
    modes = rigid_modes(mesh.p)
    if boundary is None:
        check_rigid_motions(mesh, fixed, sides)
        return ()
    normal = bool(laws.normal.active)
    wall = (on_contact.gap.somewhere if on_contact.gap is not None
            else np.zeros(boundary.nodes.size, dtype=bool))
    tangential = laws.friction is not None
    terms = [name for name, acts in (("a normal law", normal), ("a wall", wall.any()),
                                     ("friction", tangential)) if acts] or ["none"]
    check_rigid_motions(mesh, fixed, sides, (
        lambda motions: restraining_rows(motions, boundary, normal, wall, tangential),
        ", ".join(terms)))
    free = free_rigid_motions(modes, fixed)
    return tuple(describe_motions(free, mesh.p)) if free.shape[1] else ()


def gap_at_nodes(scene, mesh, boundary, times):
    """The :class:`~.gap.Gap` of the contact nodes: the scene's gap
    expression, or the distance d_F(x_a) to the foundation
    (:mod:`~adhesive_contact.fem.foundation`), measured along the frame
    normal ν_a where held components turned ν_a off the foundation's
    normal (+∞ where that misses it); checked finite and ≥ 0 at every
    time of ``times`` (the grid the run's levels lie on)."""
    x = mesh.p[:, boundary.nodes]
    if scene.contact.foundation is not None:
        nu = boundary.frame[:, :, 0].T
        along, depth = foundation_gap(scene.contact.foundation, x, nu)
        check_outside_foundation(x, depth)
        check_foundation_beside_body(scene.contact.foundation, mesh, signed_distance)
        own = np.all(nu == foundation_normal(scene.contact.foundation, x)[0], axis=0)
        return Gap(values=np.where(own, np.maximum(depth, 0.0), along))
    if not scene.contact.gap.depends_on_time:
        gap = np.asarray(scene.contact.gap(*coordinates(x), t=0.0), dtype=float)
        gap = np.broadcast_to(gap, (x.shape[1],)).copy()
        check_gap(gap[None], x, times[:1])
        return Gap(values=gap)
    field = Gap(expression=scene.contact.gap, x=x)
    check_gap(field.levels(times), x, times)
    return field


# ---------------------------------------------------------------- 6. initial bonding


def initial_bonding(scene, mesh, boundary, exact):
    """β_0^h = P_B β_0 on the contact facets (nf,), and the bonding source
    s_β at the quadrature points of Γ_C of a manufactured solution (else
    None). β_0 is β* at t = 0 with [exact], else ``contact.bonding.beta0``
    (default 1)."""
    if boundary is None:
        return np.zeros(0), None
    if exact is not None:
        normals = _side_normals_at(mesh, boundary)
        frames = tangent_frame(normals)                     # (nq, d, d)
        beta_source = exact.beta_source(normals, frames[:, :, 1:].transpose(2, 1, 0))
        return _facet_mean(mesh, boundary, exact.beta), beta_source
    beta0 = scene.contact.beta0
    if beta0 is None:
        return np.ones(boundary.facets.size), None
    if beta0.is_constant:
        return np.full(boundary.facets.size, float(beta0(0.0))), None
    values = _facet_mean(mesh, boundary, beta0)
    check_beta0(values)
    return values, None


def _facet_mean(mesh, boundary, expr, order=4):
    """P_B of an expression: its mean over each contact facet (Gauss rule)."""
    x, weights = facet_points(mesh, boundary.facet_nodes, "gauss", order)
    values = expr(*coordinates(x.reshape(mesh.dim(), -1))).reshape(x.shape[1:])
    return values @ weights


def _side_normals_at(mesh, boundary):
    """Outward facet normals (d, nq) at the quadrature points of Γ_C."""
    normals, _ = facet_normals(mesh, boundary.facets)
    return normals[:, boundary.facet_of_point]


# ---------------------------------------------------------------- 7. loads


def loads(scene, mesh, exact, held, times, assembly=None):
    """The :class:`~adhesive_contact.fem.assembly.LoadMap` of the body force
    and the surface tractions, checked finite where it is evaluated: the
    scene's ``[loads]``, or a manufactured solution's f_0, f_N on the
    remaining sides and f_C on Γ_C; on the path of ``assembly``."""
    if exact is None:
        body = None if is_zero(scene.body) else vector_of(scene.body)
        surface = [(named_facets(mesh, [side], "loads.traction", indexed=False),
                    vector_of(exprs)) for side, exprs in scene.traction.items()]
        keyed = ([] if body is None else
                 [[(f"loads.body[{i}]", e) for i, e in enumerate(scene.body)]])
        keyed += [[(f"loads.traction.{side}[{i}]", e) for i, e in enumerate(exprs)]
                  for side, exprs in scene.traction.items()]
        load_map = LoadMap(mesh, body, surface, assembly=assembly)
    else:
        neumann = np.setdiff1d(mesh.boundary_facets(),
                               np.concatenate([held.dirichlet_facets, held.contact_facets]))
        surface = []
        if neumann.size:
            surface.append((neumann, exact.traction(_load_point_normals(mesh, neumann))))
        if held.contact_facets.size:
            normal = _load_point_normals(mesh, held.contact_facets)      # (d, npoints)
            tangents = tangent_frame(normal)[:, :, 1:].transpose(2, 1, 0)  # (d-1, d, npoints)
            surface.append((held.contact_facets, exact.contact_load(normal, tangents)))
        load_map = LoadMap(mesh, exact.body_force, surface, assembly=assembly)
        keyed = [[("exact", field)] for field, _ in load_map.parts]
    check_loads(keyed, load_map, times)
    return load_map


def _load_point_normals(mesh, facets):
    """Outward unit normals (d, npoints) of the facets at the points where
    :class:`~adhesive_contact.fem.assembly.LoadMap` evaluates a surface load
    (each facet's own normal: the sides may be curved or slanted)."""
    basis = FacetBasis(mesh, vector_element(mesh.dim()), facets=facets,
                       intorder=LOAD_INTORDER)
    return np.asarray(basis.normals).reshape(mesh.dim(), -1)


# ---------------------------------------------------------------- 8. probes


def probes(scene, mesh):
    """The sparse map (nprobes, npoints) from nodal values to the probe
    points of ``[output] probes`` (None without probes), each checked to
    lie in the mesh."""
    if not scene.probes:
        return None
    scalar = Basis(mesh, ElementTriP1() if mesh.dim() == 2 else ElementTetP1())
    points = np.array(scene.probes, dtype=float).T
    check_probes(scalar, points)
    return scalar.probes(points).tocsr()
