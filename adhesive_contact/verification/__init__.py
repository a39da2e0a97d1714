"""Verification: manufactured solutions (:mod:`.manufactured`) and their
admissibility (:mod:`.admissibility`), error norms against an exact solution
or a nested fine reference (:mod:`.errors`) and the fit of observed rates
(:mod:`.rates`). Pure mathematics on meshes, below the scene (which checks
an ``[exact]`` table with :mod:`.manufactured`); the levels of a
convergence study, which build and solve scenes, are
:mod:`adhesive_contact.studies.levels`."""
