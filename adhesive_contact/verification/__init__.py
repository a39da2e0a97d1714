"""Verification: manufactured solutions (:mod:`.manufactured`) and their
admissibility (:mod:`.admissibility`), error norms against an exact solution
or a nested fine reference (:mod:`.errors`), the levels of a convergence
study (:mod:`.levels`) and the fit of observed rates (:mod:`.rates`)."""
