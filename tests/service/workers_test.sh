#!/usr/bin/env bash
# workers_test.sh - several real poro-worker processes against one real poro-server:
#   f. fair share: with user A holding 200 queued jobs, user B's job starts within one slot;
#   d. three workers with two slots each never run a job in two live attempts (200 short jobs):
#      every job ends succeeded after exactly one claim, and its events go queued -> running ->
#      succeeded with nothing in between;
#   c. a worker stopped with SIGSTOP beyond its lease: the job is re-leased to another worker,
#      which resumes it from a checkpoint (not from step 0) and finishes it; after SIGCONT the
#      stopped worker's late writes are refused (409) and it stops its solver, and the job's
#      result is the second attempt's.
# Workers are stopped (SIGTERM, drain) between the parts while they wait in a long-poll claim; the
# server must notice that the claimant has gone and not lease it a job, or the job would wait a
# lease period and run as attempt 2 (both checks below would see it).
# Real binaries on 127.0.0.1 with a port chosen at run time; the server's SQLite file is read
# read-only with python3 for the event checks.
#   bash tests/service/workers_test.sh BUILD_DIR
set -u
build=${1:-build}
cd "$(dirname "$0")/../.."
. tests/service/lib.sh
svc_init "$build"
root=$PWD
workers=()
stopped=""
cleanup_workers() {
	[ -n "$stopped" ] && kill -CONT "$stopped" 2>/dev/null
	for w in "${workers[@]}"; do kill -TERM "$w" 2>/dev/null; kill -TERM "$w" 2>/dev/null; done
	for w in "${workers[@]}"; do wait "$w" 2>/dev/null; done
	svc_cleanup
}
trap cleanup_workers EXIT
[ -n "${KEEP_TMP:-}" ] && trap "cp -r \"$SVC_TMP\" /tmp/exp/workers-tmp; cleanup_workers" EXIT

# the workers run a private copy of the solver, so a rebuild of the tree cannot fail a start
cp "$build/poro-solve" "$SVC_TMP/poro-solve"
# Parts f and d run under a 15 s lease: they test fairness and exclusivity, and a lease short enough
# for part c (2 s) would expire on a machine that stalls a live worker for 2 s, which is the lease
# doing its job, not a second live attempt. A leaked lease (a job leased to a claimant that has
# gone) still shows as attempt 2 after 15 s. Part c has its own server with a 2 s lease.
svc_start main --lease-seconds 15
check server_starts $? "no server"
alice=$(svc_token main alice user)
bob=$(svc_token main bob user)
pool=$(svc_token main pool worker)

# case END CHECKPOINT_INTERVAL NAME: a Terzaghi column ending at END s (0.0001 s steps)
make_case() {
	python3 - tests/cases/terzaghi.json "$SVC_TMP/$3.json" "$1" "$2" <<'EOF'
import json, sys
c = json.load(open(sys.argv[1]))
c["time"]["end"] = float(sys.argv[3])
if float(sys.argv[4]) > 0:
    c["checkpoint"] = {"interval": float(sys.argv[4])}
json.dump(c, open(sys.argv[2], "w"))
EOF
}
make_case 0.002 0 tiny
make_case 0.981 0.1 long

start_worker() { # NAME SLOTS: pid in $worker_pid, log in $SVC_TMP/NAME.log
	"$build/poro-worker" --server "$SVC_URL" --token "$pool" --work "$SVC_TMP/work-$1" --slots "$2" \
		--solver "$SVC_TMP/poro-solve" --name "$1" > "$SVC_TMP/$1.log" 2>&1 &
	worker_pid=$!
	workers+=("$worker_pid")
}
submit() { # TOKEN CASE-NAME: prints the job id
	code=$(svc_req POST /v1/jobs "$1" -H 'Content-Type: application/json' \
		--data-binary "{\"case\": $(cat "$SVC_TMP/$2.json")}")
	[ "$code" = 201 ] && json '["id"]' < "$SVC_BODY"
}
job_field() { # ID FIELD (as alice)
	svc_req GET "/v1/jobs/$1" "$alice" > /dev/null && json "[\"$2\"]" < "$SVC_BODY"
}
db() { python3 -c 'import sqlite3, sys; db = sqlite3.connect("file:%s?mode=ro" % sys.argv[1], uri=True); exec(sys.argv[2])' "$SVC_STATE/poro.db" "$1"; }

# ---- f. fair share ------------------------------------------------------------------------------------
"$build/poro-load" submit --server "$SVC_URL" --token "$alice" --case "$SVC_TMP/tiny.json" --clients 8 \
	--count 200 --key-prefix alice > "$SVC_TMP/alice-load.out" 2>&1
grep -q "submissions: 200 ok" "$SVC_TMP/alice-load.out"
check alice_queues_200 $? "$(cat "$SVC_TMP/alice-load.out")"
bob_job=$(submit "$bob" tiny)
start_worker fair 1
fair=$worker_pid
all_done() { [ "$(db 'print(db.execute("SELECT count(*) FROM jobs WHERE state NOT IN (\"succeeded\", \"failed\", \"cancelled\")").fetchone()[0])')" = 0 ]; }
wait_for 120 all_done
check fair_share_queue_drains $? "jobs left: $(db 'print(db.execute("SELECT state, count(*) FROM jobs GROUP BY state").fetchall())')"
position=$(db "
order = [r[0] for r in db.execute(\"SELECT job_id FROM events WHERE to_state = 'running' ORDER BY id\")]
print(order.index($bob_job) + 1 if $bob_job in order else -1)")
echo "INFO fair share: user B's job was claimed as number $position of 201, after 200 of user A's queued jobs"
check fair_share_b_within_one_slot "$([ "$position" -ge 1 ] && [ "$position" -le 2 ]; echo $?)" "claimed as number $position"
kill -TERM "$fair"; wait "$fair"

# ---- d. no job in two live attempts -------------------------------------------------------------------
"$build/poro-load" submit --server "$SVC_URL" --token "$alice" --case "$SVC_TMP/tiny.json" --clients 8 \
	--count 200 --key-prefix many > "$SVC_TMP/many-load.out" 2>&1
for n in 1 2 3; do start_worker "w$n" 2; done
wait_for 180 all_done
check many_jobs_finish $? "jobs left: $(db 'print(db.execute("SELECT state, count(*) FROM jobs GROUP BY state").fetchall())')"
db '
rows = db.execute("SELECT id, state, attempt FROM jobs").fetchall()
bad_end = [r for r in rows if r[1] != "succeeded" or r[2] != 1]
bad_seq = []
for (job_id, state, attempt) in rows:
    seq = [e[0] for e in db.execute("SELECT to_state FROM events WHERE job_id = ? ORDER BY id", (job_id,))]
    if seq != ["queued", "running", "succeeded"]:
        bad_seq.append((job_id, seq))
claims = {}
for w in ("w1", "w2", "w3", "fair"):
    for line in open("'"$SVC_TMP"'/%s.log" % w):
        if ": claimed (" in line and " job " in line:
            job = int(line.split(" job ")[1].split()[0])
            claims.setdefault(job, []).append(w)
twice = {j: ws for j, ws in claims.items() if len(ws) > 1}
print("INFO exclusivity: %d jobs, %d claims logged by the workers, %d jobs claimed twice" % (len(rows), sum(len(v) for v in claims.values()), len(twice)))
print("PASS every_job_succeeded_in_one_attempt" if not bad_end else "FAIL every_job_succeeded_in_one_attempt: %s" % bad_end[:5])
print("PASS events_queued_running_succeeded" if not bad_seq else "FAIL events_queued_running_succeeded: %s" % bad_seq[:3])
print("PASS no_job_claimed_by_two_workers" if not twice else "FAIL no_job_claimed_by_two_workers: %s" % list(twice.items())[:5])
print("PASS every_job_claimed_once" if len(claims) == len(rows) else "FAIL every_job_claimed_once: %d of %d jobs in the workers logs" % (len(claims), len(rows)))
# what a failure needs to be understood: the server events and the workers lines of the jobs concerned
for job_id in sorted(set([r[0] for r in bad_end] + [b[0] for b in bad_seq] + list(twice)))[:3]:
    for e in db.execute("SELECT at, from_state, to_state, attempt, actor, detail FROM events WHERE job_id = ? ORDER BY id", (job_id,)):
        print("INFO job %d event: %s" % (job_id, e))
    for w in ("w1", "w2", "w3", "fair"):
        for line in open("'"$SVC_TMP"'/%s.log" % w):
            if (" job %d " % job_id) in line:
                print("INFO job %d %s: %s" % (job_id, w, line.rstrip()))
'
for n in 1 2 3; do kill -TERM "${workers[-$n]}" 2>/dev/null; done
for n in 1 2 3; do wait "${workers[-$n]}" 2>/dev/null; done

# ---- c. SIGSTOP beyond the lease, then SIGCONT ----------------------------------------------------------
svc_start lease --lease-seconds 2
check lease_server_starts $? "no server"
alice=$(svc_token lease alice user)
pool=$(svc_token lease pool worker)
start_worker sleepy 1
sleepy=$worker_pid
job=$(submit "$alice" long)
checkpointed() { grep -q "job $job attempt 1: checkpoint uploaded" "$SVC_TMP/sleepy.log"; }
wait_for 60 checkpointed
check first_attempt_checkpoints $? "$(tail -3 "$SVC_TMP/sleepy.log")"
kill -STOP "$sleepy"
stopped=$sleepy
start_worker rescuer 1
rescuer=$worker_pid
done_by_rescuer() { [ "$(job_field "$job" state)" = succeeded ]; }
wait_for 90 done_by_rescuer
check job_completes_on_other_worker $? "state $(job_field "$job" state), attempt $(job_field "$job" attempt)"
[ "$(job_field "$job" attempt)" = 2 ] && grep -q "job $job attempt 2" "$SVC_TMP/rescuer.log"
check second_attempt_ran_on_rescuer $? "attempt $(job_field "$job" attempt)"
# the second attempt resumed: its first progress line is past step 0
svc_req GET "/v1/jobs/$job/log?attempt=2" "$alice" > /dev/null
first_step=$(grep -m1 -oE '^step [0-9]+' "$SVC_BODY" | awk '{print $2}')
grep -q "^resumed from .* at step [1-9]" "$SVC_BODY" && [ -n "$first_step" ] && [ "$first_step" -gt 1000 ]
check resumed_from_checkpoint_not_zero $? "first step of attempt 2: '$first_step'; log head: $(head -3 "$SVC_BODY")"
echo "INFO lease takeover: attempt 2 began at step $first_step of 9810"
kill -CONT "$sleepy"
stopped=""
refused() { grep -qE "job $job attempt 1: .*(refused|lease is gone)" "$SVC_TMP/sleepy.log"; }
wait_for 30 refused
check stale_worker_writes_refused $? "$(tail -3 "$SVC_TMP/sleepy.log")"
no_stale_solver() { ! pgrep -f "$SVC_TMP/work-sleepy/job-$job-1" > /dev/null; }
wait_for 10 no_stale_solver
check stale_solver_stopped $? "$(pgrep -af "$SVC_TMP/work-sleepy/job-$job-1")"
svc_req GET "/v1/jobs/$job" "$alice" > /dev/null
python3 -c '
import json, sys
j = json.load(open(sys.argv[1]))
files = {f["name"]: f["attempt"] for f in j.get("files", [])}
ok = j["state"] == "succeeded" and files.get("result.h5") == 2
print("PASS result_is_second_attempts" if ok else "FAIL result_is_second_attempts: state %s, files %s" % (j["state"], files))
' "$SVC_BODY"
