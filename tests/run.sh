#!/usr/bin/env bash
# Runs the test programs and prints one closing line "N passed, N failed, N skipped".
#   tests/run.sh BUILD_DIR test     unit tests, reduced-size verification, command-line tests,
#                                   the build and install tests (tests/install), the fault,
#                                   power-loss and short soak tests (tests/fault)
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

# The C test programs (tests/common, tests/solver, tests/verify) are independent processes: they
# run `jobs` at a time (PORO_TEST_JOBS, default the machine's cores), each on one OpenMP thread
# when more than one runs. A run is bit-identical at any thread count
# (tests/solver/thread_count_test.c) and two threads save only 10-25% of a run
# (docs/performance.md, "Threads"), so two programs side by side nearly halve the time. The
# longest go first (by their times in the last run, BUILD_DIR/test-times.txt, else the
# verification programs first) so the short ones fill the other cores around them; the
# command-line tests (poro-solve and the tools, no server) join them. The install, browser, fault
# and service tests then run one at a time: they start servers and workers whose deadlines assume
# the cores are theirs.
parallel=() serial=()
if [ "$mode" = test ]; then
	for t in "$build"/tests/verify/*_test "$build"/tests/solver/*_test "$build"/tests/common/*_test; do
		[ -x "$t" ] && parallel+=("$t")
	done
	# the command-line tests run poro-solve and the tools on small cases, no server: beside the
	# C programs; what starts servers and workers runs alone below
	for t in tests/cli/*_test.sh; do [ -f "$t" ] && parallel+=("bash $t $build"); done
	for t in tests/install/*_test.sh tests/web/*_test.sh; do [ -f "$t" ] && serial+=("bash $t $build"); done
	# fault injection, power loss and the short soak (docs/hardening.md)
	for t in tests/fault/*_test.sh; do [ -f "$t" ] && serial+=("bash $t $build"); done
elif [ "$mode" = service ]; then
	for t in "$build"/tests/common/*_test; do [ -x "$t" ] && parallel+=("$t"); done
else
	for t in "$build"/tests/verify/*_test; do [ -x "$t" ] && parallel+=("$t"); done
	export PORO_VERIFY_LONG=1   # verification programs add their long runs (strip_footing_test)
fi
if [ "$mode" = test ] || [ "$mode" = service ]; then
	for t in tests/service/*_test.sh; do [ -f "$t" ] && serial+=("bash $t $build"); done
	# every poro-server the service tests start logs its requests here; the coverage check reads it
	export SVC_ROUTES_LOG="$PWD/$build/service-routes.log"
	: > "$SVC_ROUTES_LOG"
	# every token the service tests create is recorded here, and the logs they leave are kept
	# there; the token-leak check then greps every log for every token (tests/service/lib.sh)
	export SVC_TOKENS_LOG="$PWD/$build/service-tokens.txt" SVC_KEEP_LOGS="$PWD/$build/service-logs"
	(umask 077 && : > "$SVC_TOKENS_LOG")
	rm -rf "$SVC_KEEP_LOGS"
	serial+=("bash tests/service/route_coverage.sh $build $SVC_ROUTES_LOG")
	serial+=("bash tests/service/token_leak_check.sh $build")
fi

jobs=${PORO_TEST_JOBS:-$(nproc 2>/dev/null || echo 1)}
[ "$jobs" -ge 1 ] 2>/dev/null || jobs=1
times="$build/test-times.txt"   # "seconds program" per line, from the last run
if [ -s "$times" ] && [ "${#parallel[@]}" -gt 1 ]; then
	mapfile -t parallel < <(for t in "${parallel[@]}"; do
		printf '%s %s\n' "$(awk -v p="$t" '{ n = $0; sub(/^[^ ]+ /, "", n) } n == p { s = $1 } END { print s + 0 }' "$times")" "$t"
	done | sort -s -k1,1nr | cut -d' ' -f2-)
fi
scratch="$build/.tests"
rm -rf "$scratch" && mkdir -p "$scratch"
new_times="$scratch/times"
: > "$new_times"

name_of() { local n=${1%% *}; [ "$n" = bash ] && { n=${1#bash }; n=${n%% *}; }; echo "${n##*/}"; }

# Runs program $2 into $scratch/$1.out; its exit status and seconds go to $scratch/$1.status.
run_one() {
	local start; start=$(date +%s)
	$2 > "$scratch/$1.out" 2>&1
	echo "$? $(( $(date +%s) - start ))" > "$scratch/$1.status"
}

crashed=0
# Prints and logs what program $2 (run as number $1) said, with its counts.
report_one() {
	local out="$scratch/$1.out" status seconds p f
	read -r status seconds < "$scratch/$1.status"
	echo "== $(name_of "$2")" | tee -a "$log"
	cat "$out" >> "$log"
	grep -E '^(FAIL|XFAIL|INFO)' "$out"
	p=$(grep -c '^PASS' "$out")
	f=$(grep -c '^FAIL' "$out")
	echo "   $p passed, $f failed in $seconds s"
	echo "$seconds $2" >> "$new_times"
	if [ "$status" -ne 0 ] && [ "$f" -eq 0 ]; then
		echo "FAIL $(name_of "$2"): exited with status $status without a failed check" | tee -a "$log"
		crashed=$((crashed + 1))
	fi
}

declare -A number_of_pid=()
running=0
finish_one() {
	local pid
	wait -n -p pid
	report_one "${number_of_pid[$pid]}" "${parallel[${number_of_pid[$pid]}]}"
	running=$((running - 1))
}
for i in "${!parallel[@]}"; do
	[ "$running" -ge "$jobs" ] && finish_one
	if [ "$jobs" -gt 1 ]; then
		OMP_NUM_THREADS=1 run_one "$i" "${parallel[$i]}" &
	else
		run_one "$i" "${parallel[$i]}" &
	fi
	number_of_pid[$!]=$i
	running=$((running + 1))
done
while [ "$running" -gt 0 ]; do finish_one; done

for i in "${!serial[@]}"; do
	run_one "s$i" "${serial[$i]}"
	report_one "s$i" "${serial[$i]}"
done
# keep the times of programs this run did not run (another mode's)
[ -s "$times" ] && awk 'NR == FNR { seen[$2] = 1; next } !($2 in seen)' "$new_times" "$times" > "$scratch/kept"
cat "$new_times" "$scratch/kept" 2>/dev/null > "$times"

passed=$(grep -c '^PASS' "$log")
failed=$(( $(grep -c '^FAIL' "$log") ))
skipped=$(grep -c '^XFAIL' "$log")
echo "$passed passed, $failed failed, $skipped skipped"
[ "$failed" -eq 0 ]
