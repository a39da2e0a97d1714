"""Build a scene in code: a dictionary with the tables of a scene file.

    python examples/scene_in_code.py

A block with memory, clamped on top and pushed down onto a compliant
foundation with a rigid wall 0.01 behind its surface, with Tresca friction
and a sideways pull. Prints where the contact nodes end up (separated, in
the compliant layer, on the wall; stuck or slipping). Writes nothing.
"""

from adhesive_contact import SceneError, build_problem, scene_from_dict, solve
from adhesive_contact.postprocess import contact_states, normal_traction


def make_scene(cells=(16, 8), steps=10, pressure=300.0):
    return {
        "title": "block pressed and sheared onto a wall",
        "dim": 2,
        "mesh": {"domain": "rectangle", "size": [2.0, 1.0], "cells": list(cells)},
        "boundary": {"dirichlet": ["top"], "contact": ["bottom"]},
        "material": {"E": 1000.0, "nu": 0.3},
        "memory": {"kernel": "prony", "terms": [{"E": 200.0, "nu": 0.3, "tau": 0.5}]},
        # expressions are strings in x, y, t; numbers are numbers
        "loads": {"body": ["20*t", f"-{pressure}*t*(1 + 0.5*x)"]},
        "contact": {
            "gap": 0.01,
            "normal": {"law": "compliance", "c": 1e4},
            "friction": {"law": "tresca", "mu": 5.0},   # a stress bound, not a coefficient
        },
        "time": {"T": 1.0, "steps": steps},
    }


def main():
    scene = scene_from_dict(make_scene())
    solution = solve(build_problem(scene))
    masks = contact_states(solution)                    # boolean (M+1, nc) per state
    print(f"{solution.message}; {solution.steps} steps")
    for name, mask in masks.items():
        print(f"{name:>10}: {int(mask[-1].sum())} contact nodes at t = T")
    print(f"largest normal traction at T: {normal_traction(solution)[-1].max():.2f}")

    try:                                                # a bad value is one clear line
        scene_from_dict(make_scene() | {"time": {"T": 1.0, "steps": 0}})
    except SceneError as err:
        print(f"refused: {err}")
    return solution


if __name__ == "__main__":
    main()
