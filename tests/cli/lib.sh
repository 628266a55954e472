#!/usr/bin/env bash
# lib.sh - helpers for the command-line tests: source it from the repository root, then call
# cli_setup, or set $solve (the poro-solve binary) and $tmp (a temporary directory the test
# removes) yourself.
#
#   cli_setup BUILD_DIR                   $build, $solve = BUILD_DIR/poro-solve, and $tmp, a fresh
#                                         directory removed when the script exits
#   check NAME STATUS WHY                 "PASS NAME" when STATUS is 0, else "FAIL NAME: WHY"
#   derive_material NAME MATERIAL PYTHON  $tmp/NAME.json: tests/cases/terzaghi.json with its first
#                                         material updated by the JSON object MATERIAL (keys whose
#                                         value is null are removed), then the python statement
#                                         PYTHON run with c (the case) and m (the material)
#   expect_invalid NAME POINTER [FILE]    `poro-solve validate` of FILE ($tmp/NAME.json) exits 2 and
#                                         names POINTER; the check is called validate_NAME_...
#   derive_case NAME BASE PYTHON          $tmp/NAME.json: the case BASE after the python statement
#                                         PYTHON run with c (the case)
#   derive_element NAME BASE PYTHON       the same for an element case
#   run_derived NAME LABEL                runs $tmp/NAME.json into $tmp/NAME; the check
#                                         LABEL_exits_0
#   expect_element_refused NAME FILE POINTER...
#                                         `poro-solve element FILE` exits 2, names every POINTER and
#                                         writes no element.csv

cli_setup() {
	build=$1
	solve="$build/poro-solve"
	tmp=$(mktemp -d)
	trap 'rm -rf "$tmp"' EXIT
}

check() {
	if [ "$2" -eq 0 ]; then echo "PASS $1"; else echo "FAIL $1: $3"; fi
}

derive_material() {
	python3 - tests/cases/terzaghi.json "$tmp/$1.json" "$2" "$3" <<'EOF2'
import json, sys
c = json.load(open(sys.argv[1]))
m = c["materials"][0]
for k, v in json.loads(sys.argv[3]).items():
    if v is None:
        m.pop(k, None)
    else:
        m[k] = v
exec(sys.argv[4])
json.dump(c, open(sys.argv[2], "w"), indent=1)
EOF2
}

expect_invalid() {
	local file=${3:-$tmp/$1.json} rc
	"$solve" validate "$file" > /dev/null 2> "$tmp/err"
	rc=$?
	grep -q "^$2: " "$tmp/err"
	check "validate_$1_exits_2_naming_pointer" $(( rc != 2 || $? != 0 )) \
		"exit $rc, wanted 2 and '$2: ...' in: $(head -c 300 "$tmp/err")"
}

derive_case() {
	python3 - "$2" "$tmp/$1.json" "$3" <<'EOF2'
import json, sys
c = json.load(open(sys.argv[1]))
exec(sys.argv[3])
json.dump(c, open(sys.argv[2], "w"))
EOF2
}

derive_element() { derive_case "$@"; }

run_derived() {
	local rc
	"$solve" run "$tmp/$1.json" --out "$tmp/$1" > /dev/null 2> "$tmp/err"
	rc=$?
	check "$2_exits_0" $rc "exit $rc: $(head -c 300 "$tmp/err")"
}

expect_element_refused() {
	local name=$1 file=$2 rc ok=0 pointer
	shift 2
	"$solve" element "$file" --out "$tmp/$name.out" > /dev/null 2> "$tmp/err"
	rc=$?
	[ "$rc" -eq 2 ] || ok=1
	for pointer in "$@"; do grep -q "^$pointer: " "$tmp/err" || ok=1; done
	[ -e "$tmp/$name.out/element.csv" ] && ok=1
	check "${name}_exits_2_listing_every_problem" $ok "exit $rc, stderr: $(head -c 300 "$tmp/err")"
}
