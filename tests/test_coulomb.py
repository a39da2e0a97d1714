"""The Coulomb-type friction bound μ p_ν(β, u_ν)_+ (laws "coulomb";
docs/model.md, "Coulomb-type friction"): a block pressed and sheared on a
compliant flat reaches Q = μ N exactly once every node slides, node by node
with the bound at the step's own pressure (the fixed point on p_ν); no
friction where the surface has separated; the law frozen at a pressure;
the scene refusal without a normal compliance."""

import numpy as np
import pytest

from adhesive_contact import SceneError, build_problem, parse_scene, solve
from adhesive_contact.laws import AdhesiveCompliance, Coulomb, FrictionSum, Tresca
from adhesive_contact.postprocess import reaction_sides, reactions

MU = 0.3
BLOCK = """
title = "Coulomb onset: a block pressed and sheared on a compliant flat"
dim = 2

[mesh]
domain = "rectangle"
size = [1.0, 0.5]
cells = [20, 10]

[boundary]
contact = ["bottom"]

[boundary.displacement]
top = ["0.002*t", "{uy}"]

[material]
E = 1000.0
nu = 0.3

[contact.normal]
law = "{normal}"
c = 2000.0

[[contact.friction]]
law = "coulomb"
mu = 0.3

[time]
T = 1.0
steps = 10
"""


def block(uy="-0.001", normal="compliance"):
    return BLOCK.format(uy=uy, normal=normal)


def run(text):
    problem = build_problem(parse_scene(text))
    solution = solve(problem)
    assert solution.success, solution.message
    top = reaction_sides(problem).index("top")
    R = reactions(solution)[:, top]
    # nodal frames at Γ_C: component 0 along the outward normal (the force of
    # Γ_C on the body; −it > 0 in compression), 1 tangential
    return SimpleRun(problem, solution, R[:, 0], -R[:, 1],
                     -solution.contact_force[:, :, 0], solution.contact_force[:, :, 1])


class SimpleRun:
    def __init__(self, problem, solution, Q, N, fn, ft):
        self.problem, self.solution, self.Q, self.N, self.fn, self.ft = (
            problem, solution, Q, N, fn, ft)


def test_a_sheared_block_reaches_mu_N_once_every_node_slides():
    r = run(block())
    nodes = r.problem.boundary.nodes.size
    full = (~r.solution.stuck).sum(axis=1) == nodes
    assert not full[1] and full[-1]                   # sticks in part first, slides at the end
    # both the step and the fixed point on p_ν stop at 1e-10 of the forces
    np.testing.assert_allclose(np.abs(r.Q[full]), MU * r.N[full], rtol=1e-8)
    assert np.all(np.abs(r.Q[~full]) < MU * r.N[~full] * (1 - 1e-3))
    # node by node at the first full slide, where the pressure has just
    # changed: the bound is that of the step's own pressure, not the last one's
    n = int(np.argmax(full))
    assert abs(r.N[n] - r.N[n - 1]) > 1e-3 * r.N[n]
    np.testing.assert_allclose(np.abs(r.ft[n]), MU * r.fn[n], rtol=0, atol=1e-8 * r.fn[n].max())
    assert np.abs(np.abs(r.ft[n]) - MU * r.fn[n - 1]).max() > 1e-4 * r.fn[n].max()


def test_no_friction_where_the_surface_has_separated():
    r = run(block(uy="0.0005 - 0.002*x"))             # the left end lifted off the flat
    scale = r.fn.max()
    separated = r.fn <= 1e-12 * scale
    assert separated.sum(axis=1).max() >= 3
    assert np.abs(r.ft[separated]).max() <= 1e-12 * scale
    assert np.all(np.abs(r.ft) <= MU * np.maximum(r.fn, 0) + 1e-8 * scale)


def test_the_law_frozen_at_a_pressure_is_tresca_with_mu_p_plus():
    normal = AdhesiveCompliance(c=100.0, gamma=50.0, L=0.1)
    beta, r = np.array([1.0, 1.0, 0.5]), np.array([0.02, -0.05, 0.0])
    p = normal.value(beta, r)                         # 2, −2.5 (the glue pulls), 0
    frozen = FrictionSum((Coulomb(MU), Tresca(0.1))).with_pressure(p)
    np.testing.assert_allclose(frozen.kink(beta), [MU * 2.0 + 0.1, 0.1, 0.1], rtol=1e-15)
    s = np.array([0.3, 0.2, 0.0])
    np.testing.assert_allclose(frozen.phi(beta, s), [(MU * 2 + 0.1) * 0.3, 0.1 * 0.2, 0.0])
    assert frozen.pressure_dependent is False
    with pytest.raises(ValueError, match="freeze it at a normal pressure"):
        Coulomb(MU).kink(beta)


def test_coulomb_without_a_normal_compliance_is_refused():
    text = block().replace('[contact.normal]\nlaw = "compliance"\nc = 2000.0\n', "")
    with pytest.raises(SceneError, match="law 'coulomb' has the bound μ p_ν.*needs "
                                         r"\[contact.normal\] law 'compliance'"):
        parse_scene(text)
