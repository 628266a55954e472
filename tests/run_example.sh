#!/usr/bin/env bash
# What `make run` does after building: runs the Terzaghi example (tests/cases/terzaghi.json, about
# 9,800 steps, a few seconds) into runs/terzaghi with the solver's progress lines shown, then says
# where result.h5 and result.xdmf are and how far the last frame is from Terzaghi's closed form
# (BUILD_DIR/terzaghi-error). Exits non-zero if the run or the check fails.
#   tests/run_example.sh BUILD_DIR
set -u
build=${1:-build}
cd "$(dirname "$0")/.."
out=runs/terzaghi

mkdir -p runs || exit 4
"$build/poro-solve" run tests/cases/terzaghi.json --out "$out"
status=$?
if [ "$status" -ne 0 ]; then
	echo "run_example: poro-solve failed with exit status $status" >&2
	exit "$status"
fi
dir=$(cd "$out" && pwd)
echo
echo "results:  $dir/result.h5"
echo "ParaView: $dir/result.xdmf"
"$build/terzaghi-error" "$out"
