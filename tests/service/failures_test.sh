#!/usr/bin/env bash
# failures_test.sh - how jobs fail, with a real poro-server, poro-worker and poro-solve:
#   - a solver failure (a case that passes validation but blows up: a soil too soft for its load,
#     E = 1e5 Pa under q = 10 kPa; a dt far above the soil's stable step is refused by validation
#     since solver/stable_dt.c) is final: state failed after one attempt, never retried, with the
#     solver's own message (which point, where, why) kept on the job;
#   - a job over its wall-time limit is stopped by the worker and fails with a message saying so,
#     its solver gone, not retried;
#   - a job that needs more memory than the worker's --memory-limit-mb fails, final, saying so;
#   - every job records the solver version, the SHA-256 of its case and the worker's host.
#   bash tests/service/failures_test.sh BUILD_DIR
set -u
build=${1:-build}
cd "$(dirname "$0")/../.."
. tests/service/lib.sh
svc_init "$build"
worker=""
trap '[ -n "$worker" ] && kill -TERM "$worker" 2>/dev/null && wait "$worker"; svc_cleanup' EXIT

cp "$build/poro-solve" "$SVC_TMP/poro-solve"
svc_start main --lease-seconds 3
check server_starts $? "no server"
alice=$(svc_token main alice user)
pool=$(svc_token main pool worker)
"$build/poro-worker" --server "$SVC_URL" --token "$pool" --work "$SVC_TMP/work" --solver "$SVC_TMP/poro-solve" \
	--name w > "$SVC_TMP/w.log" 2>&1 &
worker=$!

python3 - tests/cases/terzaghi.json "$SVC_TMP" <<'EOF'
import json, sys
c = json.load(open(sys.argv[1]))
blow = dict(c, materials=[dict(c["materials"][0], youngs_modulus=1e5)], time={"dt": 1e-3, "end": 20.0})
json.dump({"case": blow}, open(sys.argv[2] + "/blow.json", "w"))
json.dump({"case": c, "wall_time_seconds": 3, "threads": 2}, open(sys.argv[2] + "/slow.json", "w"))
huge = dict(c, grid=dict(c["grid"], extent=[100.0, 100.0]))   # 16 million nodes
json.dump({"case": huge}, open(sys.argv[2] + "/huge.json", "w"))
EOF
submit() { # BODY-FILE: prints the job id
	code=$(svc_req POST /v1/jobs "$alice" -H 'Content-Type: application/json' --data-binary "@$SVC_TMP/$1")
	[ "$code" = 201 ] && json '["id"]' < "$SVC_BODY"
}
field() { svc_req GET "/v1/jobs/$1" "$alice" > /dev/null && json "[\"$2\"]" < "$SVC_BODY"; }
ended() { case $(field "$1" state) in succeeded|failed|cancelled) return 0 ;; esac; return 1; }

# ---- a solver failure is final, with its message --------------------------------------------------
id=$(submit blow.json)
wait_for 60 ended "$id"
check solver_failure_ends $? "state $(field "$id" state)"
state=$(field "$id" state) attempt=$(field "$id" attempt) message=$(field "$id" message)
[ "$state" = failed ] && [ "$attempt" = 1 ]
check solver_failure_is_final "$?" "state $state after $attempt attempts"
echo "$message" | grep -q "soil point [0-9]* at (.*) m: .*porosity outside (0, 1)"
check solver_failure_message_kept $? "message: $message"
sleep 4   # more than a lease and a backoff: a retry would have shown by now
[ "$(field "$id" state)" = failed ] && [ "$(field "$id" attempt)" = 1 ]
check solver_failure_not_retried $? "state $(field "$id" state), attempt $(field "$id" attempt)"

# ---- the wall-time limit ----------------------------------------------------------------------------
id=$(submit slow.json)
# while it runs: the solver's environment carries the job's thread count, and threads that sleep
# between parallel regions (worker/child.c)
started() { grep -q "job $id attempt 1: solver started" "$SVC_TMP/w.log"; }
wait_for 30 started
pid=$(sed -n "s/.*job $id attempt 1: solver started (pid \([0-9]*\).*/\1/p" "$SVC_TMP/w.log")
# the log line comes between fork and exec: until the exec, /proc shows the worker's own
# environment, so read again until the solver's appears. The limit is 3 s so that on a busy machine
# the solver is still there to be read (with 1 s it was at times gone)
solver_env=""
read_solver_env() {
	solver_env=$(tr '\0' '\n' < "/proc/$pid/environ" 2>/dev/null | grep '^OMP_' | sort | tr '\n' ' ')
	[ -n "$solver_env" ]
}
wait_for 1 read_solver_env
[ "$solver_env" = "OMP_NUM_THREADS=2 OMP_WAIT_POLICY=passive " ]
check solver_environment_threads_and_wait_policy $? "solver pid '$pid' environment: '$solver_env'"
wait_for 30 ended "$id"
check wall_time_job_ends $? "state $(field "$id" state) after 30 s"
state=$(field "$id" state) message=$(field "$id" message)
[ "$state" = failed ] && echo "$message" | grep -q "wall time limit of 3 s exceeded"
check wall_time_limit_fails_job $? "state $state, message: $message"
pid=$(sed -n "s/.*job $id attempt 1: solver started (pid \([0-9]*\).*/\1/p" "$SVC_TMP/w.log")
[ -n "$pid" ] && ! kill -0 "$pid" 2>/dev/null
check wall_time_solver_gone $? "solver pid '$pid' still running"
[ "$(field "$id" attempt)" = 1 ]
check wall_time_not_retried $? "attempt $(field "$id" attempt)"

# ---- provenance: solver version, case hash, worker host ----------------------------------------------
svc_req GET "/v1/jobs/$id" "$alice" > /dev/null
python3 - "$SVC_BODY" "$("$SVC_TMP/poro-solve" version | head -1)" <<'EOF'
import json, socket, sys
job = json.load(open(sys.argv[1]))
ok = job.get("solver_version") and job["solver_version"] in sys.argv[2]
print("PASS job_records_solver_version" if ok else "FAIL job_records_solver_version: %r vs %r" % (job.get("solver_version"), sys.argv[2]))
ok = job.get("worker_host") == socket.gethostname()
print("PASS job_records_worker_host" if ok else "FAIL job_records_worker_host: %r" % job.get("worker_host"))
ok = isinstance(job.get("case_sha256"), str) and len(job["case_sha256"]) == 64
print("PASS job_records_case_sha256" if ok else "FAIL job_records_case_sha256: %r" % job.get("case_sha256"))
EOF

# ---- the memory limit --------------------------------------------------------------------------------
kill -TERM "$worker" && wait "$worker"
worker=""
if svc_asan "$build/poro-solve"; then
	echo "INFO memory limit not checked: an AddressSanitizer build cannot run under an address space limit"
	exit 0
fi
"$build/poro-worker" --server "$SVC_URL" --token "$pool" --work "$SVC_TMP/work2" --solver "$SVC_TMP/poro-solve" \
	--name small --memory-limit-mb 300 > "$SVC_TMP/small.log" 2>&1 &
worker=$!
id=$(submit huge.json)
wait_for 60 ended "$id"
state=$(field "$id" state) message=$(field "$id" message) attempt=$(field "$id" attempt)
[ "$state" = failed ] && [ "$attempt" = 1 ] && echo "$message" | grep -q "out of memory within the worker's limit of 300 MB: .*cannot allocate"
check memory_limit_fails_job_final $? "state $state after $attempt attempts, message: $message"
