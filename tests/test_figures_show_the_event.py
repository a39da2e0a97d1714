"""The figures of a run show its event (visuals/levels.py), read off the
figure objects (the times drawn, the axis along Γ_C, the colour limits,
where the legends are), not their pixels:

- ``[output] plot_times``: a list draws exactly those times; "auto" the
  levels where the run's activity is, and T (a load applied between
  t = 0.9 and 1.2 of T = 10 is drawn there, not at t = 2, 4, … 10);
- 3D maps at several times, each column on one colour scale set by the
  run's largest value; round-off drawn as zero; no offset text;
- β and tractions along the axis Γ_C extends most (by weighted spread);
- every legend inside its figure.
"""

from types import SimpleNamespace

import matplotlib.pyplot as plt
import numpy as np
import pytest
from conftest import law, scene_dict

from adhesive_contact import SceneError, build_problem, scene_from_dict, solve, visuals
from adhesive_contact.postprocess import normal_traction
from adhesive_contact.visuals.levels import (
    FLOOR,
    activity,
    contact_axis,
    floored,
    nearest_levels,
)
from adhesive_contact.visuals.studies import figure_by_key

#: pressed between t = 0.9 and 1.2 of T = 10, then held: no memory, no bonding
#: law, so nothing changes outside that window
WINDOW = {"mesh.size": [4.0, 0.5], "mesh.cells": [16, 2],
          "loads.body": ["0", "-200*minimum(maximum(t - 0.9, 0), 0.3)/0.3"],
          "contact.normal": law("compliance", c=1e3), "time.T": 10.0, "time.steps": 200}


def legend_times(ax):
    return [float(t.get_text().removeprefix("t = ")) for t in ax.get_legend().get_texts()]


@pytest.fixture(scope="module")
def window():
    return solve(build_problem(scene_from_dict(scene_dict(WINDOW))))


def test_auto_draws_where_the_load_changes_and_T(window):
    """Activity only in steps with t in (0.9, 1.2]; every level drawn but
    T lies there, and the traction figure's legend lists those times."""
    a = activity(window)
    busy = (window.t[1:] > 0.9) & (window.t[1:] <= 1.2 + 1e-9)
    assert a[busy].min() > 0 and a[~busy].max() <= 1e-9 * a.sum()
    levels = visuals.plot_levels(window)
    times = window.t[levels]
    assert times[-1] == 10.0 and len(times) == 5
    assert np.all((times[:-1] > 0.9) & (times[:-1] <= 1.2 + 1e-9))
    fig = visuals.figure_contact_traction(window)
    assert legend_times(fig.axes[0]) == pytest.approx(times)
    beta = visuals.figure_beta(window)   # "auto": t = 0 too, what the glue starts from
    assert legend_times(beta.axes[0]) == pytest.approx(np.r_[0.0, times])
    plt.close("all")


def test_listed_plot_times_are_drawn_and_nothing_else():
    scene = scene_from_dict(scene_dict({**WINDOW, "time.T": 2.0, "time.steps": 40,
                                        "output": {"plot_times": [1.2, 0.95, 2.0]}}))
    assert scene.plot_times == (0.95, 1.2, 2.0)
    assert scene.resolved["output"]["plot_times"] == [0.95, 1.2, 2.0]
    sol = solve(build_problem(scene))
    assert legend_times(visuals.figure_contact_traction(sol).axes[0]) == [0.95, 1.2, 2.0]
    assert legend_times(visuals.figure_beta(sol).axes[0]) == [0.95, 1.2, 2.0]
    plt.close("all")
    # the level nearest each time; none beyond a run that stopped early
    t = np.linspace(0.0, 1.0, 11)
    assert nearest_levels(t, (0.26, 0.5, 0.94)).tolist() == [3, 5, 9]
    assert nearest_levels(t[:4], (0.26, 0.9)).tolist() == [3]


@pytest.mark.parametrize("value, message", [
    ([], "must be \"auto\" or a list of 1 to 12 times (numbers), got []"),
    ("soon", "must be \"auto\" or a list of 1 to 12 times (numbers), got 'soon'"),
    ([0.5, 3.0], "every time must lie in [0, T] = [0, 1], got 3"),
])
def test_bad_plot_times_are_refused_naming_the_key(value, message):
    with pytest.raises(SceneError) as info:
        scene_from_dict(scene_dict({"output": {"plot_times": value}}))
    assert str(info.value) == f"output.plot_times: {message}"


BOX = {"dim": 3, "mesh": {"domain": "box", "size": [1.0, 0.5, 3.0], "cells": [2, 1, 6]},
       "boundary": {"dirichlet": [], "contact": ["bottom"],
                    "displacement": {"top": ["0", "0.05*t", "0"]}},
       "material": {"E": 1000.0, "nu": 0.3},
       "contact": {"normal": law("adhesive_compliance", c=1e3, gamma=500.0, L=0.01),
                   "bonding": {"law": "fremond", "beta0": 1.0, "gamma_nu": 1e3,
                               "gamma_tau": 0.0, "eps_a": 0.0, "L": 0.01}},
       "time": {"T": 1.0, "steps": 8}}


@pytest.fixture(scope="module")
def box():
    return solve(build_problem(scene_from_dict(scene_dict(base=BOX))))


def test_the_3d_map_has_a_row_per_time_on_one_scale_per_column(box):
    fig = visuals.figure_contact_map(box)
    levels = visuals.plot_levels(box, 4)
    maps = [ax for ax in fig.axes if ax.get_title().startswith("t = ")]
    assert len(maps) == 3 * len(levels) and len(levels) > 1
    assert sorted({float(ax.get_title()[4:]) for ax in maps}) == pytest.approx(box.t[levels])
    bars = [ax for ax in fig.axes if ax not in maps]
    assert len(bars) == 3
    # the traction column: symmetric about 0, at the run's largest |−σ_ν| over all levels
    largest = np.abs(normal_traction(box)).max()
    lo, hi = bars[1].get_xlim()
    assert (lo, hi) == pytest.approx((-largest, largest), rel=1e-12)
    assert bars[0].get_xlim() == (0.0, 1.0)
    fig.canvas.draw()
    assert all(b.xaxis.get_offset_text().get_text() == "" for b in bars)
    # along z, the longest extent of the bottom (1 × 3 in x, z)
    beta = visuals.figure_beta(box)
    assert beta.axes[0].get_xlabel().startswith("z ")
    assert visuals.figure_contact_traction(box).axes[2].get_xlabel().startswith("z along Γ_C")
    plt.close("all")


def test_a_nearly_constant_stress_draws_no_offset_text():
    """A box pressed uniformly (the top moved down, the bottom on rollers):
    von Mises is constant up to round-off, which a scale from its min to its
    max would show as an offset text; the scale runs from 0 to the max."""
    scene = scene_dict({"dim": 3, "mesh": {"domain": "box", "size": [1.0, 1.0, 1.0],
                                           "cells": [2, 2, 2]},
                        "boundary": {"dirichlet": [], "contact": [],
                                     "displacement": {"bottom": ["free", "0", "free"],
                                                      "left": ["0", "free", "free"],
                                                      "front": ["free", "free", "0"],
                                                      "top": ["free", "-0.01*t", "free"]}}})
    sol = solve(build_problem(scene_from_dict(scene)))
    fig = visuals.figure_deformed(sol)
    fig.canvas.draw()
    bar = fig.axes[-1]
    vm = visuals.deformed.cell_von_mises(sol, -1)
    assert np.ptp(vm) <= 1e-9 * vm.max()
    # the load grows with t: the largest stress over the levels drawn is that at T
    assert bar.get_xlim() == pytest.approx((0.0, vm.max()), rel=1e-12)
    assert bar.xaxis.get_offset_text().get_text() == ""
    plt.close("all")


def test_the_3d_deformed_view_is_drawn_at_the_plot_levels_on_one_scale(box):
    """One panel per plot level (at most 4, T last), titled by its time; one
    colour bar from 0 to the largest von Mises stress over those levels."""
    fig = visuals.figure_deformed(box)
    levels = visuals.plot_levels(box)
    levels = levels[np.unique(np.round(np.linspace(0, levels.size - 1, 4)).astype(int))] \
        if levels.size > 4 else levels
    panels = [ax for ax in fig.axes if ax.get_title().startswith("t = ")]
    assert len(panels) == len(levels) > 1
    assert [float(ax.get_title()[4:]) for ax in panels] == pytest.approx(box.t[levels], rel=1e-3)
    bar = [ax for ax in fig.axes if ax not in panels][0]
    mesh = box.problem.mesh
    owner = mesh.f2t[0, mesh.boundary_facets()]
    largest = max(visuals.deformed.cell_von_mises(box, n)[owner].max() for n in levels)
    assert bar.get_xlim() == pytest.approx((0.0, largest), rel=1e-12)
    plt.close("all")


def test_round_off_is_drawn_as_zero():
    values = np.array([1e-13, -3e-12, 0.5, np.nan, 2.0])
    out = floored(values, largest=2.0)
    assert out[:2].tolist() == [0.0, 0.0] and out[2] == 0.5 and np.isnan(out[3])
    # on the scale of a reference (the largest displacement): a slip of 1e-12
    # when |u| reaches 0.1 is round-off, even if it is the largest slip
    assert floored([1e-12], largest=1e-12, reference=0.1).tolist() == [0.0]
    assert floored([2 * FLOOR], largest=1.0).tolist() == [2 * FLOOR]


def test_the_axis_is_the_weighted_longest_extent_not_the_range():
    """Γ_C of 40 facets along x in [0, 4] (length 0.1 each) and 2 short
    facets of a rib spanning z in [0, 5]: the range would pick z, the
    area-weighted spread picks x."""
    xs = np.linspace(0.0, 4.0, 41)
    points = [(x, 0.0, 0.0) for x in xs] + [(0.0, 0.0, 0.0), (0.0, 0.0, 5.0)]
    p = np.array(points).T
    nodes = [(i, i + 1) for i in range(40)] + [(41, 42)]
    problem = SimpleNamespace(
        mesh=SimpleNamespace(p=p),
        boundary=SimpleNamespace(facets=np.arange(41), facet_nodes=np.array(nodes).T,
                                 measure=np.r_[np.full(40, 0.1), 0.01]))
    assert np.argmax(p.max(axis=1) - p.min(axis=1)) == 2
    assert contact_axis(problem) == 0


def inside(fig, legend):
    fig.canvas.draw()
    box, frame = legend.get_window_extent(), fig.bbox
    return (box.x0 >= frame.x0 - 1 and box.x1 <= frame.x1 + 1
            and box.y0 >= frame.y0 - 1 and box.y1 <= frame.y1 + 1)


def test_every_legend_lies_inside_its_figure(box, window):
    figures = [visuals.figure_contact_traction(window), visuals.figure_beta(window),
               visuals.figure_deformed(window), visuals.figure_contact_traction(box),
               visuals.figure_deformed(box)]
    # a sweep over T with three other keys of long names (the legend of
    # three columns of their settings was wider than the figure)
    keys = ["time.T", "contact.normal.c", "contact.friction.0.mu", "contact.bonding.gamma_nu"]
    rows = [{"time.T": T, "contact.normal.c": c, "contact.friction.0.mu": mu,
             "contact.bonding.gamma_nu": g, "outcome": "ok", "seconds": 1.0,
             "newton_total": 3, "beta_mean_T": 0.5, "normal_force_T": 1.0}
            for T in (1.0, 2.0) for c in (100.0, 1000.0) for mu in (0.2, 0.4)
            for g in (1e5, 2e5)]
    figures.append(figure_by_key(rows, keys, "time.T", "a sweep of four keys"))
    count = 0
    for fig in figures:
        legends = [ax.get_legend() for ax in fig.axes if ax.get_legend()] + fig.legends
        for legend in legends:
            assert inside(fig, legend), (fig.axes[0].get_title(), legend.get_title().get_text())
            count += 1
    assert count >= 7
    plt.close("all")


def test_a_run_that_kept_only_the_last_stress_is_drawn_by_displacement(box):
    """A streamed run keeps σ at T only: every panel is then coloured by |u|,
    on one scale from 0 to the largest |u| at a face over the levels drawn."""
    from dataclasses import replace

    streamed = replace(box, stress=box.stress[-1:])
    fig = visuals.figure_deformed(streamed)
    panels = [ax for ax in fig.axes if ax.get_title().startswith("t = ")]
    (bar,) = [ax for ax in fig.axes if ax not in panels]
    assert bar.get_xlabel().startswith("|u| (units of length")
    levels = np.array([int(np.argmin(np.abs(box.t - float(ax.get_title()[4:]))))
                       for ax in panels])
    mesh = box.problem.mesh
    nodes = mesh.facets[:, mesh.boundary_facets()]
    largest = max(np.linalg.norm(box.u[n], axis=1)[nodes].mean(axis=0).max() for n in levels)
    assert bar.get_xlim() == pytest.approx((0.0, largest), rel=1e-12)
    plt.close("all")
