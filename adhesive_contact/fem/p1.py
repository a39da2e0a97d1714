"""Vectorised kernels for P1 on simplices: gradients are constant per cell.

For a cell e with vertices p_0..p_d, J_e = [p_1 − p_0, …, p_d − p_0] and the
barycentric functions φ_i have the constant gradients g_i = J_e^{-T} ĝ_i
(ĝ_0 = −Σ e_j, ĝ_i = e_i); |e| = |det J_e| / d!. With the interleaved
vector dofs (i, a) ↦ d·node_i + a and u = φ_i e_a:

    div u div v                →  |e| g_i[a] g_j[b]                     (K_λ)
    2 ε(u) : ε(v)              →  |e| (δ_ab g_i·g_j + g_i[b] g_j[a])    (K_μ)
    ε(u)_{bc}                  =  ½ (δ_ab g_i[c] + δ_ac g_i[b])        (strain map)

so the stiffness parts are exact with no quadrature at all, and are built
from one array of element matrices and one sparse conversion each. The
same quantities from scikit-fem's forms (:mod:`adhesive_contact.fem.forms`,
the path :class:`~adhesive_contact.fem.assembly.Assembly` takes where these
kernels do not apply) agree to round-off (tests/test_p1.py,
tests/test_forms.py); these kernels assemble 1.6 (2D) to 6.5 (3D) times
faster at 1e5 dofs (studies/bench/forms_vs_kernels.py).
"""

import functools
from math import factorial

import numpy as np
import scipy.sparse as sp
from skfem.quadrature import get_quadrature
from skfem.refdom import RefTet, RefTri


def gradients(mesh):
    """(g, volume): g (ne, d+1, d) the barycentric gradients per cell,
    volume (ne,) the cell measures."""
    p, t = mesh.p, mesh.t
    d = p.shape[0]
    J = np.stack([p[:, t[i]] - p[:, t[0]] for i in range(1, d + 1)], axis=-1)  # (d, ne, d)
    J = J.transpose(1, 0, 2)                                                    # (ne, d, d)
    det, inv_T = _det_inverse_transpose(J)                                      # J^{-T}
    ref = np.vstack([-np.ones((1, d)), np.eye(d)])                              # (d+1, d)
    g = np.einsum("eab,ib->eia", inv_T, ref)
    return g, np.abs(det) / factorial(d)


def _det_inverse_transpose(J):
    """det J and J^{-T} for a stack (ne, d, d), d = 2 or 3, by cofactors:
    J^{-T} = cof(J) / det J (several times faster than LAPACK per 2 × 2)."""
    d = J.shape[-1]
    if d == 2:
        cof = np.stack([np.stack([J[:, 1, 1], -J[:, 1, 0]], -1),
                        np.stack([-J[:, 0, 1], J[:, 0, 0]], -1)], -2)
    else:
        # row i of cof(J) is row i+1 × row i+2 of J (indices mod 3)
        r0, r1, r2 = J[:, 0, :], J[:, 1, :], J[:, 2, :]
        cof = np.stack([np.cross(r1, r2), np.cross(r2, r0), np.cross(r0, r1)], -2)
    det = np.einsum("ea,ea->e", J[:, 0, :], cof[:, 0, :])
    return det, cof / det[:, None, None]


def element_dofs(mesh):
    """(ne, (d+1)·d) the global vector dofs d·node_i + a of each cell, in
    the local order l = i·d + a."""
    d = mesh.p.shape[0]
    return (d * mesh.t.T[:, :, None] + np.arange(d)[None, None, :]).reshape(mesh.t.shape[1], -1)


def node_pattern(mesh):
    """The sparsity of P1 on the nodes: every pair of vertices of a cell.

    Returns ``(indptr, indices, slot)``: the CSR pattern (n_nodes rows,
    sorted columns) and, for each pair (e, i, j) in C order of (cell, local
    vertex i, local vertex j), its position in ``indices``.

    The pattern is that of EᵀE, E the (cells × nodes) incidence matrix (a
    sparse product, linear in the cells); a pair's position is found by a
    binary search of its key i·n + j among the pattern's keys, which are
    sorted (row-major). Both avoid sorting the (d+1)² keys of every cell,
    which took 2.4 s of 2.7 for the 2e6 triangles of a 1e6-dof strip."""
    t = mesh.t
    nv, ne = t.shape
    n = mesh.p.shape[1]
    cells = t.T.astype(np.int64)
    incidence = sp.csr_matrix((np.ones(ne * nv), cells.ravel(),
                               np.arange(0, ne * nv + 1, nv)), shape=(ne, n))
    pattern = (incidence.T @ incidence).tocsr()
    pattern.sort_indices()
    indptr = pattern.indptr.astype(np.int64)
    indices = pattern.indices.astype(np.int32 if n < 2**31 else np.int64)
    keys = np.repeat(np.arange(n, dtype=np.int64), np.diff(indptr)) * n + indices
    slot = np.searchsorted(keys, (cells[:, :, None] * n + cells[:, None, :]).ravel())
    return indptr, indices, slot


def block_data(pattern, component, d):
    """The (nnzb, d, d) blocks of vector P1 summed into the node pattern of
    :func:`node_pattern`: ``component(a, b)`` gives the (ne, nv, nv) entries
    of the element matrices between the dofs d·node_i + a and d·node_j + b;
    each component is summed over the cells by one bincount."""
    _, indices, slot = pattern
    nnzb = indices.size
    data = np.empty((nnzb, d, d))
    for a in range(d):
        for b in range(d):
            data[:, a, b] = np.bincount(slot, weights=component(a, b).ravel(), minlength=nnzb)
    return data


def block_matrix(pattern, data):
    """The block (BSR) matrix of blocks ``data`` (nnzb, d, d) on the node
    pattern: block (r, c) couples the dofs d·r + a and d·c + b."""
    indptr, indices, _ = pattern
    n = (indptr.size - 1) * data.shape[1]
    return sp.bsr_matrix((data, indices, indptr), shape=(n, n))


def stiffness_parts(mesh, geometry=None):
    """(K_λ, K_μ): ∫ div u div v and ∫ 2 ε(u):ε(v) for vector P1, as block
    (BSR) matrices of d × d blocks on one node pattern (a combination
    λ K_λ + μ K_μ is then one sum of their data and one conversion to CSR:
    :meth:`~adhesive_contact.fem.assembly.Assembly.stiffness`).

    With g_i the gradients of the barycentric coordinates and |e| the cell
    measure, the element blocks are (K_λ)_ij^ab = |e| g_i[a] g_j[b] and
    (K_μ)_ij^ab = |e| (g_i[b] g_j[a] + δ_ab g_i·g_j): the μ block (a, b) is
    the λ block (b, a) plus δ_ab |e| g_i·g_j. So the cells are summed d² + 1
    times (:func:`block_data`), not 2 d², into the one node pattern of
    :func:`node_pattern`. ``geometry`` is :func:`gradients` of the mesh when
    the caller has it already."""
    g, vol = geometry or gradients(mesh)
    d = g.shape[2]
    gv = g * vol[:, None, None]                       # |e| g_i
    pattern = node_pattern(mesh)
    lam = block_data(pattern, lambda a, b: gv[:, :, None, a] * g[:, None, :, b], d)
    _, indices, slot = pattern
    G = np.bincount(slot, weights=np.einsum("eia,eja->eij", gv, g).ravel(),
                    minlength=indices.size)           # Σ_e |e| g_i·g_j
    mu = lam.transpose(0, 2, 1) + G[:, None, None] * np.eye(d)
    return block_matrix(pattern, lam), block_matrix(pattern, mu)


def symmetric_pairs(d):
    """The entries (b, c), b ≤ c, of a symmetric d × d tensor, in the order of
    :func:`strain_operator`'s rows, and for each of the d² entries (b, c)
    its position among them (``full``: ``values[..., full]`` reshaped
    (..., d, d) is the whole tensor)."""
    pairs = [(b, c) for b in range(d) for c in range(b, d)]
    full = np.array([pairs.index((min(b, c), max(b, c))) for b in range(d) for c in range(d)])
    return pairs, full


def strain_operator(mesh, geometry=None):
    """Sparse B (ne·d(d+1)/2, ndofs): (B u) reshaped (ne, d(d+1)/2) is ε(u)
    per cell at the entries b ≤ c of :func:`symmetric_pairs`
    (``geometry`` as for :func:`stiffness_parts`).

    Row (e, b, c) is ε_bc = ½ (∂_c u_b + ∂_b u_c): of the dof φ_i e_a of
    cell e it takes ½ (δ_ab g_i[c] + δ_ac g_i[b]), nonzero for a ∈ {b, c}
    only. Those entries are written straight into the CSR arrays, and only
    the rows b ≤ c (ε_cb = ε_bc): 36 a tetrahedron, against 60 for all nine
    rows and 108 for all (i, a). For the 1.9e6 tetrahedra of a 1e6-dof box
    all nine rows took 6 s and 1.5 GB to build (13 s and 4 GB with the
    dense (e, b, c, i, a) array)."""
    g, _ = geometry or gradients(mesh)
    ne, nv, d = g.shape
    dofs = element_dofs(mesh)                        # (ne, nv·d), local i·d + a
    pairs, _ = symmetric_pairs(d)
    entries = [(b, c, i, a) for b, c in pairs for i in range(nv)
               for a in sorted({b, c})]              # row-major: row (b, c), then (i, a)
    index = np.int32 if max(ne * len(entries), d * mesh.p.shape[1]) < 2**31 else np.int64
    data = np.empty((ne, len(entries)))
    cols = np.empty((ne, len(entries)), dtype=index)
    for k, (b, c, i, a) in enumerate(entries):
        data[:, k] = 0.5 * ((a == b) * g[:, i, c] + (a == c) * g[:, i, b])
        cols[:, k] = dofs[:, i * d + a]
    per_row = [nv * len({b, c}) for b, c in pairs]
    indptr = np.concatenate([[0], np.cumsum(np.tile(per_row, ne))]).astype(index)
    B = sp.csr_matrix((data.ravel(), cols.ravel(), indptr),
                      shape=(ne * len(pairs), d * mesh.p.shape[1]))
    B.eliminate_zeros()
    B.sort_indices()
    return B


class CellLoad:
    """The body-force load ⟨f, v⟩_Ω of P1 test functions from f at the
    points of a Gauss rule of degree ``intorder``, cell by cell,

        F_{d·i + c} = Σ_{e ∋ i} Σ_q φ_i(ξ_q) |det J_e| w_q f_c(x_eq),

    as one contraction per component over the cells (einsum) summed into
    the nodes (bincount). Nothing of size cells × points × nodes is kept: a
    sparse map would hold (d + 1) nq entries per cell and component, 3 GB
    for the 1.9e6 tetrahedra of a 1e6-dof box at nq = 11.

    ``points`` (d, ne·nq), ordered cell by cell (column e·nq + q), are where
    f is evaluated, made on first use; a field constant in space needs only
    :meth:`uniform` and its value at one point of Ω, ``anchor`` (d, 1).
    """

    def __init__(self, mesh, intorder):
        p, t = mesh.p, mesh.t
        d = p.shape[0]
        X, W = get_quadrature(RefTri if d == 2 else RefTet, intorder)
        self.phi = np.vstack([1.0 - X.sum(axis=0), X])                   # (d+1, nq)
        _, vol = gradients(mesh)
        self.dx = (vol * factorial(d))[:, None] * W[None, :]            # (ne, nq)
        self.coordinates, self.cells, self.npoints, self.dim = p, t, p.shape[1], d
        self.anchor = p[:, :1]
        # ∫_Ω φ_i: the load of a unit field, for fields constant in space
        self.mass = np.bincount(t.ravel(), (self.dx @ self.phi.T).T.ravel(),
                                minlength=p.shape[1])

    @functools.cached_property
    def points(self):
        """The quadrature points x_eq (d, ne·nq): 500 MB for a 1e6-dof box."""
        p, t = self.coordinates, self.cells
        return np.einsum("ien,iq->enq", p[:, t].transpose(1, 0, 2),
                         self.phi).reshape(self.dim, -1)

    def __call__(self, values):
        """F (d·npoints,) of f_c(x_eq) = ``values[c]`` (d, ne·nq)."""
        d, (ne, nq) = self.dim, self.dx.shape
        out = np.empty((self.npoints, d))
        for c in range(d):
            local = np.einsum("eq,iq->ie", values[c].reshape(ne, nq) * self.dx, self.phi)
            out[:, c] = np.bincount(self.cells.ravel(), local.ravel(), minlength=self.npoints)
        return out.ravel()

    def uniform(self, value):
        """F of a field constant in space, f = ``value`` (d,): f_c ∫_Ω φ_i."""
        return (self.mass[:, None] * np.asarray(value, dtype=float)[None, :]).ravel()
