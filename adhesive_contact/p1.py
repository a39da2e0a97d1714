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
same quantities from scikit-fem's forms (:mod:`adhesive_contact.assembly`)
agree to round-off (a test); these kernels are several times faster.
"""

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
    det = np.linalg.det(J)
    inv_T = np.linalg.inv(J).transpose(0, 2, 1)                                 # J^{-T}
    ref = np.vstack([-np.ones((1, d)), np.eye(d)])                              # (d+1, d)
    g = np.einsum("eab,ib->eia", inv_T, ref)
    return g, np.abs(det) / factorial(d)


def element_dofs(mesh):
    """(ne, (d+1)·d) the global vector dofs d·node_i + a of each cell, in
    the local order l = i·d + a."""
    d = mesh.p.shape[0]
    return (d * mesh.t.T[:, :, None] + np.arange(d)[None, None, :]).reshape(mesh.t.shape[1], -1)


def stiffness_parts(mesh):
    """(K_λ, K_μ): ∫ div u div v and ∫ 2 ε(u):ε(v) for vector P1, CSR.

    Both share one sparsity pattern, so they go through one sparse
    conversion: the element matrices as the real and imaginary parts of one
    complex array (the duplicates of each part are summed separately)."""
    g, vol = gradients(mesh)
    ne, nv, d = g.shape
    n, m = d * mesh.p.shape[1], nv * d
    flat = g.reshape(ne, m)
    # K_λ: |e| g_i[a] g_j[b]
    local = (vol[:, None, None] * flat[:, :, None] * flat[:, None, :]).astype(complex)
    # K_μ: |e| (δ_ab g_i·g_j + g_i[b] g_j[a]), local index (i, a) × (j, b)
    G = np.einsum("eia,eja->eij", g, g)
    mu = G[:, :, None, :, None] * np.eye(d)[None, None, :, None, :]
    mu += g[:, :, None, None, :] * g.transpose(0, 2, 1)[:, None, :, :, None]
    local.imag = vol[:, None, None] * mu.reshape(ne, m, m)
    dofs = element_dofs(mesh).astype(np.int32 if n < 2**31 else np.int64)
    rows = np.broadcast_to(dofs[:, :, None], (ne, m, m)).ravel()
    cols = np.broadcast_to(dofs[:, None, :], (ne, m, m)).ravel()
    K = sp.coo_matrix((local.ravel(), (rows, cols)), shape=(n, n)).tocsr()
    K.sum_duplicates()
    real = sp.csr_matrix((K.data.real.copy(), K.indices, K.indptr), shape=(n, n))
    imag = sp.csr_matrix((K.data.imag.copy(), K.indices, K.indptr), shape=(n, n))
    return real, imag


def strain_operator(mesh):
    """Sparse B (ne·d·d, ndofs): (B u) reshaped (ne, d, d) is ε(u) per cell."""
    g, _ = gradients(mesh)
    ne, nv, d = g.shape
    eye = np.eye(d)
    # ε_bc of u = φ_i e_a: ½ (δ_ab g_i[c] + δ_ac g_i[b]), indexed (e, b, c, i, a)
    eps = 0.5 * (np.einsum("ab,eic->ebcia", eye, g) + np.einsum("ac,eib->ebcia", eye, g))
    rows = np.broadcast_to(np.arange(ne * d * d).reshape(ne, d * d, 1), (ne, d * d, nv * d))
    cols = np.broadcast_to(element_dofs(mesh)[:, None, :], (ne, d * d, nv * d))
    B = sp.csr_matrix((eps.reshape(ne, d * d, nv * d).ravel(), (rows.ravel(), cols.ravel())),
                      shape=(ne * d * d, d * mesh.p.shape[1]))
    B.eliminate_zeros()
    return B


def cell_load_map(mesh, intorder):
    """Sparse maps M_c with ⟨f, v⟩_Ω = Σ_c M_c f_c(x_q), and the points x_q.

    A Gauss rule of degree ``intorder`` on the reference simplex, points
    ordered cell by cell (column e·nq + q); M_c[d·node_i + c, e·nq + q] =
    φ_i(ξ_q) |det J_e| w_q.
    """
    p, t = mesh.p, mesh.t
    d, ne = p.shape[0], t.shape[1]
    X, W = get_quadrature(RefTri if d == 2 else RefTet, intorder)
    nq = W.size
    phi = np.vstack([1.0 - X.sum(axis=0), X])                       # (d+1, nq)
    _, vol = gradients(mesh)
    dx = (vol * factorial(d))[:, None] * W[None, :]                 # (ne, nq)
    points = np.einsum("ien,iq->enq", p[:, t].transpose(1, 0, 2), phi).reshape(d, -1)
    cols = np.broadcast_to(np.arange(ne * nq).reshape(ne, 1, nq), (ne, d + 1, nq))
    values = (phi[None, :, :] * dx[:, None, :]).ravel()
    maps = []
    for c in range(d):
        rows = np.broadcast_to((d * t.T + c)[:, :, None], (ne, d + 1, nq))
        maps.append(sp.csr_matrix((values, (rows.ravel(), cols.ravel())),
                                  shape=(d * p.shape[1], ne * nq)))
    return maps, points
