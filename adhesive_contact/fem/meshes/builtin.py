"""Structured meshes of the built-in domains, with named sides.

A rectangle [0, L_x] × [0, L_y] is cut into ``cells`` quadrilaterals, each
split into two triangles (``pattern = "diagonal"``) or into four around its
centre (``"cross"``); a box [0, L_x] × [0, L_y] × [0, L_z] into tetrahedra.
``refine`` uniform refinements follow; they keep the coarse vertices first,
so meshes of one scene at different ``refine`` are nested.

Sides are named as scikit-fem does: left/right (x = 0, L_x), bottom/top
(y = 0, L_y) and, in 3D, front/back (z = 0, L_z) (:data:`SIDES`, the
names a scene may use with these domains). :func:`nodes_of` counts the
nodes of a mesh before it is built.
"""

import math

import numpy as np
from skfem import MeshQuad, MeshTet, MeshTri

from .facets import with_boundaries

#: the named sides of the rectangle (2D) and of the box (3D)
SIDES = {2: ("left", "right", "bottom", "top"),
         3: ("left", "right", "bottom", "top", "front", "back")}


def side_tests(size):
    """Facet-midpoint tests for each named side of [0, size]."""
    size = np.asarray(size, dtype=float)
    tol = 1e-9 * size.max()
    names = [("left", "right"), ("bottom", "top"), ("front", "back")]
    tests = {}
    for axis, length in enumerate(size):
        low, high = names[axis]
        tests[low] = lambda x, a=axis: np.abs(x[a]) < tol
        tests[high] = lambda x, a=axis, L=length: np.abs(x[a] - L) < tol
    return tests


def nodes_of(size_cells, refine, pattern="diagonal"):
    """The number of nodes of the structured mesh of ``cells`` refined
    ``refine`` times (exact, in Python integers: no overflow)."""
    n = [c * 2**refine for c in size_cells]
    nodes = math.prod(c + 1 for c in n)
    if pattern == "cross":   # a centre node per quadrilateral of the unrefined mesh,
        nodes += math.prod(size_cells) * 4**refine   # refined with the rest
    return nodes


def structured_mesh(spec):
    """The rectangle or box of a :class:`~adhesive_contact.scene.MeshSpec`,
    refined ``spec.refine`` times, sides named."""
    axes = [np.linspace(0.0, length, n + 1) for length, n in zip(spec.size, spec.cells)]
    if spec.domain == "rectangle":
        if spec.pattern == "cross":
            mesh = MeshQuad.init_tensor(*axes).to_meshtri(style="x")
        else:
            mesh = MeshTri.init_tensor(*axes)
    elif spec.domain == "box":
        mesh = MeshTet.init_tensor(*axes)
    else:
        raise ValueError(f"unknown domain {spec.domain!r}")
    if spec.refine:
        mesh = mesh.refined(spec.refine)
    # the tests on the boundary facets' midpoints only (scikit-fem's own
    # facets_satisfying tests every facet: 4.8 of 23 s of building a 1e6-dof box)
    boundary = mesh.boundary_facets()
    midpoints = mesh.p[:, mesh.facets[:, boundary]].mean(axis=1)
    return with_boundaries(mesh, {name: boundary[test(midpoints)]
                                  for name, test in side_tests(spec.size).items()})
