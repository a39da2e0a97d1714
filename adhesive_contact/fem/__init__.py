"""The finite element layer: meshes with named sides (:mod:`.meshes`), the
P1 kernels (:mod:`.p1`) and what is assembled once per mesh
(:mod:`.assembly`), the contact boundary Γ_C with its frames, quadrature and
trace operators (:mod:`.contact_boundary`), the prescribed displacements
(:mod:`.dirichlet`) and the foundation's geometry (:mod:`.foundation`)."""
