#!/usr/bin/env bash
# newton_failure_test.sh - a run of the implicit scheme whose Newton iteration does not converge,
# through the real build/poro-solve: exit status 3, a message naming the step, the iteration count
# and the last residual, and the last checkpoint intact (docs/case-spec.md, "The implicit u-p-U
# scheme"; docs/service.md on resuming).
#
# The case is tests/cases/strip_footing_001.json cut to a 2 m x 2 m soil (8 x 8 cells), its
# footing load ramped over 1 s, a checkpoint every 0.1 s and newton_max_iterations 3: the elastic
# steps converge in one or two corrections, the first step where the soil yields needs more (the
# elastic tangent converges linearly once points yield), and the run stops there. Then:
#  - resumed from the checkpoint with the same case, the run starts at the checkpoint's step and
#    stops at the same step with the same message: the checkpoint held the state to resume from;
#  - resumed with tangent "consistent" (the remedy the message names), the checkpoint is refused as
#    written for another case, naming /formulation/tangent, exit 2; the checkpoint is unchanged.
# Prints "PASS name" / "FAIL name: why". Runs in a few seconds.
#   bash tests/cli/newton_failure_test.sh BUILD_DIR      (from the repository root)
set -u
cd "$(dirname "$0")/../.."
. tests/cli/lib.sh
cli_setup "${1:-build}"

derive_case footing tests/cases/strip_footing_001.json '
c["grid"]["extent"] = [2.0, 2.5]
c["bodies"][0]["rectangle"]["max"] = [2.0, 2.0]
c["loads"][0]["time_function"] = {"kind": "ramp", "ramp_time": 1.0}
c["time"] = {"dt": 0.05, "end": 1.0}
c["formulation"]["newton_max_iterations"] = 3
c["checkpoint"] = {"interval": 0.1}
c["output"] = {"frame_interval": 0.1}
c.pop("probes", None)'
derive_case consistent "$tmp/footing.json" 'c["formulation"]["tangent"] = "consistent"'

# ---- the failing run ---------------------------------------------------------------------------------
OMP_NUM_THREADS=1 "$solve" run "$tmp/footing.json" --out "$tmp/run" > "$tmp/run.out" 2> "$tmp/run.err"
rc=$?
check newton_failure_exits_3 $(( rc != 3 )) "exit $rc: $(head -c 300 "$tmp/run.err")"
message=$(grep "did not converge" "$tmp/run.err")
failed_step=$(sed -n 's/^step \([0-9]*\) (t = .*did not converge in 3 iterations.*largest residual [0-9.e+-]* N\/m.*/\1/p' \
	<<< "$message")
[ -n "$failed_step" ]
check newton_failure_names_step_iterations_residual $? "stderr: $(head -c 400 "$tmp/run.err")"
checkpoint_step=$(sed -n 's/^checkpoint step=\([0-9]*\) .*/\1/p' "$tmp/run.out" | tail -1)
[ -n "$checkpoint_step" ] && [ -n "$failed_step" ] && [ "$checkpoint_step" -gt 0 ] &&
	[ "$checkpoint_step" -lt "$failed_step" ] && [ -s "$tmp/run/checkpoint.h5" ]
check newton_failure_after_a_checkpoint $? "last checkpoint at step '$checkpoint_step', failure at '$failed_step'"
sum_before=$(sha256sum < "$tmp/run/checkpoint.h5")

# ---- resumed from that checkpoint: the same state, the same failure -----------------------------------
mkdir "$tmp/again"
cp "$tmp/run/checkpoint.h5" "$tmp/run/result.h5" "$tmp/again/"
OMP_NUM_THREADS=1 "$solve" run "$tmp/footing.json" --out "$tmp/again" --resume "$tmp/again/checkpoint.h5" \
	> "$tmp/again.out" 2> "$tmp/again.err"
rc=$?
resumed_step=$(sed -n 's/^resumed from .* at step \([0-9]*\),.*/\1/p' "$tmp/again.out")
[ "$rc" = 3 ] && [ "$resumed_step" = "$checkpoint_step" ] && [ "$(grep "did not converge" "$tmp/again.err")" = "$message" ]
check resumed_from_checkpoint_fails_at_the_same_step $? \
	"exit $rc, resumed at '$resumed_step' (checkpoint $checkpoint_step): $(head -c 300 "$tmp/again.err")"

# ---- resumed with another tangent: refused, the checkpoint untouched ----------------------------------
mkdir "$tmp/other"
cp "$tmp/run/checkpoint.h5" "$tmp/run/result.h5" "$tmp/other/"
OMP_NUM_THREADS=1 "$solve" run "$tmp/consistent.json" --out "$tmp/other" --resume "$tmp/other/checkpoint.h5" \
	> "$tmp/other.out" 2> "$tmp/other.err"
rc=$?
[ "$rc" = 2 ] && grep -q "different case: '/formulation/tangent' differs" "$tmp/other.err" &&
	[ "$(sha256sum < "$tmp/other/checkpoint.h5")" = "$sum_before" ] &&
	[ "$(sha256sum < "$tmp/run/checkpoint.h5")" = "$sum_before" ]
check resume_with_another_case_refused_checkpoint_unchanged $? "exit $rc: $(head -c 300 "$tmp/other.err")"
