"""The contact terms of a step as a function of the contact unknowns.

    Φ(z) = Σ_q w_q [P_ν(β_q, (N z)_q) + j_τ(β_q, (T z)_q)]

(docs/scheme.md ('What a step solves')), with N, T the traces of :mod:`adhesive_contact.contact_boundary`
restricted to the unknowns the step solves for, β_q the P0 bonding of the
facet holding q, and j_τ(β, ξ) = φ(β, |ξ|) radial (:mod:`adhesive_contact.laws`).

``gradient`` is ∇Φ where Φ is differentiable; at ξ_q = 0 the friction part
is left out (its Clarke subdifferential is the ball of radius
w_q φ'(β_q, 0+), handled by the step solver through ``kink``).
``hessian`` is an element of the generalised Hessian: for the friction at
ξ ≠ 0, φ'' ξ̂ξ̂ᵀ + (φ'/|ξ|)(I − ξ̂ξ̂ᵀ); at ξ = 0, φ''(0+) I.
"""

import numpy as np
import scipy.sparse as sp


class ContactEnergy:
    """Φ on the step's unknowns: the laws and the traces, built once per run;
    β_n is set per step with :meth:`set_bonding`.

    Parameters
    ----------
    boundary : ContactBoundary
    columns : (nz,) which of the full nodal-frame unknowns (nc·d, node-major)
        the step solves for
    normal_law, friction : laws (friction a FrictionSum or None)
    beta : (nf,) β per contact facet
    within : (positions, size), optional
        Φ as a function of a longer vector (the free dofs,
        :mod:`adhesive_contact.scheme.full_system`) that holds the unknowns
        at ``positions``; by default the vector is the unknowns alone.

    Attributes
    ----------
    unknowns : (nz,) int, where the contact unknowns are in the vector
    """

    def __init__(self, boundary, columns, normal_law, friction, beta, within=None):
        self.boundary = boundary
        self.w = boundary.weights
        positions, size = within if within is not None else (np.arange(columns.size),
                                                            columns.size)
        self.unknowns = np.asarray(positions, dtype=np.int64)

        def trace(t):   # t restricted to the unknowns, as a map from the vector
            t = t[:, columns].tocsr()
            return sp.csr_matrix((t.data, self.unknowns[t.indices], t.indptr),
                                 shape=(t.shape[0], size))

        self.N = trace(boundary.normal_trace)
        self.normal_law = normal_law
        self.friction = friction
        self.T = ([trace(t) for t in boundary.tangential_trace]
                  if friction is not None else [])
        if self.T:
            # all tangential traces stacked (m·nq, nz), and the positions of
            # the point blocks (i, j) of the friction Hessian in (m·nq)²
            nq, m = self.w.size, len(self.T)
            self.T_all = sp.vstack(self.T).tocsr()
            q = np.arange(nq)
            self.block_rows = (np.arange(m)[:, None, None] * nq + q).repeat(m, axis=1)
            self.block_cols = (np.arange(m)[None, :, None] * nq + q).repeat(m, axis=0)
        self.nz = size
        self.set_bonding(beta)

    def set_bonding(self, beta):
        """Use β_n (nf,) per contact facet from now on."""
        self.beta = self.boundary.at_points(beta)

    def _xi(self, z):
        return np.stack([t @ z for t in self.T], axis=-1)  # (nq, d−1)

    def value(self, z):
        out = 0.0
        if self.normal_law.active:
            out += self.w @ self.normal_law.potential(self.beta, self.N @ z)
        if self.friction is not None:
            out += self.w @ self.friction.potential(self.beta, self._xi(z))
        return float(out)

    def gradient(self, z):
        g = np.zeros(self.nz)
        if self.normal_law.active:
            g += self.N.T @ (self.w * self.normal_law.value(self.beta, self.N @ z))
        if self.friction is not None:
            force = self.w[:, None] * self.friction.gradient(self.beta, self._xi(z))
            for i, t in enumerate(self.T):
                g += t.T @ force[:, i]
        return g

    def hessian(self, z, s_floor=0.0):
        """Sparse (nz, nz); ``s_floor`` bounds |ξ| from below in φ''."""
        H = sp.csr_matrix((self.nz, self.nz))
        if self.normal_law.active:
            d = self.w * self.normal_law.derivative(self.beta, self.N @ z)
            H = H + self.N.T @ sp.diags(d) @ self.N
        if self.friction is not None:
            xi = self._xi(z)
            s = np.linalg.norm(xi, axis=-1)
            sf = np.maximum(s, s_floor)
            dd = self.friction.ddphi(self.beta, sf)
            m = len(self.T)
            if m == 1:
                blocks = dd[:, None, None] * np.ones((1, 1, 1))
            else:
                e = np.where(s[:, None] > 0, xi / np.where(s > 0, s, 1.0)[:, None], 0.0)
                ee = e[:, :, None] * e[:, None, :]
                tang = np.where(s > 0, self.friction.dphi(self.beta, sf) / sf, 0.0)
                blocks = (dd[:, None, None] * np.where(s[:, None, None] > 0, ee, np.eye(m))
                          + tang[:, None, None] * (np.eye(m) - ee))
            # Σ_ij T_iᵀ diag(w b_ij) T_j as one product T_allᵀ B T_all
            n = m * self.w.size
            B = sp.csr_matrix(((self.w[:, None, None] * blocks).transpose(1, 2, 0).ravel(),
                               (self.block_rows.ravel(), self.block_cols.ravel())),
                              shape=(n, n))
            H = H + self.T_all.T @ B @ self.T_all
        return H.tocsr()

    def node_kink(self, nodes_of_points, n_nodes):
        """κ_a = Σ_{q at a} w_q φ'(β_q, 0+) per contact node (nodal rule)."""
        if self.friction is None:
            return np.zeros(n_nodes)
        keep = nodes_of_points >= 0   # clamped vertices carry no unknown
        return np.bincount(nodes_of_points[keep],
                           (self.w * self.friction.kink(self.beta))[keep], minlength=n_nodes)
