#!/usr/bin/env bash
# client_test.sh - drives the real poro-server, poro-worker, poro and poro-load binaries over HTTP on
# 127.0.0.1 (the server picks a free port; its URL is read from STATE/server.url) with a temporary
# state directory, and checks what a user and an operator see: submit --wait, logs, fetch with
# checksums, show, ls, schema errors printed as "poro: message (code, field ...)", cancel of a
# running solver (its process gone within seconds), kill -9 of a worker mid-run (the job resumes on
# another worker from its checkpoint), a draining worker finishing its job, logs -f, a corrupted
# stored file refused by fetch, and poro-load surviving a dead server. Short runs use
# tests/cases/terzaghi.json with edited end times (1.25 s of solver time per 0.05 s simulated).
# Prints "PASS name" or "FAIL name: why" per check. Runs in about 25 s.
#   bash tests/service/client_test.sh BUILD_DIR      (from the repository root)
set -u
build=${1:-build}
cd "$(dirname "$0")/../.."
root=$(pwd)
. tests/service/lib.sh   # check and wait_for; this script starts its own server, so no svc_init
for b in poro-server poro-worker poro poro-load poro-solve; do
	if [ ! -x "$build/$b" ]; then
		echo "FAIL setup: $build/$b is missing"
		exit 1
	fi
done
tmp=$(mktemp -d)
pids=()
cleanup() {
	for p in "${pids[@]}" $(solver_pids); do kill -9 "$p" 2>/dev/null; done
	wait 2>/dev/null
	svc_keep_logs "$tmp"   # for the token-leak check
	rm -rf "$tmp"
}
trap cleanup EXIT
# solver_pids [JOB]: the solvers the workers started (all, or of job JOB), from the workers' logs
solver_pids() {
	cat "$tmp"/w*.log 2>/dev/null | sed -n "s/.*job ${1:-[0-9]*} attempt [0-9]*: solver started (pid \([0-9]*\).*/\1/p"
}

# case NAME END: a Terzaghi case ending at END seconds of simulated time
case_with_end() {
	python3 - "$root/tests/cases/terzaghi.json" "$tmp/$1.json" "$2" <<'PY'
import json, sys
c = json.load(open(sys.argv[1]))
c["time"]["end"] = float(sys.argv[3])
json.dump(c, open(sys.argv[2], "w"))
PY
}

state=$tmp/state
mkdir -p "$state"
"$build/poro-server" --listen 127.0.0.1:0 --state "$state" --lease-seconds 3 ${SVC_ROUTES_LOG:+--access-log "$SVC_ROUTES_LOG"} > "$tmp/server.log" 2>&1 &
pids+=($!)
wait_for 10 test -s "$state/server.url"
check server_starts $? "no $state/server.url after 10 s: $(tail -3 "$tmp/server.log")"
export PORO_SERVER=$(cat "$state/server.url")
user_token=$("$build/poro-server" token create --state "$state" --user alice --role user | tail -1)
worker_token=$("$build/poro-server" token create --state "$state" --user pool --role worker | tail -1)
export PORO_TOKEN=$user_token
poro=$root/$build/poro

start_worker() { # NAME: starts a worker, its pid in $worker_pid, its log in $tmp/NAME.log
	"$build/poro-worker" --server "$PORO_SERVER" --token "$worker_token" --work "$tmp/work-$1" \
		--solver "$build/poro-solve" --checkpoint-wall 1 --name "$1" --keep-work yes > "$tmp/$1.log" 2>&1 &
	worker_pid=$!
	pids+=($worker_pid)
}
job_state() { "$poro" show "$1" 2>/dev/null | awk '$1 == "state" {print $2}'; }
state_is() { [ "$(job_state "$1")" = "$2" ]; }

case_with_end short 0.05
case_with_end medium 0.4
case_with_end long 2.0

# ---- submit --wait, logs, fetch, show, ls ---------------------------------------------------------
start_worker w1
w1=$worker_pid
id=$("$poro" submit "$tmp/short.json" --wait --name short-run 2> "$tmp/wait.err")
rc=$?
check submit_wait_succeeds $(( rc != 0 )) "exit $rc, stderr: $(tail -2 "$tmp/wait.err")"
grep -q "succeeded" "$tmp/wait.err"
check submit_wait_reports_state $? "stderr lacks 'succeeded': $(tail -2 "$tmp/wait.err")"

"$poro" logs "$id" > "$tmp/logs.txt" 2>&1
grep -q "^step 500/500" "$tmp/logs.txt" && grep -q "^done:" "$tmp/logs.txt"
check logs_has_solver_output $? "log lacks the last step or done: $(tail -2 "$tmp/logs.txt")"

(cd "$tmp" && "$poro" fetch "$id" --out fetched > fetch.out 2>&1)
rc=$?
ok=1
[ $rc -eq 0 ] && [ -s "$tmp/fetched/result.h5" ] && [ -s "$tmp/fetched/result.xdmf" ] && ok=0
check fetch_downloads_results $ok "exit $rc: $(cat "$tmp/fetch.out")"
said=$(awk '$1 ~ /result.h5$/ {print $NF}' "$tmp/fetch.out")
got=$(sha256sum "$tmp/fetched/result.h5" 2>/dev/null | cut -d' ' -f1)
[ -n "$got" ] && [ "$said" = "$got" ] && "$poro" show "$id" | grep -q "result.h5 .* sha256 $got"
check fetch_matches_listed_sha256 $? "fetch said '$said', file has '$got'"

solver_sha=$(sha256sum "$tmp/work-w1/job-$id-1/out/result.h5" 2>/dev/null | cut -d' ' -f1)
[ -n "$got" ] && [ "$solver_sha" = "$got" ]
check fetched_file_is_the_one_the_solver_wrote $? "solver's file '$solver_sha', fetched '$got'"

"$poro" show "$id" > "$tmp/show.txt" 2>&1
grep -q "^state  *succeeded" "$tmp/show.txt" && grep -q "short-run" "$tmp/show.txt" && grep -q "events:" "$tmp/show.txt"
check show_lists_fields $? "$(head -5 "$tmp/show.txt")"

"$poro" ls --state succeeded > "$tmp/ls.txt" 2>&1
grep -q "^$id  *succeeded" "$tmp/ls.txt"
check ls_lists_job $? "$(cat "$tmp/ls.txt")"

# ---- errors from the server -----------------------------------------------------------------------
python3 -c "import json; c=json.load(open('$tmp/short.json')); c['grid']['cell_size']='x'; json.dump(c, open('$tmp/bad.json','w'))"
"$poro" submit "$tmp/bad.json" > /dev/null 2> "$tmp/bad.err"
rc=$?
[ $rc -ne 0 ] && grep -q "^poro: .*(invalid_case" "$tmp/bad.err"
check schema_error_printed $? "exit $rc: $(head -2 "$tmp/bad.err")"
"$poro" show 999999 > /dev/null 2> "$tmp/missing.err"
rc=$?
[ $rc -ne 0 ] && grep -q "^poro: .*(not_found" "$tmp/missing.err"
check unknown_job_error_printed $? "exit $rc: $(cat "$tmp/missing.err")"

# ---- idempotency key: the same key twice is one job ------------------------------------------------
a=$("$poro" submit "$tmp/short.json" --idempotency-key same-key-7 2>/dev/null)
b=$("$poro" submit "$tmp/short.json" --idempotency-key same-key-7 2>/dev/null)
[ -n "$a" ] && [ "$a" = "$b" ]
check idempotency_key_reuses_job $? "ids '$a' and '$b'"
wait_for 30 state_is "$a" succeeded

# ---- logs -f follows a running job to its end -----------------------------------------------------
# the first solver progress line must reach the follower while the job is still running
id=$("$poro" submit "$tmp/medium.json")
state_at_first_line=""
while IFS= read -r line; do
	case $line in step*) [ -z "$state_at_first_line" ] && state_at_first_line=$(job_state "$id") ;; esac
	printf '%s\n' "$line" >> "$tmp/follow.txt"
done < <(timeout 60 "$poro" logs -f "$id" 2>&1)
grep -q "^done:" "$tmp/follow.txt" && state_is "$id" succeeded
check logs_follow_until_end $? "state $(job_state "$id"), tail: $(tail -1 "$tmp/follow.txt")"
[ "$state_at_first_line" = running ]
check logs_follow_shows_lines_while_running $? "job was '$state_at_first_line' when the first step line arrived"

# ---- cancel a running job: the solver is gone within seconds --------------------------------------
id=$("$poro" submit "$tmp/long.json")
wait_for 20 state_is "$id" running
solver_started() { [ -n "$(solver_pids "$id")" ]; }
wait_for 10 solver_started
cancelled_pids=$(solver_pids "$id")
[ -n "$cancelled_pids" ]
check cancel_target_solver_running $? "no solver process of job $id before the cancel"
t0=$(date +%s.%N)
"$poro" cancel "$id" > /dev/null 2>&1
solvers_gone() { local p; for p in $cancelled_pids; do kill -0 "$p" 2>/dev/null && return 1; done; return 0; }
wait_for 10 solvers_gone
gone=$?
elapsed=$(python3 -c "print('%.2f' % ($(date +%s.%N) - $t0))")
echo "INFO cancel of a running job: solver process gone $elapsed s after the cancel request"
check cancel_kills_solver_within_5s "$([ $gone -eq 0 ] && python3 -c "import sys; sys.exit(not $elapsed <= 5)"; echo $?)" \
	"solver pids $cancelled_pids after $elapsed s"
wait_for 10 state_is "$id" cancelled
check cancel_ends_cancelled $? "state $(job_state "$id") after the cancel"

# ---- kill -9 of a worker: the job resumes elsewhere from its checkpoint ---------------------------
id=$("$poro" submit "$tmp/long.json")
wait_for 20 grep -q "job $id attempt .*: checkpoint uploaded" "$tmp/w1.log"
check checkpoint_uploaded $? "no checkpoint upload of job $id in the worker log"
kill -9 "$w1"
wait "$w1" 2>/dev/null
for p in $(solver_pids "$id"); do kill -9 "$p" 2>/dev/null; done # the host went down with it
start_worker w2
w2=$worker_pid
wait_for 90 state_is "$id" succeeded
check killed_worker_job_succeeds $? "state $(job_state "$id"); w2 log: $(tail -3 "$tmp/w2.log")"
grep -q "job $id attempt .*resuming from the checkpoint" "$tmp/w2.log"
check killed_worker_job_resumes $? "w2 did not resume job $id from a checkpoint"

# ---- drain: SIGTERM lets the running job finish, then the worker exits 0 --------------------------
id=$("$poro" submit "$tmp/medium.json")
wait_for 20 state_is "$id" running
kill -TERM "$w2"
wait "$w2"
rc=$?
check drain_exits_zero $rc "worker exited $rc"
state_is "$id" succeeded
check drain_finishes_running_job $? "state $(job_state "$id")"

# ---- fetch refuses a file whose bytes do not match the listed SHA-256 ------------------------------
first=$(ls "$state/files" 2>/dev/null | sort -n | head -1)
stored=$(find "$state/files/$first" -name result.h5 2>/dev/null | head -1)
if [ -n "$stored" ]; then
	printf 'X' | dd of="$stored" bs=1 seek=100 conv=notrunc 2>/dev/null
	(cd "$tmp" && "$poro" fetch "$first" --out corrupt > corrupt.out 2>&1)
	rc=$?
	[ $rc -ne 0 ] && [ ! -e "$tmp/corrupt/result.h5" ] && [ ! -e "$tmp/corrupt/result.h5.part" ]
	check fetch_refuses_corrupt_file $? "exit $rc: $(cat "$tmp/corrupt.out")"
else
	echo "FAIL fetch_refuses_corrupt_file: no stored result.h5 under $state/files/$first"
fi

# ---- poro-load: submissions, then a dead server ---------------------------------------------------
"$build/poro-load" submit --server "$PORO_SERVER" --token "$user_token" --case "$tmp/short.json" \
	--clients 4 --count 40 --key-prefix t --record "$tmp/rec.txt" > "$tmp/load.txt" 2>&1
grep -q "^submissions: 40 ok, 0 errors" "$tmp/load.txt" && [ "$(awk '$2 == 201' "$tmp/rec.txt" | wc -l)" -eq 40 ]
check load_submits $? "$(cat "$tmp/load.txt")"
"$build/poro-load" submit --server "http://127.0.0.1:1" --token "$user_token" --case "$tmp/short.json" \
	--clients 2 --count 10 --record "$tmp/rec0.txt" > "$tmp/load0.txt" 2>&1
rc=$?
[ $rc -eq 0 ] && grep -q "^submissions: 0 ok, 10 errors" "$tmp/load0.txt" && [ "$(awk '$2 == 0' "$tmp/rec0.txt" | wc -l)" -eq 10 ]
check load_survives_dead_server $? "exit $rc: $(cat "$tmp/load0.txt")"
