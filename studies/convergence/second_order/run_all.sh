#!/usr/bin/env bash
# Reruns (resumes) the k-studies of the second-order scheme (time.scheme =
# "second-order"); see studies/README.md. Same set-up as ../run_all.sh's
# k-studies: 5 levels on the 16 x 16 mesh against a fine reference of 16x the
# finest level's steps; (h), the debonding strip, 6 levels from 32 steps on
# its own mesh, and the paper's scheme on it for comparison.
set -euo pipefail
cd "$(dirname "$0")"
jobs=${JOBS:-2}
for case in a_separated_slipping b_wall_multiplier c_stick_slip d_uneven_debonding; do
    adhcontact converge "$case.toml" --param k --levels 5 --refine 2 --steps 4 --reference fine --jobs "$jobs" --out "results/$case-k"
done
adhcontact converge e_peel_reference.toml --param k --levels 5 --refine 2 --steps 16 --reference fine --jobs "$jobs" --out results/e_peel_reference-k
adhcontact converge h_debonding_strip.toml --param k --levels 6 --steps 32 --reference fine --jobs "$jobs" --out results/h_debonding_strip-k
adhcontact converge ../h_debonding_strip.toml --param k --levels 6 --steps 32 --reference fine --jobs "$jobs" --out ../results/h_debonding_strip-k
