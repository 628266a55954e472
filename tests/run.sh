#!/usr/bin/env bash
# Runs the test programs and prints one closing line "N passed, N failed, N skipped".
#   tests/run.sh BUILD_DIR test     unit tests, reduced-size verification, command-line tests
#   tests/run.sh BUILD_DIR verify   the verification runs alone (tests/verify/); the cases there
#                                   are already at the papers' sizes, so `make test` includes them,
#                                   except runs a program keeps for PORO_VERIFY_LONG=1, which this
#                                   mode sets (strip_footing_test: finer grids, full load)
#   tests/run.sh BUILD_DIR service  the service's tests alone: tests/common and tests/service, with
#                                   the route-coverage and token-leak checks (make test-san runs
#                                   them on the sanitizer build)
# Each C test prints PASS/FAIL/XFAIL lines; INFO lines carry the measured figures. The full
# output is kept in BUILD_DIR/test-output.txt.
set -u
build=${1:-build}
mode=${2:-test}
cd "$(dirname "$0")/.."
log="$build/test-output.txt"
: > "$log"

programs=()
if [ "$mode" = test ] || [ "$mode" = service ]; then
	if [ "$mode" = test ]; then
		for t in "$build"/tests/common/*_test "$build"/tests/solver/*_test "$build"/tests/verify/*_test; do [ -x "$t" ] && programs+=("$t"); done
		for t in tests/cli/*_test.sh; do [ -f "$t" ] && programs+=("bash $t $build"); done
	else
		for t in "$build"/tests/common/*_test; do [ -x "$t" ] && programs+=("$t"); done
	fi
	for t in tests/service/*_test.sh; do [ -f "$t" ] && programs+=("bash $t $build"); done
	# every poro-server the service tests start logs its requests here; the coverage check reads it
	export SVC_ROUTES_LOG="$PWD/$build/service-routes.log"
	: > "$SVC_ROUTES_LOG"
	# every token the service tests create is recorded here, and the logs they leave are kept
	# there; the token-leak check then greps every log for every token (tests/service/lib.sh)
	export SVC_TOKENS_LOG="$PWD/$build/service-tokens.txt" SVC_KEEP_LOGS="$PWD/$build/service-logs"
	(umask 077 && : > "$SVC_TOKENS_LOG")
	rm -rf "$SVC_KEEP_LOGS"
	programs+=("bash tests/service/route_coverage.sh $build $SVC_ROUTES_LOG")
	programs+=("bash tests/service/token_leak_check.sh $build")
else
	for t in "$build"/tests/verify/*_test; do [ -x "$t" ] && programs+=("$t"); done
	export PORO_VERIFY_LONG=1   # verification programs add their long runs (strip_footing_test)
fi

crashed=0
for prog in "${programs[@]}"; do
	name=${prog%% *}; [ "$name" = bash ] && { name=${prog#bash }; name=${name%% *}; }; name=${name##*/}
	echo "== $name" | tee -a "$log"
	start=$(date +%s)
	$prog > "$build/.one-test.txt" 2>&1
	status=$?
	cat "$build/.one-test.txt" >> "$log"
	grep -E '^(FAIL|XFAIL|INFO)' "$build/.one-test.txt"
	p=$(grep -c '^PASS' "$build/.one-test.txt")
	f=$(grep -c '^FAIL' "$build/.one-test.txt")
	echo "   $p passed, $f failed in $(( $(date +%s) - start )) s"
	if [ "$status" -ne 0 ] && [ "$f" -eq 0 ]; then
		echo "FAIL $name: exited with status $status without a failed check" | tee -a "$log"
		crashed=$((crashed + 1))
	fi
done

passed=$(grep -c '^PASS' "$log")
failed=$(( $(grep -c '^FAIL' "$log") ))
skipped=$(grep -c '^XFAIL' "$log")
echo "$passed passed, $failed failed, $skipped skipped"
[ "$failed" -eq 0 ]
