#!/usr/bin/env bash
# Speed figures for PoroMPM, printed and never asserted. One thread unless OMP_NUM_THREADS is set,
# except solver_bench, which steps one simulation per thread count (1 and 2) in turn and prints
# them side by side with the speed-up.
set -u
build=${1:-build}
cd "$(dirname "$0")/.."
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
echo "machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//'), $(nproc --all) cores; OMP_NUM_THREADS=$OMP_NUM_THREADS"
echo "== solver: 2-D elastic block, >= 100,000 soil points, 1 and 2 threads in turn, by each scheme"
"$build"/bench/solver_bench
"$build"/bench/solver_bench --single-point
"$build"/bench/solver_bench --projection consistent
"$build"/bench/solver_bench --scheme explicit
# the implicit scheme's sparse LU grows faster than the points (2-D fill): at 100,000 points one
# factorisation takes about 7 s on one core, so one step is timed
"$build"/bench/solver_bench --scheme implicit_upU --steps 1
echo "== schemes: a consolidation column and the strip load by each scheme at its own step; the implicit scheme's Newton iterations (bench/scheme_bench.c)"
"$build"/bench/scheme_bench
echo "== slope cost: 000 Table 4, single against double point, 6x6 to 24x24 points per cell (bench/slope_cost_bench.c)"
"$build"/bench/slope_cost_bench
echo "== service: durable submissions, claims, log delay (bench/service.sh)"
bash bench/service.sh "$build"
echo "== service: listing latency at 100,000 jobs (bench/list.sh)"
bash bench/list.sh "$build"
echo "== materials: ns per stress update, elastic and plastic steps (bench/material_bench.c)"
"$build"/bench/material_bench
echo "== case validation: us per item at a tenth of each list's limit and at the limit (bench/case_validate_bench.c)"
"$build"/bench/case_validate_bench
