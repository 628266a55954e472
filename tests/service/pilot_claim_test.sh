#!/usr/bin/env bash
# pilot_claim_test.sh - what a worker with a limited allocation may take (docs/slurm.md §2), over
# HTTP against a real poro-server and real poro-worker processes:
#   - a claim with seconds_left gets only jobs whose wall_time_seconds fit, or that asked for
#     none; a job asking for more stays queued until a claim with enough time comes;
#   - a claim with max_threads gets only jobs asking for at most that many threads;
#   - seconds_left is checked like every member (a negative one is 422 naming /seconds_left);
#   - a worker whose --lifetime is nearly over does not take a job that asks for more, then claims
#     nothing more and exits, saying why; one with
#     --idle-exit exits after that long without a job;
#   - poro-worker refuses a --lifetime not beyond its --retire-margin.
#   bash tests/service/pilot_claim_test.sh BUILD_DIR      (from the repository root)
set -u
build=${1:-build}
cd "$(dirname "$0")/../.."
. tests/service/lib.sh
svc_init "$build"
tmp=$SVC_TMP

svc_start main
user=$(svc_token main alice user)
worker=$(svc_token main pilot worker)
(umask 077 && echo "$worker" > "$tmp/worker.token")
python3 - tests/cases/terzaghi.json "$tmp" <<'PY'
import json, sys
c = json.load(open(sys.argv[1]))
c["time"]["end"] = 0.002
json.dump({"case": c, "wall_time_seconds": 600}, open(sys.argv[2] + "/long.json", "w"))
json.dump({"case": c, "wall_time_seconds": 250}, open(sys.argv[2] + "/fits.json", "w"))
json.dump({"case": c}, open(sys.argv[2] + "/any.json", "w"))
PY
submit() { svc_req POST /v1/jobs "$user" -H 'Content-Type: application/json' --data-binary "@$tmp/$1.json" > /dev/null; json '["id"]' < "$SVC_BODY"; }
claim() { # SECONDS_LEFT -> the claimed job's id, or the status
	local code
	code=$(svc_req POST /v1/worker/claim "$worker" -d "{\"worker\": \"t:1\", \"seconds_left\": $1}")
	[ "$code" = 200 ] && json '["job"]["id"]' < "$SVC_BODY" || echo "$code"
}
long=$(submit long)
fits=$(submit fits)
any=$(submit any)
got1=$(claim 300)
got2=$(claim 300)
got3=$(claim 300)
check claim_takes_only_jobs_that_fit "$([ "$got1" = "$fits" ] && [ "$got2" = "$any" ] && [ "$got3" = 204 ]; echo $?)" \
	"with 300 s left: got '$got1', '$got2', '$got3'; jobs: 600 s $long, 250 s $fits, none $any"
got4=$(claim 600)
check long_job_goes_to_a_claim_with_time "$([ "$got4" = "$long" ]; echo $?)" "with 600 s left got '$got4'"
python3 -c "import json; d = json.load(open('$tmp/any.json')); d['threads'] = 4; json.dump(d, open('$tmp/wide.json', 'w'))"
wide=$(submit wide)
narrow=$(svc_req POST /v1/worker/claim "$worker" -d '{"worker": "t:1", "seconds_left": 300, "max_threads": 2}')
wide_claim=$(svc_req POST /v1/worker/claim "$worker" -d '{"worker": "t:1", "seconds_left": 300, "max_threads": 4}' > /dev/null; json '["job"]["id"]' < "$SVC_BODY")
check claim_takes_only_jobs_within_its_threads "$([ "$narrow" = 204 ] && [ "$wide_claim" = "$wide" ]; echo $?)" \
	"a 4-thread job: claim with 2 threads answered $narrow, with 4 got '$wide_claim'"
code=$(svc_req POST /v1/worker/claim "$worker" -d '{"worker": "t:1", "seconds_left": -5}')
field=$(json '["error"]["field"]' < "$SVC_BODY")
check negative_seconds_left_refused "$([ "$code" = 422 ] && [ "$field" = /seconds_left ]; echo $?)" "answered $code on '$field'"

# a worker near the end of its lifetime, with a job that asks for more than it has, and an idle one
submit long > /dev/null
"$build/poro-worker" --server "$SVC_URL" --token-file "$tmp/worker.token" --work "$tmp/w1" --lifetime 3 --retire-margin 2 \
	--name ending:1 > "$tmp/ending.log" 2>&1 &
pid=$!
wait_for 20 bash -c "! kill -0 $pid"
gone=$?
wait "$pid"
status=$?
check ending_worker_exits_without_claiming "$([ "$gone" = 0 ] && [ "$status" = 0 ] && grep -q "the allocation ends in .* claiming no more" "$tmp/ending.log" && ! grep -q "worker=ending:1" "$tmp/main.err"; echo $?)" \
	"exit $status: $(tail -3 "$tmp/ending.log")"
start=$(date +%s)
"$build/poro-worker" --server "$SVC_URL" --token-file "$tmp/worker.token" --work "$tmp/w2" --idle-exit 2 \
	--name idle:1 > "$tmp/idle.log" 2>&1
status=$?
took=$(( $(date +%s) - start ))
check idle_worker_exits "$([ "$status" = 0 ] && grep -q "no job for 2 s: ending (--idle-exit)" "$tmp/idle.log" && [ "$took" -lt 30 ]; echo $?)" \
	"exit $status after $took s: $(tail -3 "$tmp/idle.log")"
"$build/poro-worker" --server "$SVC_URL" --token-file "$tmp/worker.token" --lifetime 30 --retire-margin 60 > /dev/null 2> "$tmp/bad.err"
status=$?
check lifetime_within_margin_refused "$([ "$status" = 2 ] && grep -q "must be longer than --retire-margin" "$tmp/bad.err"; echo $?)" \
	"exit $status: $(cat "$tmp/bad.err")"
svc_summary
