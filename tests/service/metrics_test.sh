#!/usr/bin/env bash
# metrics_test.sh - poro_worker_heartbeat_age_seconds is labelled per worker, not per token user
# (docs/service.md §4): two real poro-worker processes share one worker token (one token file, as
# a pool of workers on one host would), each runs a job and heartbeats; /metrics then holds one
# series per worker, labelled with the worker's own id ("host:pid", what each sends in its claims
# and heartbeats) and the token's user, and none labelled with the user alone (what a heartbeat
# without the worker's id falls back to). Jobs are cancelled once both workers have heartbeated;
# nothing here waits on a clock but for the state it needs.
#   bash tests/service/metrics_test.sh BUILD_DIR      (from the repository root)
set -u
build=${1:-build}
cd "$(dirname "$0")/../.."
. tests/service/lib.sh
svc_init "$build"
tmp=$SVC_TMP
pids=()
stop_workers() {
	for p in "${pids[@]}"; do kill -TERM "$p" 2>/dev/null; kill -TERM "$p" 2>/dev/null; done
	for p in "${pids[@]}"; do wait "$p" 2>/dev/null; done
	pids=()
}
trap 'stop_workers; svc_cleanup' EXIT

cp "$build/poro-solve" "$tmp/poro-solve"
python3 - tests/cases/terzaghi.json "$tmp/long.json" <<'EOF'
import json, sys
c = json.load(open(sys.argv[1]))
c["time"]["end"] = 0.981   # thousands of steps: running while the heartbeats are counted
json.dump({"case": c}, open(sys.argv[2], "w"))
EOF

svc_start main --lease-seconds 30 || { echo "FAIL start_main: server did not start"; exit 1; }
alice=$(svc_token main alice user)
admin=$(svc_token main root admin)
(umask 077 && svc_token main pool worker > "$tmp/pool.token")

for n in a b; do
	"$build/poro-worker" --server "$SVC_URL" --token-file "$tmp/pool.token" --work "$tmp/work-$n" \
		--solver "$tmp/poro-solve" --lease-renew 1 > "$tmp/worker-$n.log" 2>&1 &
	pids+=($!)
done
host=$(hostname)
jobs=()
for n in 1 2; do
	code=$(svc_req POST /v1/jobs "$alice" -H 'Content-Type: application/json' --data-binary "@$tmp/long.json")
	jobs+=("$(json '["id"]' < "$SVC_BODY")")
done
running() { # both jobs running (a worker has one slot: each on a worker of its own)
	local j
	for j in "${jobs[@]}"; do
		svc_req GET "/v1/jobs/$j" "$alice" > /dev/null && [ "$(json '["state"]' < "$SVC_BODY")" = running ] || return 1
	done
}
wait_for 60 running
check both_jobs_running $? "jobs ${jobs[*]}: $(tail -2 "$tmp/worker-a.log") / $(tail -2 "$tmp/worker-b.log")"
# every worker sends a heartbeat a second: at least four answered heartbeats means both have
heartbeats() { [ "$(grep -c 'route=/v1/worker/jobs/{id}/heartbeat status=200 .*user=pool' "$tmp/main.err")" -ge 4 ]; }
wait_for 60 heartbeats
check both_workers_heartbeat $? "$(grep -c 'route=/v1/worker/jobs/{id}/heartbeat' "$tmp/main.err") heartbeats"

code=$(svc_req GET /metrics "$admin")
grep '^poro_worker_heartbeat_age_seconds{' "$SVC_BODY" > "$tmp/series.txt"
want=$(printf 'poro_worker_heartbeat_age_seconds{worker="%s:%s",user="pool"}\n' "$host" "${pids[0]}" "$host" "${pids[1]}" | sort)
got=$(sed 's/} .*/}/' "$tmp/series.txt" | sort)
[ "$code" = 200 ] && [ "$got" = "$want" ]
check heartbeat_series_per_worker_sharing_a_token $? "status $code; got:
$got
wanted:
$want"
! grep -q 'worker="pool"' "$tmp/series.txt"
check no_series_of_the_token_user_alone $? "$(cat "$tmp/series.txt")"
python3 - "$tmp/series.txt" <<'PY'
import sys
ages = [float(l.split()[-1]) for l in open(sys.argv[1])]
sys.exit(0 if ages and all(a >= 0 for a in ages) else 1)
PY
check heartbeat_ages_are_numbers $? "$(cat "$tmp/series.txt")"
echo "INFO heartbeat series of two workers sharing one token: $(tr '\n' ' ' < "$tmp/series.txt")"

for j in "${jobs[@]}"; do svc_req POST "/v1/jobs/$j/cancel" "$alice" > /dev/null; done
stop_workers
