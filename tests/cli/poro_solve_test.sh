#!/usr/bin/env bash
# poro_solve_test.sh - drives the real build/poro-solve binary and checks its exit codes (error.h:
# 0 ok, 2 invalid input, 3 solver failure, 4 I/O, 6 interrupted), its messages and what it leaves
# on disk. Bad cases are derived from tests/cases/terzaghi.json with python3 JSON edits in a
# temporary directory. Prints one line per check, "PASS name" or "FAIL name: why", like the C tests.
# Runs in about 5 s (the longest part is a full Terzaghi run stopped by SIGTERM after ~1 s).
#   bash tests/cli/poro_solve_test.sh BUILD_DIR      (from the repository root)
set -u
build=${1:-build}
cd "$(dirname "$0")/../.."
solve="$build/poro-solve"
check_tool="$build/terzaghi-error"
base=tests/cases/terzaghi.json
tmp=$(mktemp -d)
running=""
trap '[ -n "$running" ] && kill "$running" 2>/dev/null; rm -rf "$tmp"' EXIT

check() { # name, condition exit status ($?-style: 0 = holds), why
	if [ "$2" -eq 0 ]; then echo "PASS $1"; else echo "FAIL $1: $3"; fi
}

# derive NAME PYTHON: writes $tmp/NAME.json, the base case c after the statement PYTHON
derive() {
	python3 - "$base" "$tmp/$1.json" "$2" <<'EOF'
import json, sys
c = json.load(open(sys.argv[1]))
exec(sys.argv[3])
json.dump(c, open(sys.argv[2], "w"), indent=1)
EOF
}

# ---- invalid input: validate and run both exit 2, the message names the JSON pointer ----------

head -c 300 "$base" > "$tmp/malformed.json"
derive wrong_type 'c["grid"]["cell_size"] = "0.025"'
derive out_of_range 'c["materials"][0]["poisson_ratio"] = 0.7'
derive unknown_key 'c["time"]["dtt"] = 1e-4'
derive body_outside_grid 'c["bodies"][0]["rectangle"]["max"] = [0.1, 1.5]'
derive missing_material 'c["bodies"][0]["material"] = "clay"'

bad_input() { # kind, JSON pointer the message must name
	local kind=$1 pointer=$2 rc out="$tmp/out_$1"
	"$solve" validate "$tmp/$kind.json" > /dev/null 2> "$tmp/err"
	rc=$?
	grep -q "^$pointer: " "$tmp/err"
	check "validate_${kind}_exits_2_naming_pointer" $(( rc != 2 || $? != 0 )) \
		"exit $rc, wanted 2 and '$pointer: ...' in: $(head -c 300 "$tmp/err")"
	"$solve" run "$tmp/$kind.json" --out "$out" > /dev/null 2> "$tmp/err"
	rc=$?
	local left=0
	[ -e "$out/result.h5" ] || [ -e "$out/result.xdmf" ] && left=1
	grep -q "^$pointer: " "$tmp/err"
	check "run_${kind}_exits_2_leaves_no_result" $(( rc != 2 || left || $? != 0 )) \
		"exit $rc, result files left: $left, stderr: $(head -c 300 "$tmp/err")"
}

bad_input malformed "/"
bad_input wrong_type "/grid/cell_size"
bad_input out_of_range "/materials/0/poisson_ratio"
bad_input unknown_key "/time/dtt"
bad_input body_outside_grid "/bodies/0"
bad_input missing_material "/bodies/0/material"

# ---- a dt a few times the skeleton's CFL step (solver/stable_dt.c) is refused with the bound -------

derive dt_above_cfl 'c["time"]["dt"] = 2e-3'
bad_input dt_above_cfl "/time/dt"
"$solve" validate "$tmp/dt_above_cfl.json" > /dev/null 2> "$tmp/err"
grep -q "^/time/dt: must be at most 0.000426 s, 1.25 times the soil skeleton's CFL step h / c_p = 0.00034 s" "$tmp/err"
check validate_names_the_stable_dt $? "stderr: $(head -c 300 "$tmp/err")"

# ---- limits of a case (docs/case-spec.md "Limits"): 1.6e9 cells and an end time of 1e12 s, as reported ----

derive too_many_cells 'c["grid"]["extent"] = [1000.0, 1000.0]'
derive endless 'c["time"]["end"] = 1e12; c["output"]["frame_interval"] = 0'
bad_input too_many_cells "/grid"
bad_input endless "/time/end"
"$solve" validate "$tmp/too_many_cells.json" > /dev/null 2> "$tmp/err"
grep -qx '/grid: must have at most 100000000 cells (the case limit), got 1600000000' "$tmp/err"
check validate_names_the_cell_limit $? "stderr: $(head -c 300 "$tmp/err")"

# ---- a case with 1000 problems lists the first 100 and counts the rest --------------------------

derive many_problems 'c["probes"] = [{"name": "p%d" % i, "kind": "pore_pressure"} for i in range(1000)]'
"$solve" validate "$tmp/many_problems.json" > /dev/null 2> "$tmp/err"
rc=$?
listed=$(grep -c '^/probes/[0-9]*/point: missing required key$' "$tmp/err")
grep -qx '\.\.\. and 900 more problems' "$tmp/err"
check validate_caps_the_problems_and_counts_the_rest $(( rc != 2 || listed != 100 || $? != 0 )) \
	"exit $rc, $listed problems listed, last line: $(tail -1 "$tmp/err")"

# ---- a friction angle that reads as radians is valid but warned about, naming the key -------------
# (0.38 written for 21.8 degrees is a soil almost without friction: nothing refuses it, so only a
# warning tells the author; a case at 30 degrees gets none)

for f in mc_slope_k1e-3_double_point mohr_coulomb_drained; do
	python3 -c "import sys; open(sys.argv[2], 'w').write(open(sys.argv[1]).read().replace('\"friction_angle\": 30', '\"friction_angle\": 0.38'))" \
		"tests/cases/$f.json" "$tmp/radians_$f.json"
	"$solve" validate "$tmp/radians_$f.json" > /dev/null 2> "$tmp/err"
	rc=$?
	grep -q "warning: /materials\?/\(0/\)\?friction_angle: 0.38 degrees .* write 21.77$" "$tmp/err"
	found=$?
	"$solve" validate "tests/cases/$f.json" > /dev/null 2> "$tmp/err_degrees"
	check "validate_${f}_warns_of_radians" $(( rc != 0 || found != 0 || $(grep -c warning "$tmp/err_degrees") != 0 )) \
		"exit $rc, stderr: $(head -c 300 "$tmp/err"); in degrees: $(head -c 200 "$tmp/err_degrees")"
done

# ---- a file that does not exist: exit 4 naming the path ---------------------------------------

absent="$tmp/no_such_case.json"
for cmd in validate run; do
	if [ $cmd = run ]; then "$solve" run "$absent" --out "$tmp/out_absent" > /dev/null 2> "$tmp/err"
	else "$solve" validate "$absent" > /dev/null 2> "$tmp/err"; fi
	rc=$?
	grep -qF "'$absent'" "$tmp/err"
	check "${cmd}_missing_file_exits_4_naming_path" $(( rc != 4 || $? != 0 )) \
		"exit $rc, stderr: $(head -c 300 "$tmp/err")"
done

# ---- usage errors ---------------------------------------------------------------------------------

"$solve" > /dev/null 2> "$tmp/err"
rc=$?
grep -q usage "$tmp/err"
check usage_no_arguments_exits_2 $(( rc != 2 || $? != 0 )) "exit $rc, stderr: $(head -c 200 "$tmp/err")"
"$solve" run "$base" > /dev/null 2>&1
rc=$?
check usage_run_without_out_exits_2 $(( rc != 2 )) "exit $rc"

# ---- every example case validates ------------------------------------------------------------------

for f in tests/cases/*.json; do
	"$solve" validate "$f" > /dev/null 2> "$tmp/err"
	rc=$?
	check "example_$(basename "$f" .json)_validates" "$rc" "exit $rc: $(head -c 300 "$tmp/err")"
done

# ---- a short successful run -----------------------------------------------------------------------

derive short 'c["time"]["end"] = 0.01'
out="$tmp/out_short"
"$solve" run "$tmp/short.json" --out "$out" > "$tmp/stdout" 2> "$tmp/err"
rc=$?
check run_short_exits_0 "$rc" "exit $rc: $(head -c 300 "$tmp/err")"
grep -q "us per material-point step" "$tmp/stdout"
check run_short_prints_progress $? "no progress line in: $(head -c 300 "$tmp/stdout")"
"$check_tool" "$out" > "$tmp/check" 2>&1
rc=$?
grep -q "^terzaghi: t = 0.01 s" "$tmp/check" && [ -f "$out/result.xdmf" ]
check run_short_result_readable $(( rc != 0 || $? != 0 )) "terzaghi-error exit $rc: $(cat "$tmp/check")"

# ---- GNU habits: --help and --version exit 0, "--opt=value", options before the file ----------------

"$solve" --help > "$tmp/help" 2> "$tmp/err"
rc=$?
grep -q "^usage: poro-solve run CASE.json --out DIR" "$tmp/help" && grep -q "^  3  solver failure" "$tmp/help" && [ ! -s "$tmp/err" ]
check help_exits_0_on_stdout_with_exit_statuses $(( rc != 0 || $? != 0 )) "exit $rc: $(head -c 300 "$tmp/help" "$tmp/err")"
version=$("$solve" --version 2>&1)
rc=$?
echo "$version" | grep -Eqx "poro-solve [A-Za-z0-9._-]+" && [ "$version" = "$("$solve" version)" ] && [ "$version" != "poro-solve unknown" ]
check version_exits_0_with_the_build_version $(( rc != 0 || $? != 0 )) "exit $rc: '$version'"
ok=0
commands=$("$solve" --help | sed -n 's/^\(usage:\|      \) poro-solve \([a-z]\+\).*/\2/p')
[ "$(echo "$commands" | wc -l)" -ge 7 ] || ok=1   # run validate element report probes frames version
for c in $commands; do
	"$solve" "$c" --help > "$tmp/help" 2>&1 && grep -q "^usage: poro-solve $c" "$tmp/help" || ok=1
done
check every_command_help_exits_0 $ok "$(head -c 300 "$tmp/help")"
"$solve" 2> "$tmp/err" > /dev/null
grep -q -- "--checkpoint-wall" "$tmp/err"    # poro-worker reads the usage for it
check usage_names_checkpoint_wall $? "$(head -c 300 "$tmp/err")"
"$solve" run --out="$tmp/out_eq" --checkpoint-wall=30 "$tmp/short.json" > /dev/null 2> "$tmp/err"
rc=$?
[ -s "$tmp/out_eq/result.h5" ]
check run_opt_equals_value_before_the_file $(( rc != 0 || $? != 0 )) "exit $rc: $(head -c 300 "$tmp/err")"
"$solve" probes --job=12 --attempt=3 "$tmp/out_eq/result.h5" --out="$tmp/probes.json" 2> "$tmp/err"
rc=$?
[ "$(python3 -c 'import json, sys; d = json.load(open(sys.argv[1])); print(d["job"], d["attempt"])' "$tmp/probes.json" 2>&1)" = "12 3" ]
check probes_opt_equals_value $(( rc != 0 || $? != 0 )) "exit $rc: $(head -c 300 "$tmp/err")"
"$solve" run "$tmp/short.json" --out "$tmp/out_bad" --frobnicate > /dev/null 2> "$tmp/err"
rc=$?
grep -q "^poro-solve run: unrecognized option '--frobnicate'" "$tmp/err" && [ ! -e "$tmp/out_bad" ]
check unknown_option_exits_2_naming_it $(( rc != 2 || $? != 0 )) "exit $rc: $(head -c 300 "$tmp/err")"
"$solve" element "$tmp/short.json" > /dev/null 2> "$tmp/err"
rc=$?
grep -q "^poro-solve element: missing --out DIR" "$tmp/err"
check element_without_out_exits_2_naming_it $(( rc != 2 || $? != 0 )) "exit $rc: $(head -c 300 "$tmp/err")"

# ---- a solver failure: the column falls out of the grid through its free bottom ------------------

derive falls 'c["boundaries"]["bottom"] = {"soil": "free", "water": "free"}
c["gravity"]["acceleration"] = [0.0, -2000.0]
c["time"]["end"] = 0.05'
"$solve" run "$tmp/falls.json" --out "$tmp/out_falls" > /dev/null 2> "$tmp/err"
rc=$?
grep -qE "point [0-9]+ .*\(-?[0-9.e+-]+, -?[0-9.e+-]+\)" "$tmp/err"
check solver_failure_exits_3_naming_point_and_position $(( rc != 3 || $? != 0 )) \
	"exit $rc, stderr: $(head -c 300 "$tmp/err")"

# ---- SIGTERM during a full-length run: exit 6, the frames written so far readable ------------------

out="$tmp/out_term"
"$solve" run "$base" --out "$out" > "$tmp/stdout" 2> "$tmp/err" &
running=$!
# the first progress line comes after 1 s of wall time, when the signal handlers are installed
for _ in $(seq 100); do
	grep -q "^step " "$tmp/stdout" && break
	kill -0 "$running" 2>/dev/null || break
	sleep 0.1
done
kill -TERM "$running" 2>/dev/null
wait "$running"
rc=$?
running=""
check sigterm_exits_6 $(( rc != 6 )) "exit $rc (0: finished before the signal), stderr: $(head -c 300 "$tmp/err")"
"$check_tool" "$out" > "$tmp/check" 2>&1
tool_rc=$?
h5dump -a /run/status "$out/result.h5" > "$tmp/h5" 2>&1
grep -q '"failed"' "$tmp/h5"
check sigterm_result_readable $(( tool_rc != 0 || $? != 0 )) \
	"terzaghi-error exit $tool_rc: $(cat "$tmp/check"); h5dump: $(head -c 200 "$tmp/h5")"
