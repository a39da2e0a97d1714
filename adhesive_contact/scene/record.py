"""The resolved record of a scene: every default filled in, as a JSON-able
dict of its tables (expressions as their text, or as the number given).

It is written to summary.json and is the identity of a convergence study:
a key added later (``solver.linear_tol``) is recorded only when it is set,
so that the studies of earlier scenes keep their identity.
"""

from pathlib import Path

from .keys import default


def resolved(scene):
    """The resolved record of ``scene`` (:attr:`Scene.resolved`)."""
    return {
        "title": scene.title, "dim": scene.dim,
        "mesh": _mesh_record(scene.mesh),
        "boundary": {"dirichlet": list(scene.dirichlet), "contact": list(scene.contact_sides),
                     **({"displacement": {
                         side: [e.source if e is not None else "free" for e in exprs]
                         for side, exprs in scene.displacement.items()}}
                        if scene.displacement else {})},
        "material": {**_young(scene.material), "lam": scene.material.lam,
                     "mu": scene.material.mu},
        "memory": _memory_record(scene.memory),
        "loads": {"body": _texts(scene.body),
                  "traction": {side: _texts(v) for side, v in scene.traction.items()}},
        "contact": _contact_record(scene.contact),
        "time": {"T": scene.T, "steps": scene.steps, "k": scene.k,
                 # only when not the paper's: a study recorded before the key resumes
                 **({"scheme": scene.scheme} if scene.scheme != "paper" else {}),
                 **({"adaptive": _adaptive_record(scene.adaptive)} if scene.adaptive
                    else {})},
        "solver": _solver_record(scene.solver),
        "output": {"probes": [list(p) for p in scene.probes],
                   **({"units": dict(scene.units)} if scene.units else {}),
                   **({"plot_times": list(scene.plot_times)}
                      if scene.plot_times != "auto" else {}),
                   # only when not the defaults: a study recorded before the keys resumes
                   **({"every": scene.every} if scene.every != default("output.every")
                      else {}),
                   **({"fields": list(scene.fields)}
                      if scene.fields != default("output.fields") else {})},
        "exact": _exact_record(scene.exact),
    }


def _adaptive_record(adaptive):
    return {"tol": adaptive.tol, "rate_floor": adaptive.rate_floor,
            "k_min": adaptive.k_min, "halvings": adaptive.halvings,
            "growth": adaptive.growth, "shrink": adaptive.shrink, "safety": adaptive.safety}


def _mesh_record(mesh):
    """A file mesh is recorded by its name and content (not its folder), so
    that a study's identity does not depend on where the files live."""
    if mesh.domain == "file":
        return {"domain": "file", "file": Path(mesh.file).name, "sha256": mesh.sha256,
                "refine": mesh.refine}
    return {"domain": mesh.domain, "size": list(mesh.size), "cells": list(mesh.cells),
            "pattern": mesh.pattern, "refine": mesh.refine}


def _texts(expressions):
    return [e.source for e in expressions]


def _young(tensor):
    return {} if tensor.E is None else {"E": tensor.E, "nu": tensor.nu}


def _pair(tensor):
    """The pair the scene gave: (E, nu) or (lam, mu)."""
    return _young(tensor) or {"lam": tensor.lam, "mu": tensor.mu}


def _law_record(spec):
    return {"law": spec.law, **spec.params}


def _memory_record(memory):
    if memory is None:
        return None
    if memory.kernel == "prony":
        return {"kernel": "prony",
                "terms": [{**_pair(t.tensor), "tau": t.tau} for t in memory.terms]}
    if memory.kernel == "relaxation":
        return {"kernel": "relaxation", "long_term": _pair(memory.long_term),
                "terms": [{**_pair(t.tensor), "tau": t.tau} for t in memory.terms]}
    return {"kernel": "function", "r": memory.function.source, **_pair(memory.tensor)}


def _contact_record(contact):
    """{} for a scene without contact settings."""
    if contact == type(contact)():        # every default: the scene said nothing
        return {}
    record = {} if contact.gap is None else {"gap": contact.gap.given}
    if contact.foundation is not None:
        f = contact.foundation
        record["foundation"] = {"shape": f.shape, "point": list(f.point),
                                **({"normal": list(f.normal)} if f.normal else {}),
                                **({"axis": list(f.axis)} if f.axis else {}),
                                **({"radius": f.radius} if f.radius is not None else {})}
    record.update(quadrature=contact.quadrature, order=contact.order,
                  normal=_law_record(contact.normal),
                  friction=[_law_record(f) for f in contact.friction])
    if contact.beta0 is not None:
        record["beta0"] = contact.beta0.given
    if contact.bonded:
        record["integrator"] = contact.integrator
    record["bonding"] = _law_record(contact.bonding)
    return record


def _solver_record(solver):
    record = {"method": solver.method, "tol": solver.tol, "max_iter": solver.max_iter,
              "linear": solver.linear}
    # recorded only when set: the studies made before the key existed keep their identity
    if solver.linear_tol != default("solver.linear_tol"):
        record["linear_tol"] = solver.linear_tol
    if solver.method == "penalty":
        record.update(penalty=solver.penalty, smoothing=solver.smoothing)
    return record


def _exact_record(exact):
    if exact is None:
        return None
    record = {"u": _texts(exact.u)}
    if exact.beta is not None:
        record["beta"] = exact.beta.source
    if exact.multiplier is not None:
        record["multiplier"] = exact.multiplier.source
    return record
