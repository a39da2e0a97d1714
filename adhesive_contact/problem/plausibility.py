"""Warnings about a scene's material data that the discretisation or the
physics cannot bear, one line each (nothing here raises), and the note
``adhcontact check`` gives on a Prony kernel.

- :func:`locking_warning`: ν above :data:`NU_LOCKING` with P1 elements.
  P1 triangles and tetrahedra lock as ν → ½ (the discrete divergence-free
  fields are too few): displacements come out too small and converge
  slowly. Measured with ``python studies/locking/cantilever.py`` (a plane
  strain cantilever 10 × 1 with 4 cells through its thickness, the tip
  deflection over Timoshenko's beam formula): 0.81 at ν = 0.3, 0.63 at
  ν = 0.45, 0.29 at 0.49, 0.05 at 0.499.
- :func:`unit_warnings`: with ``[output] units`` naming a stress unit this
  module knows (:data:`STRESS_UNITS`), a modulus no solid or glue has:
  outside [:data:`SOFTEST`, :data:`STIFFEST`] Pa once converted.
- :func:`prony_note`: a ``kernel = "prony"`` stiffens the body (R > 0); the
  Prony series of a relaxation modulus is ``kernel = "relaxation"``.
"""

#: above this Poisson ratio P1 elements lock (see the module docstring)
NU_LOCKING = 0.45
#: the tip deflection of the locking study, 4 cells through the thickness,
#: over the beam formula: ν -> ratio (studies/locking/cantilever.py)
LOCKING_FIGURES = {0.3: 0.81, 0.45: 0.63, 0.49: 0.29, 0.499: 0.05}
#: stress units by name -> Pa
STRESS_UNITS = {"Pa": 1.0, "kPa": 1e3, "MPa": 1e6, "GPa": 1e9, "N/m^2": 1.0, "N/m²": 1.0,
                "N/mm^2": 1e6, "N/mm²": 1e6, "kN/m^2": 1e3, "kN/m²": 1e3, "bar": 1e5,
                "psi": 6894.757, "ksi": 6.894757e6, "Mpsi": 6.894757e9}
#: Young's moduli of real solids and glues, Pa: from the softest gels to diamond
SOFTEST, STIFFEST = 1.0, 1.2e12


def poisson(tensor):
    """ν of an isotropic tensor (its own, or λ / (2(λ + μ)))."""
    if tensor.nu is not None:
        return tensor.nu
    return tensor.lam / (2.0 * (tensor.lam + tensor.mu))


def young(tensor):
    """E of an isotropic tensor (its own, or μ(3λ + 2μ)/(λ + μ))."""
    if tensor.E is not None:
        return tensor.E
    return tensor.mu * (3.0 * tensor.lam + 2.0 * tensor.mu) / (tensor.lam + tensor.mu)


def elastic_tensors(scene):
    """(key, tensor) of the scene's stress-valued tensors: the material (the
    instantaneous one of a relaxation kernel) and a relaxation kernel's
    long-term tensor and terms (the terms of a prony or function kernel
    are rates, stress per time)."""
    memory = scene.memory
    if memory is not None and memory.kernel == "relaxation":
        return ([("memory.long_term", memory.long_term)]
                + [(f"memory.terms[{i}]", t.tensor) for i, t in enumerate(memory.terms)])
    return [("material", scene.material)]


def locking_warning(scene):
    """A line when a tensor of the body has ν > NU_LOCKING."""
    memory = scene.memory
    tensors = [("material", scene.material)]
    if memory is not None and memory.kernel == "relaxation":
        tensors.append(("memory.long_term", memory.long_term))
    high = [(key, poisson(t)) for key, t in tensors if poisson(t) > NU_LOCKING]
    if not high:
        return None
    key, nu = max(high, key=lambda item: item[1])
    figures = ", ".join(f"{r:g} at ν = {n:g}" for n, r in LOCKING_FIGURES.items())
    return (f"{key}.nu = {nu:.6g} (λ/μ = {2 * nu / (1 - 2 * nu):.3g}) is above {NU_LOCKING:g}: "
            f"P1 elements lock near incompressibility, so displacements come out too small "
            f"and forces move with the mesh (a bending cantilever with 4 cells through its "
            f"thickness deflects {figures} of the beam formula); refine well beyond the usual "
            "or keep ν at or below 0.45 if the material allows "
            "(docs/conventions.md#near-incompressible-materials-lock)")


def unit_warnings(scene):
    """One line per modulus outside [SOFTEST, STIFFEST] Pa, when
    ``[output] units`` names a stress unit of STRESS_UNITS."""
    unit = scene.units.get("stress")
    if unit not in STRESS_UNITS:
        return []
    scale = STRESS_UNITS[unit]
    lines = []
    for key, tensor in elastic_tensors(scene):
        E = young(tensor)
        pascal = E * scale
        if SOFTEST <= pascal <= STIFFEST:
            continue
        which = "E" if tensor.E is not None else "E (from lam, mu)"
        lines.append(
            f"{key}.{which} = {E:g} {unit} is {pascal:.3g} Pa: no solid or glue is "
            + ("that stiff (diamond: 1.2e12 Pa)" if pascal > STIFFEST else
               "that soft (the softest gels: about 1 Pa)")
            + f"; check the units (output.units.stress = {unit!r})")
    return lines


def prony_note(scene):
    """The note on a ``kernel = "prony"`` (None for another kernel): it
    stiffens the body; under a held strain E grows from E_0 to E_0 + Σ τ_m E_m."""
    memory = scene.memory
    if memory is None or memory.kernel != "prony":
        return None
    lam = scene.material.lam + sum(t.tau * t.tensor.lam for t in memory.terms)
    mu = scene.material.mu + sum(t.tau * t.tensor.mu for t in memory.terms)
    E0 = young(scene.material)
    E_long = mu * (3.0 * lam + 2.0 * mu) / (lam + mu)
    return (f"memory.kernel = \"prony\" adds R(t) = Σ e^(-t/τ_m) C_m > 0 to the elastic stress: "
            f"it stiffens the body over time (under a held strain E grows from {E0:.4g} "
            f"towards {E_long:.4g}); the Prony series of a relaxation modulus E(t) falling "
            "to E_∞ (an Abaqus-style input) is kernel = \"relaxation\" "
            "(docs/model.md#5-memory-kernels)")


def plausibility_warnings(scene):
    """The lines of :func:`locking_warning` and :func:`unit_warnings` that apply."""
    return [w for w in [locking_warning(scene), *unit_warnings(scene)] if w is not None]


__all__ = ["locking_warning", "unit_warnings", "prony_note", "plausibility_warnings",
           "NU_LOCKING", "STRESS_UNITS"]
