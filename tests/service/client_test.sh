#!/usr/bin/env bash
# client_test.sh - drives the real poro-server, poro-worker, poro and poro-load binaries over HTTP on
# 127.0.0.1 (the server picks a free port; its URL is read from STATE/server.url) with a temporary
# state directory, and checks what a user and an operator see: submit --wait, logs, fetch with
# checksums, show, ls, schema errors printed as "poro: message (code, field ...)", cancel of a
# running solver (its process gone within seconds), kill -9 of a worker mid-run (the job resumes on
# another worker from its checkpoint), a draining worker finishing its job, logs -f, a corrupted
# stored file refused by fetch, and poro-load surviving a dead server. Then the CLI's habits: the
# exit status of each kind of failure (unreachable, token, unknown id, invalid case, failed and
# cancelled jobs, logs -f included), every problem of a refused case, --json as the API's object,
# poro wait, the bar on a 72-column terminal (under script) and none when stdout is a file, pages
# of ls, why a queued job waits (no live worker, a retry's backoff, the user's cap, behind other
# jobs), fetch of named files and of a running job's partial result (opened with h5dump), tokens
# listed and revoked, --opt=value, --help and --version. Short runs use tests/cases/terzaghi.json
# with edited end times (1.25 s of solver time per 0.05 s simulated). Prints "PASS name" or
# "FAIL name: why" per check. Runs in about 60 s.
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

# api METHOD PATH TOKEN [curl arguments...]: one request; the status on stdout, the body in
# $tmp/api.json (the token reaches curl through a file, not its command line)
api() {
	local method=$1 path=$2
	(umask 077 && printf 'Authorization: Bearer %s\n' "$3" > "$tmp/.auth")
	shift 3
	curl -s -X "$method" -H "@$tmp/.auth" -o "$tmp/api.json" -w '%{http_code}' "$@" "$PORO_SERVER$path"
}
# same_json A B: the two files hold the same JSON value
same_json() { python3 -c 'import json, sys; sys.exit(json.load(open(sys.argv[1])) != json.load(open(sys.argv[2])))' "$1" "$2"; }

# ---- why a queued job waits: no live worker, then a retry's backoff -------------------------------
# (the server names the reason in the job's "waiting"; ls shows it, show says it in words)
waiter=$("$poro" submit "$tmp/short.json" --name waits 2> "$tmp/waits.err")
"$poro" show --json "$waiter" > "$tmp/waits.json"
[ "$(json '["waiting"]["reason"]' < "$tmp/waits.json")" = no_worker ] && grep -q "waits: no worker has asked for work" "$tmp/waits.err" &&
	"$poro" ls | grep -q "^$waiter .*queued .* no live worker$" && "$poro" show "$waiter" | grep -q "^waiting .* no worker has asked"
check queued_job_says_no_live_worker $? "$(cat "$tmp/waits.err"); $(head -c 600 "$tmp/waits.json")"
code=$(api POST /v1/worker/claim "$worker_token" -d '{"worker": "test:1", "wait_seconds": 0}')
claimed=$(json '["job"]["id"]' < "$tmp/api.json")
code2=$(api POST "/v1/worker/jobs/$waiter/finish" "$worker_token" -d '{"attempt": 1, "outcome": "infrastructure", "message": "host lost"}')
[ "$code" = 200 ] && [ "$claimed" = "$waiter" ] && [ "$code2" = 200 ] && [ "$(json '["waiting"]["reason"]' < "$tmp/api.json")" = retry_backoff ]
check requeued_job_says_retry_backoff $? "claim $code (job $claimed), finish $code2: $(head -c 400 "$tmp/api.json")"

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

# ==== the CLI's habits: exit statuses, --json, wait, the bar, pages of ls, fetch of any file =========
drained=$id   # the medium job the drained worker finished: it ran long enough to leave checkpoints
# the load's queued jobs would keep the next worker busy for a minute: cancel them (ids from ls --json)
"$poro" ls --json --state queued --limit 1000 |
	python3 -c 'import json, sys; print("\n".join(str(j["id"]) for j in json.load(sys.stdin)["jobs"]))' > "$tmp/queued.txt"
while read -r q; do "$poro" cancel "$q" > /dev/null; done < "$tmp/queued.txt"
start_worker w3
python3 - "$tmp/short.json" "$tmp/falls.json" "$tmp/bad3.json" <<'PY'
import json, sys
c = json.load(open(sys.argv[1]))
f = json.loads(json.dumps(c))   # a solver failure: the column falls out of the grid
f["boundaries"]["bottom"] = {"soil": "free", "water": "free"}
f["gravity"]["acceleration"] = [0.0, -2000.0]
json.dump(f, open(sys.argv[2], "w"))
c["grid"]["cell_size"] = "x"     # three problems in one case
c["materials"][0]["poisson_ratio"] = 0.7
c["time"]["dtt"] = 1
json.dump(c, open(sys.argv[3], "w"))
PY

# ---- --help, --version: exit 0, the exit statuses listed from their one table -----------------------
"$poro" --help > "$tmp/help.txt" 2>&1
rc=$?
[ $rc -eq 0 ] && grep -q "^  3   the server cannot be reached" "$tmp/help.txt" && grep -q "^  4   authentication" "$tmp/help.txt" &&
	grep -q "^  5   no such job" "$tmp/help.txt" && grep -q "^  6   the case file" "$tmp/help.txt" &&
	grep -q "^  7   the job failed" "$tmp/help.txt" && grep -q "^  8   the job was cancelled" "$tmp/help.txt"
check poro_help_exits_0_listing_exit_statuses $? "exit $rc: $(head -c 600 "$tmp/help.txt")"
ok=0
for b in poro poro-load; do   # the version is the build's git describe (a changed tree rebuilds only what changed)
	out=$("$build/$b" --version 2>&1) || ok=1
	echo "$out" | grep -Eqx "$b [A-Za-z0-9._-]+" || ok=1
	{ [ ! -d .git ] && [ ! -f .git ]; } || [ "$out" != "$b unknown" ] || ok=1
	"$build/$b" --help > "$tmp/$b.help" 2>&1 && grep -q "usage: $b" "$tmp/$b.help" || ok=1
done
for c in submit wait ls show logs cancel rm fetch token; do
	PORO_SERVER= "$poro" "$c" --help > "$tmp/c.help" 2>&1 && grep -q "^usage: poro $c" "$tmp/c.help" || ok=1
done
check help_and_version_exit_0 $ok "poro --version '$("$poro" --version 2>&1)', poro-load --version '$("$build/poro-load" --version 2>&1)'"
"$poro" submit --wiat "$tmp/short.json" > /dev/null 2> "$tmp/opt.err"
rc=$?
[ $rc -eq 2 ] && grep -q "^poro submit: unrecognized option '--wiat'" "$tmp/opt.err"
check unknown_option_exits_2_naming_it $? "exit $rc: $(cat "$tmp/opt.err")"

# ---- one exit status per kind of failure ---------------------------------------------------------------
PORO_SERVER=http://127.0.0.1:1 "$poro" ls > /dev/null 2> "$tmp/down.err"
rc=$?
[ $rc -eq 3 ] && grep -q "^poro: cannot reach 'http://127.0.0.1:1'" "$tmp/down.err"
check exit_3_server_unreachable $? "exit $rc: $(cat "$tmp/down.err")"
PORO_TOKEN=poro_0000000000000000000000000000000000000000000 "$poro" ls > /dev/null 2> "$tmp/auth.err"
rc=$?
[ $rc -eq 4 ] && grep -q "(unauthorized" "$tmp/auth.err"
check exit_4_bad_token $? "exit $rc: $(cat "$tmp/auth.err")"
for c in show wait cancel fetch; do
	"$poro" $c 999999 > /dev/null 2> "$tmp/nf.err"
	rc=$?
	[ $rc -eq 5 ] && grep -q "no job 999999 (not_found)" "$tmp/nf.err"
	check "exit_5_unknown_id_$c" $? "exit $rc: $(cat "$tmp/nf.err")"
done
"$poro" submit "$tmp/bad3.json" > /dev/null 2> "$tmp/bad3.err"
rc=$?
[ $rc -eq 6 ] && grep -q "^/grid/cell_size: expected a number" "$tmp/bad3.err" &&
	grep -q "^/materials/0/poisson_ratio: must be" "$tmp/bad3.err" && grep -q "^/time/dtt: unknown key" "$tmp/bad3.err"
check exit_6_invalid_case_every_problem_listed $? "exit $rc: $(cat "$tmp/bad3.err")"
echo '{"time": ' > "$tmp/broken.json"
"$poro" submit "$tmp/broken.json" > /dev/null 2> "$tmp/broken.err"
rc=$?
[ $rc -eq 6 ] && grep -q "'$tmp/broken.json' is not JSON: line" "$tmp/broken.err"
check exit_6_case_not_json $? "exit $rc: $(cat "$tmp/broken.err")"
fid=$("$poro" submit "$tmp/falls.json" --wait 2> "$tmp/falls.err")
rc=$?
[ $rc -eq 7 ] && grep -q "^job $fid failed after .*left the grid" "$tmp/falls.err"
check exit_7_submit_wait_failed_job $? "exit $rc: $(tail -2 "$tmp/falls.err")"
"$poro" wait "$fid" > /dev/null 2>&1
rc=$?
check exit_7_wait_failed_job $(( rc != 7 )) "exit $rc"
timeout 60 "$poro" logs -f "$fid" > "$tmp/falls.log" 2>&1
rc=$?
[ $rc -eq 7 ] && grep -q "left the grid" "$tmp/falls.log"
check exit_7_logs_follow_failed_job $? "exit $rc: $(tail -2 "$tmp/falls.log")"

# ---- --json: the API's object, as the server answers it --------------------------------------------------
"$poro" submit --json --name=json-run --priority=7 "$tmp/short.json" > "$tmp/submit.json"
rc=$?
jid=$(json '["id"]' < "$tmp/submit.json")
[ $rc -eq 0 ] && [ "$(json '["name"]' < "$tmp/submit.json")" = json-run ] && [ "$(json '["priority"]' < "$tmp/submit.json")" = 7 ] &&
	[ "$(json '["state"]' < "$tmp/submit.json")" = queued ] && [ "$(json '["files"]' < "$tmp/submit.json")" = "" ]
check submit_json_is_the_job $? "exit $rc: $(head -c 400 "$tmp/submit.json")"
"$poro" wait --json "$jid" > "$tmp/wait.json" 2> "$tmp/waitj.err"
rc=$?
code=$(api GET "/v1/jobs/$jid" "$user_token")
[ $rc -eq 0 ] && [ "$code" = 200 ] && same_json "$tmp/wait.json" "$tmp/api.json" && [ "$(json '["state"]' < "$tmp/wait.json")" = succeeded ]
check wait_json_is_the_job_as_it_ended $? "exit $rc: $(head -c 300 "$tmp/wait.json")"
"$poro" show --json "$jid" > "$tmp/show.json"
rc=$?
[ $rc -eq 0 ] && same_json "$tmp/show.json" "$tmp/api.json"
check show_json_is_the_api_job $? "exit $rc: $(head -c 300 "$tmp/show.json")"
"$poro" ls --json --state=succeeded,failed > "$tmp/ls.json"
rc=$?
code=$(api GET "/v1/jobs?state=succeeded,failed&limit=100" "$user_token")
[ $rc -eq 0 ] && [ "$code" = 200 ] && same_json "$tmp/ls.json" "$tmp/api.json"
check ls_json_is_the_api_page $? "exit $rc: $(head -c 300 "$tmp/ls.json")"

# ---- ls: pages with a hint to the next, the elapsed time -----------------------------------------------
"$poro" ls --state=succeeded --limit=1 > "$tmp/page1.txt" 2> "$tmp/page1.err"
rc=$?
row1=$(awk 'NR == 2 {print $1}' "$tmp/page1.txt")
next=$(sed -n 's/^poro: more jobs: \(poro ls --after [0-9]* --state succeeded --limit 1\)$/\1/p' "$tmp/page1.err")
[ $rc -eq 0 ] && [ "$(wc -l < "$tmp/page1.txt")" -eq 2 ] && [ -n "$next" ] && head -1 "$tmp/page1.txt" | grep -q "ELAPSED" &&
	awk 'NR == 2' "$tmp/page1.txt" | grep -Eq " 0:[0-9]{2} "
check ls_page_says_how_to_get_the_next $? "exit $rc: $(cat "$tmp/page1.txt" "$tmp/page1.err")"
"$poro" ${next#poro } > "$tmp/page2.txt" 2>/dev/null
row2=$(awk 'NR == 2 {print $1}' "$tmp/page2.txt")
[ -n "$row2" ] && [ "$row2" -lt "${row1:-0}" ] && awk 'NR == 2 {print $2}' "$tmp/page2.txt" | grep -qx succeeded
check ls_next_page_follows $? "page 1 row '$row1', page 2: $(cat "$tmp/page2.txt")"

# ---- the progress bar: fitted to a 72-column terminal, ending at 100%; none when stdout is a file ------
script -qec "stty cols 72 rows 24; '$poro' submit '$tmp/medium.json' --wait" /dev/null > "$tmp/bar.raw" 2>&1
rc=$?
python3 - "$tmp/bar.raw" > "$tmp/bar.check" <<'PY'
import re, sys
text = open(sys.argv[1], encoding="utf-8", errors="replace").read()
pieces = [p for p in re.split(r"[\r\n]", text) if p.strip()]
bars = [p for p in pieces if re.match(r"job \d+ \w+ +\[", p)]
wide = [p for p in pieces if len(p) > 71]
ok = bars and not wide and "100%" in bars[-1] and "succeeded" in bars[-1] and any("elapsed" in b for b in bars)
print("ok" if ok else "bars %d, wider than 71: %r, last bar %r" % (len(bars), wide[:2], bars[-1:] ))
PY
[ $rc -eq 0 ] && [ "$(cat "$tmp/bar.check")" = ok ]
check bar_fits_72_columns_and_ends_at_100 $? "exit $rc: $(cat "$tmp/bar.check")"
script -qec "stty cols 72 rows 24; '$poro' submit '$tmp/short.json' --wait > '$tmp/nobar.out'" /dev/null > "$tmp/nobar.raw" 2>&1
rc=$?
# (the terminal ends lines with \r\n; a bar is redrawn with a \r of its own)
[ $rc -eq 0 ] && ! grep -q '\[' "$tmp/nobar.raw" && python3 -c 'import re, sys; sys.exit(bool(re.search(rb"\r(?!\n)", open(sys.argv[1], "rb").read())))' "$tmp/nobar.raw" &&
	grep -q "succeeded" "$tmp/nobar.raw" && grep -Eq '^[0-9]+$' "$tmp/nobar.out"
check no_bar_when_stdout_is_not_a_terminal $? "exit $rc: $(cat -A "$tmp/nobar.raw" | head -5)"

# ---- why a queued job waits: the user's cap on running jobs, behind other jobs ----------------------------
admin=$("$build/poro-server" token create --state "$state" --user root --role admin | tail -1)
api POST /v1/users "$admin" -d '{"name": "carol", "max_running": 1}' > /dev/null
carol=$("$build/poro-server" token create --state "$state" --user carol --role user | tail -1)
c1=$(PORO_TOKEN=$carol "$poro" submit "$tmp/long.json")
carol_running() { [ "$(PORO_TOKEN=$carol "$poro" show --json "$c1" | json '["state"]')" = running ]; }
wait_for 30 carol_running
c2=$(PORO_TOKEN=$carol "$poro" submit "$tmp/long.json")
a1=$("$poro" submit "$tmp/short.json")
PORO_TOKEN=$carol "$poro" show --json "$c2" > "$tmp/c2.json"
"$poro" show --json "$a1" > "$tmp/a1.json"
[ "$(json '["waiting"]["reason"]' < "$tmp/c2.json")" = user_running_cap ] &&
	PORO_TOKEN=$carol "$poro" ls | grep -q "^$c2 .*queued .* your cap on running jobs$"
check queued_job_says_user_cap $? "$(head -c 500 "$tmp/c2.json")"
[ "$(json '["waiting"]["reason"]' < "$tmp/a1.json")" = behind_other_jobs ] && "$poro" ls | grep -q "^$a1 .*queued .* behind other jobs$"
check queued_job_says_behind_other_jobs $? "$(head -c 500 "$tmp/a1.json")"

# ---- fetch of a running job: the newest result.h5 snapshot, partial, and readable -------------------------
wait_for 60 grep -q "job $c1 attempt .*: checkpoint uploaded" "$tmp/w3.log"
(cd "$tmp" && PORO_TOKEN=$carol "$poro" fetch "$c1" --out=partial > partial.out 2> partial.err)
rc=$?
h5dump -H "$tmp/partial/result.h5" > "$tmp/partial.h5dump" 2>&1
h5=$?
[ $rc -eq 0 ] && [ $h5 -eq 0 ] && grep -q 'GROUP "frames"' "$tmp/partial.h5dump" && grep -q "result.h5 is partial" "$tmp/partial.err" &&
	[ ! -e "$tmp/partial/result.xdmf" ]
check fetch_running_job_partial_result_opens $? "exit $rc, h5dump $h5: $(cat "$tmp/partial.err"); $(head -3 "$tmp/partial.h5dump")"
if /usr/bin/python3 -c 'import h5py' 2> /dev/null; then
	/usr/bin/python3 -c 'import h5py, sys; f = h5py.File(sys.argv[1], "r"); assert len(f["frames"]) >= 1; assert "case" in f' \
		"$tmp/partial/result.h5" 2> "$tmp/h5py.err"
	check fetch_running_job_partial_result_opens_with_h5py $? "$(tail -2 "$tmp/h5py.err")"
fi

# ---- cancel: wait and logs -f exit 8; cancel --json is the job after the cancel ----------------------------
PORO_TOKEN=$carol "$poro" wait "$c1" > /dev/null 2>&1 &
waiter_pid=$!
PORO_TOKEN=$carol timeout 60 "$poro" logs -f "$c1" > /dev/null 2>&1 &
follower_pid=$!
PORO_TOKEN=$carol "$poro" cancel --json "$c2" > "$tmp/cancel.json"
rc=$?
[ $rc -eq 0 ] && [ "$(json '["state"]' < "$tmp/cancel.json")" = cancelled ] && [ "$(json '["id"]' < "$tmp/cancel.json")" = "$c2" ]
check cancel_json_is_the_job $? "exit $rc: $(head -c 300 "$tmp/cancel.json")"
"$poro" cancel "$a1" > /dev/null
PORO_TOKEN=$carol "$poro" cancel "$c1" > /dev/null
wait "$waiter_pid"
rc=$?
check exit_8_wait_cancelled_job $(( rc != 8 )) "exit $rc"
wait "$follower_pid"
rc=$?
check exit_8_logs_follow_cancelled_job $(( rc != 8 )) "exit $rc"
"$poro" wait "$a1" > /dev/null 2>&1
rc=$?
check exit_8_wait_job_cancelled_while_queued $(( rc != 8 )) "exit $rc"

# ---- fetch of named files: probes.json, the log, a checkpoint; refusals ----------------------------------
"$poro" fetch "$drained" --out "$tmp/named" --file probes.json --file=log --file checkpoint.h5 > "$tmp/named.out" 2>&1
rc=$?
code=$(api GET "/v1/jobs/$drained/probes" "$user_token")
[ $rc -eq 0 ] && [ "$code" = 200 ] && same_json "$tmp/named/probes.json" "$tmp/api.json" && grep -q "^done:" "$tmp/named/log" &&
	[ "$(sha256sum < "$tmp/named/checkpoint.h5" | cut -d' ' -f1)" = "$(awk '$1 ~ /checkpoint.h5$/ {print $NF}' "$tmp/named.out")" ]
check fetch_named_files $? "exit $rc: $(cat "$tmp/named.out")"
"$poro" fetch "$jid" --out "$tmp/named" --file frames.h5 > /dev/null 2> "$tmp/nofile.err"
rc=$?
[ $rc -eq 5 ] && grep -q "job $jid has no file 'frames.h5' (its files: .*result.h5" "$tmp/nofile.err"
check fetch_unknown_file_exit_5_naming_the_files $? "exit $rc: $(cat "$tmp/nofile.err")"
"$poro" fetch "$jid" --out "$tmp/named" --file ../escape > /dev/null 2> "$tmp/badname.err"
rc=$?
[ $rc -eq 2 ] && grep -q "'../escape' is not a file name" "$tmp/badname.err" && [ ! -e "$tmp/escape" ]
check fetch_bad_file_name_exit_2 $? "exit $rc: $(cat "$tmp/badname.err")"

# ---- tokens: ls and revoke, with --json -------------------------------------------------------------------
code=$(api POST /v1/tokens "$admin" -d '{"user": "alice", "label": "spare"}')
spare=$(json '["token"]' < "$tmp/api.json")
spare_id=$(json '["id"]' < "$tmp/api.json")
svc_record_token "$spare"
svc_record_token "$admin"
svc_record_token "$carol"
"$poro" token ls --json > "$tmp/tokens.json"
rc=$?
python3 - "$tmp/tokens.json" "$spare_id" <<'PY'
import json, sys
page = json.load(open(sys.argv[1]))
ids = [t["id"] for t in page["tokens"]]
assert page["next_after"] is None and int(sys.argv[2]) in ids and all(t["user"] == "alice" for t in page["tokens"])
assert not any("token" in t for t in page["tokens"])
PY
ok=$?
"$poro" token ls | grep -qE "^$spare_id +alice +user +[0-9a-f]{8} .* spare$"
check token_ls_json_and_table $(( rc != 0 || ok != 0 || $? != 0 )) "exit $rc: $(head -c 300 "$tmp/tokens.json")"
"$poro" token revoke --json "$spare_id" > "$tmp/revoke.json"
rc=$?
PORO_TOKEN=$spare "$poro" ls > /dev/null 2>&1
after=$?
[ $rc -eq 0 ] && [ "$(json '["id"]' < "$tmp/revoke.json")" = "$spare_id" ] && [ -n "$(json '["revoked_at"]' < "$tmp/revoke.json")" ] &&
	[ "$(json '["revoked_at"]' < "$tmp/revoke.json")" != null ] && [ $after -eq 4 ]
check token_revoke_json_then_exit_4 $? "exit $rc, the revoked token's ls exit $after: $(head -c 300 "$tmp/revoke.json")"
"$poro" token revoke 999999 > /dev/null 2>&1
rc=$?
check token_revoke_unknown_exit_5 $(( rc != 5 )) "exit $rc"
