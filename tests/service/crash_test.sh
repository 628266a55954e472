#!/usr/bin/env bash
# crash_test.sh - an acknowledged submission survives kill -9 of the server at any moment.
#
# poro-load sends 1,000 submissions from 16 concurrent clients, each with its own Idempotency-Key,
# paced to about 200 per second so the run lasts several seconds, and resends a submission that
# got no answer for up to 60 s (what a client relying on the key does). Meanwhile the server is
# killed with SIGKILL at random moments (every 0.1-0.4 s) and
# restarted on the same port and state directory. Afterwards, with the server stopped cleanly,
# the SQLite file is read directly (read-only) and checked:
#   - every submission that was acknowledged (200/201) is present exactly once, under the id the
#     client was given, and every key was acknowledged in the end;
#   - there is no job without its key (no ghost from a half-done request);
#   - no job is in two states: each job's state is the to_state of its last event, and it has
#     exactly one creation event.
#   bash tests/service/crash_test.sh BUILD_DIR
set -u
build=${1:-build}
cd "$(dirname "$0")/../.."
. tests/service/lib.sh
svc_init "$build"

COUNT=1000
CLIENTS=16
state="$SVC_TMP/crash"
mkdir -p "$state"
port=$(python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
url="http://127.0.0.1:$port"
server_pid=""
load_pid=""
cleanup_crash() {
	[ -n "$load_pid" ] && kill -9 "$load_pid" 2>/dev/null
	[ -n "$server_pid" ] && kill -9 "$server_pid" 2>/dev/null
	svc_cleanup
}
trap cleanup_crash EXIT

# start_server: starts poro-server on the fixed port and waits until it answers /healthz; a start
# that exits at once (the port not yet free) is retried.
start_server() {
	local extra=() try i
	[ -n "${SVC_ROUTES_LOG:-}" ] && extra=(--access-log "$SVC_ROUTES_LOG")
	for try in $(seq 20); do
		"$build/poro-server" --listen "127.0.0.1:$port" --state "$state" "${extra[@]}" >> "$SVC_TMP/server.out" 2>&1 &
		server_pid=$!
		for i in $(seq 100); do
			curl -s -o /dev/null "$url/healthz" && return 0
			kill -0 "$server_pid" 2>/dev/null || break
			sleep 0.02
		done
		sleep 0.1
	done
	return 1
}

token=$("$build/poro-server" token create --state "$state" --user alice --role user | tail -1)
python3 - tests/cases/terzaghi.json "$SVC_TMP/case.json" <<'EOF'
import json, sys
c = json.load(open(sys.argv[1]))
c["time"]["end"] = 0.01
json.dump(c, open(sys.argv[2], "w"))
EOF
start_server
check server_starts $? "$(tail -5 "$SVC_TMP/server.out")"

"$build/poro-load" submit --server "$url" --token "$token" --case "$SVC_TMP/case.json" --clients "$CLIENTS" \
	--count "$COUNT" --key-prefix crash --record "$SVC_TMP/record.txt" --retry-seconds 60 --pause-ms 80 \
	> "$SVC_TMP/load.out" 2>&1 &
load_pid=$!

kills=0
while kill -0 "$load_pid" 2>/dev/null; do
	# bash's own RANDOM: a Python start per kill slowed the loop enough on a busy machine that the
	# load could end after only 4 kills
	sleep "$(printf '0.%03d' $((100 + RANDOM % 301)))"
	kill -0 "$load_pid" 2>/dev/null || break
	kill -9 "$server_pid" 2>/dev/null
	wait "$server_pid" 2>/dev/null
	kills=$((kills + 1))
	start_server || break
done
wait "$load_pid"
load_pid=""
echo "INFO crash test: $kills kills of the server during $COUNT submissions; $(cat "$SVC_TMP/load.out")"
check server_killed_repeatedly "$([ "$kills" -ge 5 ]; echo $?)" "only $kills kills: the load finished too early"

kill -TERM "$server_pid" 2>/dev/null
wait "$server_pid"
server_pid=""

python3 - "$state/poro.db" "$SVC_TMP/record.txt" "$COUNT" <<'EOF'
import sqlite3, sys
db = sqlite3.connect("file:%s?mode=ro" % sys.argv[1], uri=True)
count = int(sys.argv[3])
acked, unanswered, replayed = {}, 0, 0
for line in open(sys.argv[2]):
    key, status, job = line.split()
    unanswered += status == "0"
    replayed += status == "200"
    if status in ("200", "201"):
        acked.setdefault(key, set()).add(int(job))
print("INFO crash test: %d tries got no answer (server killed or down) and were resent; %d resent "
      "submissions were answered 200 with the job an unanswered try had created" % (unanswered, replayed))

def check(name, ok, why):
    print(("PASS %s" % name) if ok else ("FAIL %s: %s" % (name, why)))

check("every_key_acknowledged_in_the_end", len(acked) == count, "%d of %d keys acknowledged" % (len(acked), count))
same = [k for k, ids in acked.items() if len(ids) != 1]
check("one_id_per_key_across_retries", not same, "keys answered with several ids: %s" % same[:5])
rows = dict(db.execute("SELECT i.key, i.job_id FROM idempotency i JOIN users u ON u.id = i.user_id WHERE u.name = 'alice'"))
missing = [k for k in acked if k not in rows]
check("acknowledged_submissions_present", not missing, "%d acknowledged keys missing, e.g. %s" % (len(missing), missing[:5]))
wrong = [k for k, ids in acked.items() if k in rows and rows[k] not in ids]
check("present_under_the_acknowledged_id", not wrong, "%d keys stored under another id, e.g. %s" % (len(wrong), wrong[:5]))
jobs = [r[0] for r in db.execute("SELECT id FROM jobs")]
check("no_duplicate_or_ghost_jobs", len(jobs) == len(rows) == len(set(rows.values())),
      "%d jobs, %d keys, %d distinct job ids" % (len(jobs), len(rows), len(set(rows.values()))))
bad_state, bad_create = [], []
for job_id, state in db.execute("SELECT id, state FROM jobs"):
    events = db.execute("SELECT from_state, to_state FROM events WHERE job_id = ? ORDER BY id", (job_id,)).fetchall()
    if not events or events[-1][1] != state:
        bad_state.append(job_id)
    if sum(1 for e in events if e[0] is None) != 1:
        bad_create.append(job_id)
check("each_job_in_one_state", not bad_state, "jobs whose state is not their last event's: %s" % bad_state[:5])
check("each_job_created_once", not bad_create, "jobs without exactly one creation event: %s" % bad_create[:5])
check("integrity_check", db.execute("PRAGMA integrity_check").fetchone()[0] == "ok", "sqlite integrity_check failed")
EOF
