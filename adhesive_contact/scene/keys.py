"""The limits every scene must keep, and the keys each table takes."""

#: the ranges every scene must keep (see the readers that use them for why)
MAX_TITLE = 500             # characters of the title (it heads every plot)
LINEAR_TOL_RANGE = (1e-14, 1e-2)   # below: round-off; above: a solve that barely acts
LENGTHS = (1e-6, 1e6)       # each length of the domain; rescale the units outside
MAX_CELL_ASPECT = 1e3       # longest over shortest edge of the structured cells
MAX_NODES = 10**8           # nodes of the refined mesh
MAX_STEPS = 10**8           # time steps
TOL_RANGE = (1e-14, 1e-3)   # solver.tol, relative to the force scale of a step
MAX_ITER = 10_000           # solver.max_iter
MAX_UNIT = 16               # characters of a unit name in output.units

#: the quantities ``output.units`` may name (labels of the plots only)
UNIT_KEYS = ("length", "stress", "time", "force")

#: every key of a table whose reader asks for some only in some branches
#: (a law's parameters are named by the law's reader; [mesh] and [memory]
#: are read whole for their domain or kernel)
KNOWN_KEYS = {
    "": {"title", "dim", "mesh", "boundary", "material", "memory", "loads", "contact",
         "time", "solver", "output", "exact"},
    "boundary": {"dirichlet", "contact", "displacement"},
    "material": {"E", "nu", "lam", "mu"},
    "loads": {"body", "traction"},
    "contact": {"gap", "foundation", "quadrature", "order", "normal", "friction", "bonding"},
    "contact.foundation": {"shape", "point", "normal", "radius", "axis"},
    "contact.bonding": {"law", "beta0", "integrator", "gamma_nu", "gamma_tau", "eps_a", "L"},
    "time": {"T", "steps"},
    "solver": {"method", "tol", "max_iter", "linear", "linear_tol", "penalty", "smoothing"},
    "output": {"probes", "units"},
    "output.units": set(UNIT_KEYS),
    "exact": {"u", "beta", "multiplier"},
}
