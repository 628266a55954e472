#!/usr/bin/env bash
# ops_test.sh - what an operator relies on, against the real poro-server, poro-worker, poro-solve
# and poro binaries on 127.0.0.1 (docs/service.md §3 tokens, §5 state directory and worker):
#   state directory: a server started by hand under umask 022, on a state directory an older run
#     left world-readable (directory 0755, poro.db and a stored result 0644), leaves the directory,
#     the database, its -wal and -shm, files/ and everything under it private to the owner (also
#     the results it stores later); a second server on the same directory exits 1 at once naming
#     the first one's pid, and server.url keeps the first one's URL; `token create` still works;
#   /healthz: says which checks ran; a client hammering it costs at most about one write a second
#     (the health row counts its rewrites); degraded (503, naming each failing check) below the
#     free-space floor and when files/ cannot take a file; under a file-size limit (ulimit -f, so
#     the WAL cannot grow) the server survives, refuses writes with a JSON 5xx and /healthz turns
#     degraded naming database_write; restarted without the limit, every acknowledged job is
#     there and the database passes PRAGMA integrity_check;
#   tokens: listed (admin: all, a user: their own) with id, label and an 8-digit fingerprint but
#     never the token or its hash; revoked over HTTP (own or, as admin, anyone's; another user's is
#     404), offline (`poro-server token revoke`) and with `poro token revoke`: the token gets 401 on
#     its very next request; last_used_at is not rewritten on every request;
#   worker: a token file readable by others is refused; with PORO_TOKEN in its environment the
#     solver gets neither PORO_TOKEN nor the token, no token is in the process list of the server,
#     the worker or the solver; --token on argv is scrubbed from /proc/PID/cmdline; the default
#     memory limit is 3/4 of physical memory over the slots (the solver's RLIMIT_AS, and the start
#     line says so); --threads over the slots caps OMP_NUM_THREADS with a line in the job's log;
#     kill -9 of the worker takes its solver down within 5 s; a worker given --token-file runs a
#     job to success.
#   bash tests/service/ops_test.sh BUILD_DIR
set -u
build=${1:-build}
cd "$(dirname "$0")/../.."
. tests/service/lib.sh
svc_init "$build"
workers=()
solvers=()
# Only processes this script started are ever signalled: a worker or server while it is this shell's
# child, a solver while it runs this script's private copy of poro-solve.
my_child() { [ "$1" -gt 0 ] && [ "$(awk '/^PPid:/ {print $2}' "/proc/$1/status" 2>/dev/null)" = "$$" ]; }
my_solver() { [ "$1" -gt 0 ] && tr '\0' ' ' 2>/dev/null < "/proc/$1/cmdline" | grep -qF "$SVC_TMP/poro-solve"; }
cleanup_ops() {
	ulimit -S -f unlimited 2>/dev/null
	for w in "${workers[@]}"; do my_child "$w" && kill -9 "$w"; done
	for p in "${solvers[@]}"; do my_solver "$p" && kill -9 "$p"; done
	for w in "${workers[@]}"; do wait "$w" 2>/dev/null; done
	svc_cleanup
}
trap cleanup_ops EXIT
cp "$build/poro-solve" "$SVC_TMP/poro-solve"

# token_on NAME USER ROLE: a new token from `poro-server token create` on instance NAME's state
# directory (which need not have a running server), recorded for the token-leak check
token_on() {
	local t
	t=$("$build/poro-server" token create --state "$SVC_TMP/$1" --user "$2" --role "$3") || return 1
	svc_record_token "$t"
	printf '%s\n' "$t"
}
db() { python3 -c 'import sqlite3, sys; db = sqlite3.connect("file:%s?mode=ro" % sys.argv[1], uri=True); exec(sys.argv[2])' "$SVC_STATE/poro.db" "$1"; }
# make_case NAME END [PROGRESS]: tests/cases/terzaghi.json ending at END s (1.25 s of solver time
# per 0.05 s), with a progress line every PROGRESS s of wall time (default 1)
make_case() {
	python3 - tests/cases/terzaghi.json "$SVC_TMP/$1.json" "$2" "${3:-1}" <<'EOF'
import json, sys
c = json.load(open(sys.argv[1]))
c["time"]["end"] = float(sys.argv[3])
c.setdefault("output", {})["progress_interval"] = float(sys.argv[4])
json.dump(c, open(sys.argv[2], "w"))
EOF
}
submit() { # TOKEN CASE-NAME [THREADS]: prints the job id
	local code
	code=$(svc_req POST /v1/jobs "$1" -H 'Content-Type: application/json' \
		--data-binary "{\"case\": $(cat "$SVC_TMP/$2.json"), \"threads\": ${3:-1}}")
	[ "$code" = 201 ] && json '["id"]' < "$SVC_BODY"
}
# not_private DIR: every path under DIR (DIR included) with a group or other permission bit
not_private() {
	find "$1" -perm /077 -printf '%p %m\n' 2>/dev/null | sed "s|$SVC_TMP/||" | head -8
}
# health_names CHECK: the current instance's /healthz is 503 and names CHECK among its failing
# checks (a grep of the compact answer: polls stay cheap)
health_names() {
	[ "$(svc_req GET /healthz "")" = 503 ] && grep -q "\"failing\":\[[^]]*\"$1\"" "$SVC_BODY"
}
make_case tiny 0.05
# the long job prints no progress: a solver writing to the dead worker's pipe would die of SIGPIPE
# at its next line anyway; a silent one (a long step, a rare progress line) is what outlives it
make_case long 10 3600

# ---- state directory: permissions and lock ---------------------------------------------------------
state=$SVC_TMP/main
mkdir -p "$state/files/7/1"
printf 'result of an older run\n' > "$state/files/7/1/result.h5"
admin=$(token_on main root admin)
# what an older poro-server under umask 022 left behind
chmod 755 "$state" "$state/files" "$state/files/7" "$state/files/7/1"
chmod 644 "$state/poro.db" "$state/files/7/1/result.h5"
saved_umask=$(umask)
umask 022
svc_start main --lease-seconds 30
check main_server_starts $? "no server"
umask "$saved_umask"
svc_req GET /healthz "" > /dev/null   # a first write: the WAL exists from here on
open=$(not_private "$state")
[ -z "$open" ] && [ -e "$state/poro.db-wal" ] && [ -e "$state/poro.db-shm" ]
check state_dir_private_at_start $? "readable by group or others: $open"
[ "$(stat -c %a "$state")" = 700 ] && [ "$(stat -c %a "$state/poro.db")" = 600 ]
check state_dir_0700_database_0600 $? "state $(stat -c %a "$state"), poro.db $(stat -c %a "$state/poro.db")"

"$build/poro-server" --listen 127.0.0.1:0 --state "$state" > "$SVC_TMP/second.out" 2> "$SVC_TMP/second.err" &
second=$!
wait_for 5 bash -c "! kill -0 $second"
exited=$?
[ "$exited" -ne 0 ] && my_child "$second" && kill -TERM "$second"
wait "$second"
second_status=$?
[ "$exited" -eq 0 ] && [ "$second_status" -eq 1 ]
check second_server_on_state_dir_exits_1 $? "exited within 5 s: $([ "$exited" -eq 0 ] && echo yes || echo no), status $second_status"
grep -qF "state directory '$state' is in use by poro-server pid $SVC_PID" "$SVC_TMP/second.err"
check second_server_names_holder_pid $? "stderr: $(head -c 300 "$SVC_TMP/second.err")"
[ "$(cat "$state/server.url")" = "$SVC_URL" ] && [ "$(svc_req GET /healthz "")" = 200 ]
check first_server_keeps_url_and_answers $? "server.url $(cat "$state/server.url"), first at $SVC_URL"
carol=$(token_on main carol user)
check token_create_while_server_runs $? "token create failed"
[ "$(svc_req GET /v1/jobs "$carol")" = 200 ]
check token_created_offline_works $? "status $(svc_req GET /v1/jobs "$carol")"

# ---- tokens: list, fingerprint, revoke ----------------------------------------------------------------
alice=$(svc_token main alice user)
bob=$(svc_token main bob user)
pool=$(svc_token main pool worker)
code=$(svc_req POST /v1/tokens "$admin" -d '{"user": "alice", "label": "laptop"}')
laptop=$(json '["token"]' < "$SVC_BODY")
svc_record_token "$laptop"
laptop_id=$(json '["id"]' < "$SVC_BODY")
fp=$(printf '%s' "$laptop" | sha256sum | cut -c1-8)
[ "$code" = 201 ] && [ "$(json '["label"]' < "$SVC_BODY")" = laptop ] && [ "$(json '["fingerprint"]' < "$SVC_BODY")" = "$fp" ]
check token_create_label_and_fingerprint $? "status $code: $(head -c 300 "$SVC_BODY" | sed 's/poro_[A-Za-z0-9_-]*/TOKEN/g')"
svc_req GET /v1/tokens "$alice" > /dev/null   # a use, so last_used_at is set below

code=$(svc_req GET "/v1/tokens?limit=1000" "$admin")
cp "$SVC_BODY" "$SVC_TMP/tokens-admin.json"
python3 - "$SVC_TMP/tokens-admin.json" "$code" "$SVC_STATE/poro.db" "$alice" "$laptop" "$admin" <<'EOF'
import hashlib, json, sqlite3, sys
path, code, dbpath, alice, laptop, admin = sys.argv[1:7]
text = open(path).read()
page = json.loads(text) if code == "200" else {}
tokens = page.get("tokens", [])
db = sqlite3.connect("file:%s?mode=ro" % dbpath, uri=True)
rows = db.execute("SELECT count(*) FROM tokens").fetchone()[0] if code == "200" else -1
keys = {"id", "user", "role", "label", "created_at", "last_used_at", "revoked_at", "fingerprint"}
ok = code == "200" and len(tokens) == rows and all(set(t) == keys for t in tokens)
print("PASS tokens_list_admin_sees_all" if ok else "FAIL tokens_list_admin_sees_all: status %s, %d listed of %d, keys %s" % (code, len(tokens), rows, sorted(set(k for t in tokens for k in t))))
hashes = [hashlib.sha256(t.encode()).hexdigest() for t in (alice, laptop, admin)]
leak = [n for n, h in zip(("alice", "laptop", "admin"), hashes) if h in text or h[:16] in text] + \
       [n for n, t in zip(("alice", "laptop", "admin"), (alice, laptop, admin)) if t in text]
print("PASS tokens_list_shows_no_token_or_hash" if code == "200" and not leak else "FAIL tokens_list_shows_no_token_or_hash: status %s, found %s" % (code, leak))
fps = {t["fingerprint"] for t in tokens}
ok = code == "200" and all(h[:8] in fps for h in hashes)
print("PASS tokens_list_fingerprints_are_sha256_prefixes" if ok else "FAIL tokens_list_fingerprints_are_sha256_prefixes: %s" % sorted(fps))
used = [t for t in tokens if t["fingerprint"] == hashes[0][:8]]
print("PASS token_last_used_at_recorded" if used and used[0]["last_used_at"] else "FAIL token_last_used_at_recorded: %s" % used)
EOF
code=$(svc_req GET /v1/tokens "$alice")
[ "$code" = 200 ] && python3 -c '
import json, sys
t = json.load(open(sys.argv[1]))["tokens"]
sys.exit(0 if len(t) == 2 and all(x["user"] == "alice" for x in t) else 1)' "$SVC_BODY"
check tokens_list_user_sees_own $? "status $code: $(head -c 300 "$SVC_BODY")"
first_used=$(json '["tokens"][-1]["last_used_at"]' < "$SVC_BODY")
svc_req GET /v1/jobs "$alice" > /dev/null
svc_req GET /v1/tokens "$alice" > /dev/null
[ -n "$first_used" ] && [ "$(json '["tokens"][-1]["last_used_at"]' < "$SVC_BODY")" = "$first_used" ]
check token_last_used_at_not_rewritten_per_request $? "was '$first_used', now '$(json '["tokens"][-1]["last_used_at"]' < "$SVC_BODY")'"
code=$(svc_req GET /v1/tokens "$pool")
check tokens_list_worker_token_403 "$([ "$code" = 403 ]; echo $?)" "status $code"

code=$(svc_req DELETE "/v1/tokens/$laptop_id" "$bob")
[ "$code" = 404 ] && [ "$(json '["error"]["code"]' < "$SVC_BODY")" = not_found ] && [ "$(svc_req GET /v1/jobs "$laptop")" = 200 ]
check token_revoke_other_users_404 $? "status $code: $(head -c 200 "$SVC_BODY")"
code=$(svc_req DELETE "/v1/tokens/$laptop_id" "$alice")
[ "$code" = 200 ] && [ "$(json '["revoked_at"]' < "$SVC_BODY")" != None ] && [ -n "$(json '["revoked_at"]' < "$SVC_BODY")" ]
check token_revoke_own_200 $? "status $code: $(head -c 300 "$SVC_BODY")"
code=$(svc_req GET /v1/jobs "$laptop")
[ "$code" = 401 ] && [ "$(json '["error"]["code"]' < "$SVC_BODY")" = unauthorized ]
check revoked_token_401_on_next_request $? "status $code"
[ "$(svc_req GET /v1/jobs "$alice")" = 200 ]
check other_tokens_of_user_still_work $? "alice's other token refused"
code=$(svc_req DELETE "/v1/tokens/$laptop_id" "$alice")
check token_revoke_again_200 "$([ "$code" = 200 ]; echo $?)" "status $code"
bob_id=$(svc_req GET /v1/tokens "$bob" > /dev/null; json '["tokens"][0]["id"]' < "$SVC_BODY")
code=$(svc_req DELETE "/v1/tokens/$bob_id" "$admin")
[ "$code" = 200 ] && [ "$(svc_req GET /v1/jobs "$bob")" = 401 ]
check token_revoke_by_admin $? "status $code"
code=$(svc_req DELETE /v1/tokens/987654 "$admin")
check token_revoke_missing_404 "$([ "$code" = 404 ]; echo $?)" "status $code"

# offline: poro-server token list / revoke on the state directory of the running server
"$build/poro-server" token list --state "$state" > "$SVC_TMP/token-list.txt" 2>&1
carol_fp=$(printf '%s' "$carol" | sha256sum | cut -c1-8)
carol_id=$(awk -v fp="$carol_fp" '$4 == fp {print $1}' "$SVC_TMP/token-list.txt")
[ -n "$carol_id" ] && grep -q "laptop" "$SVC_TMP/token-list.txt" && ! grep -qE 'poro_[A-Za-z0-9_-]{43}|[0-9a-f]{64}' "$SVC_TMP/token-list.txt"
check offline_token_list $? "$(head -5 "$SVC_TMP/token-list.txt")"
"$build/poro-server" token revoke --state "$state" --id "${carol_id:-0}" > "$SVC_TMP/token-revoke.txt" 2>&1
[ $? -eq 0 ] && [ "$(svc_req GET /v1/jobs "$carol")" = 401 ]
check offline_token_revoke_seen_by_running_server $? "$(cat "$SVC_TMP/token-revoke.txt"); status $(svc_req GET /v1/jobs "$carol")"

# the CLI: poro token ls / revoke, as alice
code=$(svc_req POST /v1/tokens "$admin" -d '{"user": "alice", "label": "cli"}')
cli_token=$(json '["token"]' < "$SVC_BODY")
svc_record_token "$cli_token"
cli_id=$(json '["id"]' < "$SVC_BODY")
PORO_SERVER=$SVC_URL PORO_TOKEN=$alice "$build/poro" token ls > "$SVC_TMP/poro-token-ls.txt" 2>&1
ls_status=$?
[ "$ls_status" -eq 0 ] && grep -qE "^$cli_id +alice +user +[0-9a-f]{8} .* cli$" "$SVC_TMP/poro-token-ls.txt" &&
	! grep -q "bob\|root" "$SVC_TMP/poro-token-ls.txt"
check poro_token_ls $? "exit $ls_status: $(head -4 "$SVC_TMP/poro-token-ls.txt")"
PORO_SERVER=$SVC_URL PORO_TOKEN=$alice "$build/poro" token revoke "$cli_id" > "$SVC_TMP/poro-token-revoke.txt" 2>&1
rv_status=$?
[ "$rv_status" -eq 0 ] && [ "$(svc_req GET /v1/jobs "$cli_token")" = 401 ]
check poro_token_revoke $? "exit $rv_status: $(cat "$SVC_TMP/poro-token-revoke.txt")"

# ---- /healthz -------------------------------------------------------------------------------------------
code=$(svc_req GET /healthz "")
[ "$code" = 200 ] && [ "$(json '["checks"]' < "$SVC_BODY")" = \
	'{"database_read": "ok", "database_write": "ok", "disk_space": "ok", "files": "ok"}' ]
check healthz_reports_each_check $? "status $code: $(cat "$SVC_BODY")"
writes_before=$(db 'print(db.execute("SELECT writes FROM health").fetchone()[0])')
python3 - "$SVC_URL" > "$SVC_TMP/hammer.txt" <<'EOF'
import http.client, sys, time, urllib.parse
u = urllib.parse.urlparse(sys.argv[1])
conn = http.client.HTTPConnection(u.hostname, u.port, timeout=10)
start, n, bad = time.monotonic(), 0, 0
while time.monotonic() - start < 2.5:
    conn.request("GET", "/healthz")
    r = conn.getresponse()
    r.read()
    n += 1
    bad += r.status != 200
print(n, bad, "%.2f" % (time.monotonic() - start))
EOF
read -r hammered hammer_bad hammer_seconds < "$SVC_TMP/hammer.txt"
writes_after=$(db 'print(db.execute("SELECT writes FROM health").fetchone()[0])')
writes=$(( ${writes_after:-0} - ${writes_before:-0} ))
echo "INFO /healthz hammered: $hammered requests in $hammer_seconds s without a token cost $writes health writes"
python3 -c 'import sys; n, bad, s, w = int(sys.argv[1]), int(sys.argv[2]), float(sys.argv[3]), int(sys.argv[4]); sys.exit(0 if n > 10 and bad == 0 and 1 <= w <= s + 2 else 1)' \
	"${hammered:-0}" "${hammer_bad:-1}" "${hammer_seconds:-0}" "$writes"
check healthz_hammered_about_one_write_per_second $? "$hammered requests ($hammer_bad not 200) in $hammer_seconds s, $writes writes"

# ---- worker: token handling, memory and thread defaults, death with the worker ---------------------------
printf '%s\n' "$pool" > "$SVC_TMP/pool.token"
chmod 644 "$SVC_TMP/pool.token"
"$build/poro-worker" --server "$SVC_URL" --token-file "$SVC_TMP/pool.token" --work "$SVC_TMP/work-open" \
	--solver "$SVC_TMP/poro-solve" > "$SVC_TMP/open.log" 2>&1 &
open_worker=$!
workers+=("$open_worker")
wait_for 5 bash -c "! kill -0 $open_worker"
wait "$open_worker"
open_status=$?
[ "$open_status" -eq 2 ] && grep -q "token file '$SVC_TMP/pool.token' is readable by group or others" "$SVC_TMP/open.log"
check worker_refuses_token_file_readable_by_others $? "exit $open_status: $(head -c 300 "$SVC_TMP/open.log")"
chmod 600 "$SVC_TMP/pool.token"

# worker A: the token in its environment, 2 threads for 2 slots, the default memory limit
PORO_TOKEN=$pool "$build/poro-worker" --server "$SVC_URL" --work "$SVC_TMP/work-a" --slots 2 --threads 2 \
	--solver "$SVC_TMP/poro-solve" --name wa > "$SVC_TMP/wa.log" 2>&1 &
wa=$!
workers+=("$wa")
long_job=$(submit "$alice" long 2)
started() { grep -q "job $long_job attempt 1: solver started" "$SVC_TMP/wa.log"; }
wait_for 30 started
check long_job_starts "$?" "$(tail -3 "$SVC_TMP/wa.log")"
solver=$(sed -n "s/.*job $long_job attempt 1: solver started (pid \([0-9]*\).*/\1/p" "$SVC_TMP/wa.log" | head -1)
solver=${solver:-0}
[ "$solver" -gt 0 ] && solvers+=("$solver")

tr '\0' '\n' > "$SVC_TMP/solver-env.txt" 2>/dev/null < "/proc/$solver/environ"
[ -s "$SVC_TMP/solver-env.txt" ] && ! grep -q '^PORO_TOKEN=' "$SVC_TMP/solver-env.txt" && ! grep -qF "$pool" "$SVC_TMP/solver-env.txt"
check solver_environment_has_no_token $? "$(grep -c . "$SVC_TMP/solver-env.txt") variables, PORO_TOKEN: $(grep -c '^PORO_TOKEN=' "$SVC_TMP/solver-env.txt")"
ps -o args= -p "$SVC_PID,$wa,$solver" > "$SVC_TMP/ps.txt" 2>&1
printf '%s\n' "$admin" "$alice" "$bob" "$pool" "$carol" "$laptop" "$cli_token" > "$SVC_TMP/tokens.txt"
[ "$(grep -c . "$SVC_TMP/ps.txt")" -eq 3 ] && ! grep -qF -f "$SVC_TMP/tokens.txt" "$SVC_TMP/ps.txt" &&
	! grep -qE 'poro_[A-Za-z0-9_-]{43}' "$SVC_TMP/ps.txt"
check no_token_in_process_list $? "$(grep -c . "$SVC_TMP/ps.txt") processes listed; token shown: $(grep -cE 'poro_[A-Za-z0-9_-]{43}' "$SVC_TMP/ps.txt")"

grep -q '^OMP_NUM_THREADS=1$' "$SVC_TMP/solver-env.txt"
check thread_budget_caps_omp_num_threads $? "solver has $(grep '^OMP_NUM_THREADS=' "$SVC_TMP/solver-env.txt")"
clamp_logged() {
	svc_req GET "/v1/jobs/$long_job/log" "$alice" > /dev/null &&
		grep -q "^running with 1 thread of the 2 asked: this worker gives each of its 2 slots 1 thread (--threads 2)$" "$SVC_BODY"
}
wait_for 15 clamp_logged
check thread_clamp_line_in_job_log $? "log head: $(head -2 "$SVC_BODY")"
grep -q "wa serving .* with 2 slots of 1 thread (--threads 2)" "$SVC_TMP/wa.log"
check worker_start_line_states_threads $? "$(head -1 "$SVC_TMP/wa.log")"

expected_mb=$(python3 -c 'import os; print(int(0.75 * (os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE") / 2**20) / 2))')
expected_limit=$(( expected_mb << 20 ))
expected_line="memory limit $expected_mb MB per solver (default: 75% of [0-9]* MB physical / 2 slots)"
if svc_asan "$build/poro-worker"; then
	# an AddressSanitizer build (make test SAN=1) defaults to no limit: its shadow memory needs the address space
	expected_limit=unlimited
	expected_line="no memory limit (default of this build: AddressSanitizer"
fi
as_limit=$(awk '/^Max address space/ {print $4}' "/proc/$solver/limits" 2>/dev/null)
echo "INFO default memory limit: $expected_mb MB per solver with 2 slots; the solver's RLIMIT_AS is $as_limit bytes"
[ "$as_limit" = "$expected_limit" ]
check default_memory_limit_three_quarters_over_slots $? "RLIMIT_AS '$as_limit', expected $expected_limit"
grep -q "$expected_line" "$SVC_TMP/wa.log"
check worker_start_line_states_memory_limit $? "$(head -1 "$SVC_TMP/wa.log")"

my_child "$wa" && kill -9 "$wa"
wait "$wa" 2>/dev/null
solver_gone() { [ ! -e "/proc/$solver" ] || grep -q '^[0-9]* (.*) Z' "/proc/$solver/stat"; }
[ "$solver" -gt 0 ] && wait_for 5 solver_gone
check solver_dies_with_worker_kill_9 $? "solver pid $solver still running 5 s after kill -9 of its worker"
# the orphaned attempt would return to the queue when its lease expires: cancel it
svc_req POST "/v1/jobs/$long_job/cancel" "$alice" > /dev/null

# worker B: the token from a private file, runs a job to success (its result stored privately)
env -u PORO_TOKEN "$build/poro-worker" --server "$SVC_URL" --token-file "$SVC_TMP/pool.token" \
	--work "$SVC_TMP/work-b" --solver "$SVC_TMP/poro-solve" --name wb > "$SVC_TMP/wb.log" 2>&1 &
wb=$!
workers+=("$wb")
tiny_job=$(submit "$alice" tiny)
tiny_done() { svc_req GET "/v1/jobs/$tiny_job" "$alice" > /dev/null; grep -q '"state":"succeeded"' "$SVC_BODY"; }
wait_for 60 tiny_done
check worker_with_token_file_runs_job $? "job $tiny_job: $(head -c 200 "$SVC_BODY"); $(tail -2 "$SVC_TMP/wb.log")"
! grep -q "warning" "$SVC_TMP/wb.log"
check token_file_worker_no_warning $? "$(grep warning "$SVC_TMP/wb.log")"
open=$(not_private "$state")
[ -z "$open" ] && [ -n "$(find "$state/files/$tiny_job" -type f 2>/dev/null)" ]
check stored_results_private $? "readable by group or others: $open"
my_child "$wb" && kill -TERM "$wb"
wait "$wb"

# worker C: --token on the command line works, is warned about and does not stay in /proc/PID/cmdline
"$build/poro-worker" --server "$SVC_URL" --token "$pool" --work "$SVC_TMP/work-c" --solver "$SVC_TMP/poro-solve" \
	--name wc > "$SVC_TMP/wc.log" 2>&1 &
wc_pid=$!
workers+=("$wc_pid")
wc_up() { grep -q "wc serving" "$SVC_TMP/wc.log"; }
wait_for 10 wc_up
tr '\0' ' ' > "$SVC_TMP/wc-cmdline.txt" 2>/dev/null < "/proc/$wc_pid/cmdline"
[ -s "$SVC_TMP/wc-cmdline.txt" ] && ! grep -qF "$pool" "$SVC_TMP/wc-cmdline.txt" &&
	grep -q "warning: --token shows the token" "$SVC_TMP/wc.log"
check worker_token_argument_scrubbed_and_warned $? "cmdline holds the token: $(grep -cF "$pool" "$SVC_TMP/wc-cmdline.txt"); $(head -2 "$SVC_TMP/wc.log")"
my_child "$wc_pid" && kill -TERM "$wc_pid"
wait "$wc_pid"

grep -q -- '--token-file' tests/run_example.sh && ! grep -qE -- '--token[ =]' tests/run_example.sh
check make_run_passes_worker_token_by_file $? "tests/run_example.sh: $(grep -n -- '--token' tests/run_example.sh)"

# ---- /healthz degraded: free-space floor, files/ refusing files -----------------------------------------
svc_start floor --min-free-mb 1073741824
check floor_server_starts $? "no server"
code=$(svc_req GET /healthz "")
[ "$code" = 503 ] && [ "$(json '["status"]' < "$SVC_BODY")" = degraded ] && [ "$(json '["failing"]' < "$SVC_BODY")" = '["disk_space"]' ]
check healthz_degraded_below_free_space_floor $? "status $code: $(cat "$SVC_BODY")"
mv "$SVC_STATE/files" "$SVC_STATE/files.away"
printf 'not a directory\n' > "$SVC_STATE/files"
wait_for 10 health_names files
check healthz_degraded_when_files_refuses $? "$(cat "$SVC_BODY")"
[ "$(json '["failing"]' < "$SVC_BODY")" = '["disk_space", "files"]' ] && [ "$(json '["database"]' < "$SVC_BODY")" = ok ]
check healthz_names_each_failing_check $? "$(cat "$SVC_BODY")"
rm "$SVC_STATE/files"
mv "$SVC_STATE/files.away" "$SVC_STATE/files"
svc_stop floor

# ---- /healthz degraded and writes refused under a file-size limit; nothing acknowledged lost -----------
make_case small 0.01
svc_start fs
check fs_server_starts $? "no server"
fs_alice=$(svc_token fs alice user)
acked=()
for i in 1 2 3; do acked+=("$(submit "$fs_alice" small)"); done
svc_stop fs
# the WAL may grow 64 KiB past the database file, not more: a handful of commits, then EFBIG
limit_kb=$(( $(stat -c %s "$SVC_TMP/fs/poro.db") / 1024 + 64 ))
ulimit -S -f "$limit_kb"
svc_start fs
started=$?
ulimit -S -f unlimited
check fs_server_starts_under_file_size_limit "$started" "no server under ulimit -f $limit_kb"
refused=""
for i in $(seq 100); do
	code=$(svc_req POST /v1/jobs "$fs_alice" -H 'Content-Type: application/json' --data-binary "{\"case\": $(cat "$SVC_TMP/small.json")}")
	if [ "$code" = 201 ]; then
		acked+=("$(json '["id"]' < "$SVC_BODY")")
	else
		refused=$code
		break
	fi
done
echo "INFO under ulimit -f $limit_kb (KiB): ${#acked[@]} jobs acknowledged in all, then a submission got $refused"
error_code=$(json '["error"]["code"]' < "$SVC_BODY")
[ "${refused:-0}" -ge 500 ] && [ "${refused:-0}" -le 599 ] && [ -n "$error_code" ]
check write_past_file_size_limit_is_json_5xx $? "status '$refused': $(head -c 300 "$SVC_BODY")"
kill -0 "$SVC_PID" 2>/dev/null
check server_survives_file_size_limit $? "the server died: $(tail -3 "$SVC_TMP/fs.err")"
wait_for 30 health_names database_write
check healthz_degraded_when_writes_fail $? "$(head -c 400 "$SVC_BODY")"
svc_stop fs
svc_start fs
check fs_server_restarts_without_limit $? "no server"
missing=""
for id in "${acked[@]}"; do
	[ "$(svc_req GET "/v1/jobs/$id" "$fs_alice")" = 200 ] || missing="$missing $id"
done
[ -z "$missing" ] && [ "${#acked[@]}" -ge 3 ]
check acknowledged_jobs_survive_write_failures $? "missing:$missing of ${acked[*]}"
wait_for 5 bash -c "[ \"\$(curl -s -o /dev/null -w '%{http_code}' $SVC_URL/healthz)\" = 200 ]"
check healthz_ok_after_limit_lifted $? "$(curl -s "$SVC_URL/healthz")"
svc_stop fs
integrity=$(python3 -c 'import sqlite3, sys; print(sqlite3.connect(sys.argv[1]).execute("PRAGMA integrity_check").fetchone()[0])' "$SVC_TMP/fs/poro.db" 2>&1)
check database_integrity_after_write_failures "$([ "$integrity" = ok ]; echo $?)" "integrity_check: $integrity"
