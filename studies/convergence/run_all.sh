#!/usr/bin/env bash
# Reruns (resumes) every committed convergence study; see studies/README.md.
# h-studies: 5 mesh levels at a fixed, small k against the exact solution;
# k-studies: 5 step levels on a fixed mesh against a fine-in-time reference
#   (the same mesh, 16x the steps of the finest level), which isolates the
#   time error; hk-studies: both halved together against the exact solution.
set -euo pipefail
cd "$(dirname "$0")"
out=results
jobs=${JOBS:-2}
for case in a_separated_slipping a50_separated_slipping_small b_wall_multiplier c_stick_slip d_uneven_debonding; do
    steps_h=256
    [ "$case" = d_uneven_debonding ] && steps_h=2048
    adhcontact converge "$case.toml" --param h --levels 5 --steps "$steps_h" --jobs "$jobs" --out "$out/$case-h"
    adhcontact converge "$case.toml" --param k --levels 5 --refine 2 --steps 4 --reference fine --jobs "$jobs" --out "$out/$case-k"
    adhcontact converge "$case.toml" --param hk --levels 5 --steps 4 --jobs "$jobs" --out "$out/$case-hk"
done
# (e): a realistic peel without an exact solution, against fine reference runs
# (the mesh refined twice more for h, 16x the steps for k, both 4x for hk).
# The bonding ODE runs at rates up to (γ_ν + γ_τ) L² = 3: from 4 steps (k λ =
# 0.75) the k-levels are pre-asymptotic (pairwise rates 0.62, 0.79, 0.93,
# 0.98; fitted 0.84), so the time levels start from 16 steps.
case=e_peel_reference
adhcontact converge "$case.toml" --param h --levels 5 --reference fine --jobs "$jobs" --out "$out/$case-h"
adhcontact converge "$case.toml" --param k --levels 5 --refine 2 --steps 16 --reference fine --jobs "$jobs" --out "$out/$case-k"
adhcontact converge "$case.toml" --param hk --levels 5 --steps 16 --reference fine --jobs "$jobs" --out "$out/$case-hk"
# (f) 3D manufactured case on the box; (g) 2D manufactured case on a gmsh mesh
# (studies/meshes/plate_with_hole.msh): h-studies against the exact solution.
adhcontact converge f_box_3d.toml --param h --levels 4 --steps 64 --jobs "$jobs" --out "$out/f_box_3d-h"
adhcontact converge g_plate_with_hole.toml --param h --levels 5 --steps 256 --jobs "$jobs" --out "$out/g_plate_with_hole-h"
