"""The contact terms of a step as a function of the contact unknowns.

    Φ(z) = Σ_q w_q [P_ν(β_q, (N z)_q) + j_τ(β_q, (T z)_q)]

(docs/scheme.md ('What a step solves')), with N, T the traces of :mod:`adhesive_contact.fem.contact_boundary`
restricted to the unknowns the step solves for, β_q the P0 bonding of the
facet holding q, and j_τ(β, ξ) = φ(β, |ξ|) radial (:mod:`adhesive_contact.laws`).
A frame component the boundary holds is no unknown but enters the traces
at its prescribed value: (N z)_q stands for N_F z + N_D z_D, z_D the held
values of the step (:meth:`ContactEnergy.set_held`).

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
        # the scene's friction; ``friction`` is it with a Coulomb bound frozen
        # at the pressure of :meth:`set_pressure` (the same object without one)
        self.friction_law = self.friction = friction
        self.pressure_dependent = friction is not None and friction.pressure_dependent
        self.T = ([trace(t) for t in boundary.tangential_trace]
                  if friction is not None else [])
        self.nz = size
        self.hessian_map = HessianMap(self.N if normal_law.active else None, self.T,
                                      self.w.size, size)
        # the traces of the held components, and their part of u_ν, u_τ
        self.held = np.flatnonzero(boundary.held.ravel())
        self.N_held = boundary.normal_trace[:, self.held].tocsr()
        self.T_held = ([t[:, self.held].tocsr() for t in boundary.tangential_trace]
                       if friction is not None else [])
        self.n0 = self.t0 = None
        self.set_bonding(beta)
        if self.pressure_dependent:
            self.set_pressure(None)

    def set_bonding(self, beta):
        """Use β_n (nf,) per contact facet from now on."""
        self.beta = self.boundary.at_points(beta)

    def set_pressure(self, z):
        """Freeze a Coulomb bound μ p_ν(β_q, u_ν,q)_+ at the normal pressure
        of ``z`` (at 0 for None) from now on (docs/model.md, "Coulomb-type
        friction"); returns p_q (nq,). Nothing for other friction laws."""
        if not self.pressure_dependent:
            return None
        pressure = (np.zeros(self.w.size) if z is None
                    else self.normal_law.value(self.beta, self.normal(z)))
        self.friction = self.friction_law.with_pressure(pressure)
        return pressure

    def set_pressure_values(self, pressure):
        """Freeze a Coulomb bound at the given pressure (nq,) from now on."""
        if self.pressure_dependent:
            self.friction = self.friction_law.with_pressure(np.asarray(pressure, dtype=float))

    def set_held(self, values):
        """Use the held values z_D from now on: ``values`` (nc·d,) the frame
        components of g_D(t_n) (:meth:`~adhesive_contact.fem.contact_boundary.ContactBoundary.held_values`),
        read at the held components; None for none held."""
        if values is None or self.held.size == 0:
            self.n0 = self.t0 = None
            return
        v = values[self.held]
        self.n0 = self.N_held @ v
        self.t0 = np.stack([t @ v for t in self.T_held], axis=-1) if self.T_held else None

    def normal(self, z):
        """u_ν at the points (nq,)."""
        r = self.N @ z
        return r if self.n0 is None else r + self.n0

    def tangential(self, z):
        """u_τ at the points (nq, d−1) (with friction)."""
        xi = np.stack([t @ z for t in self.T], axis=-1)
        return xi if self.t0 is None else xi + self.t0

    def held_gradient(self, z):
        """∂Φ/∂z_D (nh,): the gradient of Φ in the held frame components
        (those of ``held``, node-major indices into the nc·d frame
        components) at z, the held values of :meth:`set_held` in place;
        −∂Φ/∂z_D is the force of the contact laws on the body along them.
        At ξ_q = 0 the friction part is left out, as in :meth:`gradient`
        (its least-norm subgradient; the kink's force along a held slip is
        not determined by the step)."""
        g = np.zeros(self.held.size)
        if self.held.size == 0:
            return g
        if self.normal_law.active:
            g += self.N_held.T @ (self.w * self.normal_law.value(self.beta, self.normal(z)))
        if self.friction is not None:
            force = self.w[:, None] * self.friction.gradient(self.beta, self.tangential(z))
            for i, t in enumerate(self.T_held):
                g += t.T @ force[:, i]
        return g

    def value(self, z):
        out = 0.0
        if self.normal_law.active:
            out += self.w @ self.normal_law.potential(self.beta, self.normal(z))
        if self.friction is not None:
            out += self.w @ self.friction.potential(self.beta, self.tangential(z))
        return float(out)

    def gradient(self, z):
        g = np.zeros(self.nz)
        if self.normal_law.active:
            g += self.N.T @ (self.w * self.normal_law.value(self.beta, self.normal(z)))
        if self.friction is not None:
            force = self.w[:, None] * self.friction.gradient(self.beta, self.tangential(z))
            for i, t in enumerate(self.T):
                g += t.T @ force[:, i]
        return g

    def hessian(self, z, s_floor=0.0, kink_free=False):
        """Sparse (nz, nz); ``s_floor`` bounds |ξ| from below in φ''.

        H = Nᵀ diag(w p_ν') N + Σ_ij T_iᵀ diag(w b_ij) T_j, with b the
        point blocks of the friction Hessian in the module doc, entered
        through :class:`HessianMap` (one sparse product, no sparse algebra
        per call). With ``kink_free`` it is the Hessian of Φ − Σ_q w_q
        φ'(β_q, 0+) |ξ_q|, the contact terms without the kink's cone (the
        smooth part F of the semismooth step method,
        :mod:`adhesive_contact.step_methods.newton`): the tangential
        curvature (φ'(|ξ|) − φ'(0+))/|ξ| (I − ξ̂ξ̂ᵀ) in place of
        φ'/|ξ| (I − ξ̂ξ̂ᵀ), bounded as ξ → 0 (the same in 2D)."""
        normal = blocks = None
        if self.normal_law.active:
            normal = self.w * self.normal_law.derivative(self.beta, self.normal(z))
        if self.friction is not None:
            xi = self.tangential(z)
            s = np.linalg.norm(xi, axis=-1)
            sf = np.maximum(s, s_floor)
            dd = self.friction.ddphi(self.beta, sf)
            m = len(self.T)
            if m == 1:
                blocks = dd[:, None, None]
            else:
                e = np.where(s[:, None] > 0, xi / np.where(s > 0, s, 1.0)[:, None], 0.0)
                ee = e[:, :, None] * e[:, None, :]
                slope = self.friction.dphi(self.beta, sf)
                if kink_free:
                    slope = slope - self.friction.kink(self.beta)
                tang = np.where(s > 0, slope / np.where(sf > 0, sf, 1.0), 0.0)
                blocks = (dd[:, None, None] * np.where(s[:, None, None] > 0, ee, np.eye(m))
                          + tang[:, None, None] * (np.eye(m) - ee))
            blocks = self.w[:, None, None] * blocks
        return self.hessian_map(normal, blocks)

    def node_kink(self, nodes_of_points, n_nodes):
        """κ_a = Σ_{q at a} w_q φ'(β_q, 0+) per contact node (nodal rule)."""
        if self.friction is None:
            return np.zeros(n_nodes)
        keep = nodes_of_points >= 0   # every point of the nodal rule reads a node
        return np.bincount(nodes_of_points[keep],
                           (self.w * self.friction.kink(self.beta))[keep], minlength=n_nodes)


def _row_pairs(A, B):
    """For csr A, B with the same rows: every pair of a nonzero of A and a
    nonzero of B in the same row q, as (q, column in A, column in B,
    A value · B value)."""
    A, B = A.tocsr(), B.tocsr()
    na, nb = np.diff(A.indptr), np.diff(B.indptr)
    row = np.repeat(np.arange(A.shape[0]), na)             # the row of each nonzero of A
    a = np.repeat(np.arange(A.nnz), nb[row])                # nonzero of A, once per partner
    first = np.repeat(np.cumsum(nb[row]) - nb[row], nb[row])
    b = B.indptr[row[a]] + np.arange(a.size) - first        # its partners in B
    return row[a], A.indices[a], B.indices[b], A.data[a] * B.data[b]


class HessianMap:
    """The Hessian of Φ as a linear map of its point coefficients:

        H = Nᵀ diag(n) N + Σ_ij T_iᵀ diag(b_ij) T_j,

    n (nq,) and b (nq, m, m) per quadrature point q. Entry (k, l) of H is
    Σ_q n_q N_qk N_ql + Σ_qij b_qij (T_i)_qk (T_j)_ql: linear in (n, b), so
    H's data is one sparse product E [n; b] with E (nnz H, nq (1 + m²))
    built once, on the pattern of all entries any coefficients can fill."""

    def __init__(self, N, T, nq, size):
        rows, cols, coefs, values = [], [], [], []
        m = len(T)
        if N is not None:
            q, k, l, v = _row_pairs(N, N)
            rows.append(k), cols.append(l), coefs.append(q), values.append(v)
        for i, Ti in enumerate(T):
            for j, Tj in enumerate(T):
                q, k, l, v = _row_pairs(Ti, Tj)
                # b_qij sits after the nq normal coefficients, at q·m² + i·m + j
                rows.append(k), cols.append(l), coefs.append(nq + (q * m + i) * m + j)
                values.append(v)
        cat = (lambda x: np.concatenate(x) if x else np.zeros(0, dtype=np.int64))
        rows, cols, coefs, values = cat(rows), cat(cols), cat(coefs), cat(values)
        # row-major keys in 64 bits (the traces' indices are 32-bit, and k·size
        # passes 2³¹ from 46 341 unknowns on: the free dofs of a large mesh)
        keys, entry = np.unique(rows.astype(np.int64) * size + cols, return_inverse=True)
        self.indices = (keys % size).astype(np.int32)
        self.indptr = np.concatenate([[0], np.cumsum(np.bincount(keys // size,
                                                                 minlength=size))]).astype(np.int32)
        self.expansion = sp.csr_matrix((values, (entry, coefs)),
                                       shape=(keys.size, nq * (1 + m * m)))
        self.nq, self.size = nq, size

    def __call__(self, normal=None, blocks=None):
        """H (csr) for n = ``normal`` (nq,) and b = ``blocks`` (nq, m, m);
        None for a term the energy does not have."""
        coef = np.zeros(self.expansion.shape[1])
        if normal is not None:
            coef[:self.nq] = normal
        if blocks is not None:
            coef[self.nq:] = blocks.ravel()
        return sp.csr_matrix((self.expansion @ coef, self.indices.copy(), self.indptr.copy()),
                             shape=(self.size, self.size))
