"""Facets by their vertices, and named boundaries through uniform refinement.

A uniform refinement (scikit-fem's ``refined()``) keeps the coarse vertices
first and adds one per coarse edge (the facets in 2D, ``edges`` in 3D), in
edge order: fine vertex n_c + e is the midpoint of coarse edge e. Each fine
boundary facet then lies in exactly one coarse facet, whose vertices are
the coarse vertices the fine facet's vertices come from (a fine vertex
comes from its coarse vertex, or from the two ends of its edge). This is
how named boundaries follow a refinement and how a fine contact facet finds
the coarse facet it refines. New vertices are midpoints of straight coarse
edges: a curved side of a file mesh is not re-projected onto the curve.
"""

from dataclasses import replace

import numpy as np


def _keys(nodes, npoints):
    """One integer per column of sorted vertex indices (d, n)."""
    s = np.sort(np.asarray(nodes, dtype=np.int64), axis=0)
    return np.ravel_multi_index(tuple(s), (npoints,) * s.shape[0])


def facet_index(mesh, nodes):
    """Indices (n,) of the mesh facets with the vertices ``nodes`` (d, n),
    in any order; −1 where the vertices span no facet."""
    nodes = np.asarray(nodes, dtype=np.int64)
    if nodes.size == 0:
        return np.zeros(0, dtype=np.int64)
    npoints = mesh.p.shape[1]
    bad = (nodes < 0) | (nodes >= npoints)
    keys = _keys(np.where(bad, 0, nodes), npoints)
    facet_keys = _keys(mesh.facets, npoints)
    order = np.argsort(facet_keys)
    pos = np.minimum(np.searchsorted(facet_keys, keys, sorter=order), order.size - 1)
    found = order[pos]
    ok = (facet_keys[found] == keys) & ~bad.any(axis=0)
    return np.where(ok, found, -1)


def refinement_parents(coarse, fine, fine_facets):
    """The coarse facet (n,) in which each of ``fine_facets`` lies, −1 for
    a fine facet inside a coarse cell (``fine = coarse.refined()``)."""
    nc = coarse.p.shape[1]
    edges = coarse.facets if coarse.dim() == 2 else coarse.edges
    if fine.p.shape[1] != nc + edges.shape[1]:
        raise ValueError("meshes are not one uniform refinement apart")
    nodes = fine.facets[:, np.asarray(fine_facets, dtype=np.int64)]       # (d, n)
    old = nodes < nc
    ends = edges[:, np.where(old, 0, nodes - nc)]                          # (2, d, n)
    origin = np.where(old, nodes, ends).reshape(-1, nodes.shape[1])      # (2d, n)
    origin = np.sort(origin, axis=0)
    distinct = np.vstack([np.ones((1, origin.shape[1]), bool), np.diff(origin, axis=0) > 0])
    d = coarse.dim()
    inside = distinct.sum(axis=0) == d
    parents = np.full(nodes.shape[1], -1, dtype=np.int64)
    if inside.any():
        spans = origin[:, inside].T[distinct[:, inside].T].reshape(-1, d).T
        parents[inside] = facet_index(coarse, spans)
    return parents


#: the entities scikit-fem builds on first use and keeps on the mesh object
ENTITIES = ("_facets", "_t2f", "_f2t")


def with_boundaries(mesh, boundaries):
    """``mesh.with_boundaries(boundaries)`` without building its facets twice.

    scikit-fem's copy of the mesh forgets the facets it built to find the
    named sides, and the first use of the copy builds them again (0.9 s for
    the 2e6 triangles of a 1e6-dof strip); the copy has the same cells, so
    its facets are the original's, handed over here."""
    named = mesh.with_boundaries(boundaries)
    if np.array_equal(named.t, mesh.t):
        for name in ENTITIES:
            if name in vars(mesh) and name not in vars(named):
                setattr(named, name, getattr(mesh, name))
    return named


def unnamed(mesh):
    """``mesh`` without its named boundaries, the facets it built kept:
    what is refined, since scikit-fem drops the names there and says so on
    stderr (they are carried by :func:`refined_with_boundaries`)."""
    if not mesh.boundaries:
        return mesh
    bare = replace(mesh, _boundaries=None)
    for name in ENTITIES:
        if name in vars(mesh) and name not in vars(bare):
            setattr(bare, name, getattr(mesh, name))
    return bare


def refined_with_boundaries(mesh, times):
    """``mesh`` refined uniformly ``times`` times, its named boundaries
    carried to the fine facets that refine theirs."""
    names = dict(mesh.boundaries or {})
    for _ in range(times):
        fine = unnamed(mesh).refined(1)
        if names:
            boundary = fine.boundary_facets()
            parents = refinement_parents(mesh, fine, boundary)
            member = np.zeros(mesh.facets.shape[1], dtype=np.int64)
            groups = {}
            for name, facets in names.items():
                member[:] = 0
                member[facets] = 1
                keep = parents >= 0
                groups[name] = np.sort(boundary[keep][member[parents[keep]] == 1])
            names = groups
            fine = with_boundaries(fine, groups)
        mesh = fine
    return mesh
