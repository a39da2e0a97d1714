"""Built objects pickle (a study sends them to worker processes): a Scene,
a Problem and a Solution survive a round trip, and an unpickled Problem
runs to the same numbers, bit for bit."""

import pickle
from pathlib import Path

import numpy as np
import pytest

from adhesive_contact import build_problem, parse_scene, solve
from adhesive_contact.studies.levels import with_discretisation

ROOT = Path(__file__).resolve().parents[1]
SCENES = {
    # memory, adhesive compliance, slip weakening, Frémond bonding
    "debonding": (ROOT / "studies/scenes/debonding.toml", 0, 50),
    # a manufactured solution: sympy-derived loads and the bonding source
    "manufactured": (ROOT / "studies/convergence/d_uneven_debonding.toml", 0, 4),
}


@pytest.mark.parametrize("name", sorted(SCENES))
def test_scene_problem_solution_pickle_and_run_the_same(name):
    path, refine, steps = SCENES[name]
    scene = with_discretisation(parse_scene(path.read_text()), refine=refine, steps=steps)
    problem = build_problem(scene)
    again = pickle.loads(pickle.dumps(problem))
    assert pickle.loads(pickle.dumps(scene)).resolved == scene.resolved
    first, second = solve(problem), solve(again)
    assert first.success and second.success
    for key in ("u", "beta", "contact_force", "stress"):
        np.testing.assert_array_equal(getattr(first, key), getattr(second, key))
    copy = pickle.loads(pickle.dumps(first))
    np.testing.assert_array_equal(copy.u, first.u)
    assert copy.status == first.status and copy.message == first.message


def test_a_scene_error_pickles_whole():
    """A SceneError raised in a worker comes back as it was raised: its type,
    its key (whole, however long) and its one-line message; it is one class
    under each name it is imported by."""
    import adhesive_contact
    import adhesive_contact.errors
    import adhesive_contact.scene

    assert adhesive_contact.SceneError is adhesive_contact.scene.SceneError
    assert adhesive_contact.scene.SceneError is adhesive_contact.errors.SceneError
    for key in ("contact.normal.c", "k" * 200, None):
        err = adhesive_contact.SceneError(key, "must be > 0, got -1")
        again = pickle.loads(pickle.dumps(err))
        assert type(again) is adhesive_contact.SceneError
        assert (again.key, str(again)) == (err.key, str(err))
