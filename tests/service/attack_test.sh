#!/usr/bin/env bash
# attack_test.sh - the service under connection exhaustion, with a real poro-server, poro-worker and
# poro-solve on 127.0.0.1: while 600 silent sockets (from 127.0.0.2), 600 slowloris sockets sending
# a request head a byte at a time (127.0.0.3) and 200 keep-alive connections left idle after one
# request (127.0.0.4) are held open, a user on 127.0.0.1 must still be answered within its usual
# latency, and a worker must still claim and finish a job: the queue keeps moving. Each hostile
# connection must be refused at once beyond the per-client limit (429 too_many_connections) or cut
# at the header deadline (408 request_timeout), always with the API's JSON error; a JSON body sent a
# byte a second is cut at the body deadline. Then the users' connections are exhausted outright,
# by idle keep-alive connections from several addresses: users get 503 at once (JSON), and a worker
# started only then still claims and finishes a queued job, since workers' connections have their
# own budget. Every 127.0.0.0/8 address reaches the loopback interface, so each attacker has an
# address of its own without privileges.
#   bash tests/service/attack_test.sh BUILD_DIR
set -u
build=${1:-build}
cd "$(dirname "$0")/../.."
. tests/service/lib.sh
svc_init "$build"
worker=""
trap '[ -n "$worker" ] && kill -TERM "$worker" 2>/dev/null && wait "$worker"; svc_cleanup' EXIT

HEADER_TIMEOUT=3
BODY_TIMEOUT=4
PER_CLIENT=32
HOLD=14                 # seconds the attackers keep their sockets
PROBES=40               # user requests during the attack

svc_start main --header-timeout-seconds $HEADER_TIMEOUT --body-timeout-seconds $BODY_TIMEOUT \
	--max-connections-per-client $PER_CLIENT --lease-seconds 10
check attack_server_starts $? "no server"
port=${SVC_URL##*:}
alice=$(svc_token main alice user)
pool=$(svc_token main pool worker)
cp "$build/poro-solve" "$SVC_TMP/poro-solve"
"$build/poro-worker" --server "$SVC_URL" --token "$pool" --work "$SVC_TMP/work" --solver "$SVC_TMP/poro-solve" \
	--name attacked > "$SVC_TMP/worker.log" 2>&1 &
worker=$!
python3 -c "
import json
c = json.load(open('tests/cases/terzaghi.json'))
c['time']['end'] = 0.02
json.dump({'case': c}, open('$SVC_TMP/job.json', 'w'))"

# probe N OUT: N user requests (GET /v1/jobs) one after another, each given 5 s; prints one line per
# request, "STATUS SECONDS" (status 000 when no answer came)
probe() {
	local i
	for i in $(seq "$1"); do
		curl -s -o /dev/null --max-time 5 -H "Authorization: Bearer $alice" -w '%{http_code} %{time_total}\n' \
			"$SVC_URL/v1/jobs?limit=5"
	done > "$2"
}
percentiles() { # FILE: "p50 P p99 Q" of the seconds of the answered requests, in ms
	python3 -c "
import sys
t = sorted(float(l.split()[1]) * 1e3 for l in open(sys.argv[1]) if l.split()[0] == '200')
q = lambda f: t[min(len(t) - 1, int(f * len(t)))] if t else float('nan')
print('p50 %.1f ms, p99 %.1f ms' % (q(0.5), q(0.99)))" "$1"
}
answered() { grep -c '^200 ' "$1"; }

probe 20 "$SVC_TMP/before.txt"
before=$(percentiles "$SVC_TMP/before.txt")

# ---- the attack ------------------------------------------------------------------------------------
python3 tests/service/sockets.py idle "$port" --from 127.0.0.2 --count 600 --hold $HOLD \
	--ready "$SVC_TMP/idle.ready" > "$SVC_TMP/idle.json" 2> "$SVC_TMP/idle.err" &
idle_pid=$!
wait_for 10 test -s "$SVC_TMP/idle.ready"   # the silent sockets first: they take what they can
python3 tests/service/sockets.py slow "$port" --from 127.0.0.3 --count 600 --hold $HOLD --interval 0.5 \
	--ready "$SVC_TMP/slow.ready" > "$SVC_TMP/slow.json" 2> "$SVC_TMP/slow.err" &
slow_pid=$!
python3 tests/service/sockets.py keepalive "$port" --from 127.0.0.4 --count 200 --hold $HOLD \
	--ready "$SVC_TMP/keep.ready" > "$SVC_TMP/keep.json" 2> "$SVC_TMP/keep.err" &
keep_pid=$!
python3 tests/service/sockets.py slowbody "$port" --from 127.0.0.5 --token "$alice" --hold $HOLD \
	> "$SVC_TMP/body.json" 2> "$SVC_TMP/body.err" &
body_pid=$!
wait_for 10 test -s "$SVC_TMP/slow.ready"
wait_for 10 test -s "$SVC_TMP/keep.ready"

code=$(svc_req POST /v1/jobs "$alice" -H 'Content-Type: application/json' --max-time 10 \
	--data-binary "@$SVC_TMP/job.json")
id=$(json '["id"]' < "$SVC_BODY")
probe $PROBES "$SVC_TMP/during.txt"
during=$(percentiles "$SVC_TMP/during.txt")
job_state() { svc_req GET "/v1/jobs/$id" "$alice" --max-time 5 > /dev/null && json '["state"]' < "$SVC_BODY"; }
succeeded() { [ "$(job_state)" = succeeded ]; }
wait_for 60 succeeded
moved=$?
wait "$idle_pid" "$slow_pid" "$keep_pid" "$body_pid"

echo "INFO attack: user requests before $before; during $during ($(answered "$SVC_TMP/during.txt") of $PROBES answered)"
for f in idle slow keep body; do echo "INFO attack $f: $(python3 -c "
import json, sys
r = json.load(open(sys.argv[1]))
t = r['close_seconds']
print('%d opened, %d closed by the server (last after %.1f s), %d still open; answers %s'
      % (r['opened'], r['closed_by_server'], t[-1] if t else 0, r['still_open'], r['answers']))" "$SVC_TMP/$f.json")"; done

[ "$code" = 201 ] && [ "$(answered "$SVC_TMP/during.txt")" = $PROBES ]
check attack_users_still_answered $? "submission $code; $(answered "$SVC_TMP/during.txt") of $PROBES requests answered"
slowest=$(python3 -c "
import sys
lines = [l.split() for l in open(sys.argv[1])]
print('%s s%s' % (max(float(t) for _, t in lines), '' if all(c == '200' for c, _ in lines) else ' (some unanswered)'))" \
	"$SVC_TMP/during.txt")
case $slowest in 0.*|1.*) [[ $slowest != *unanswered* ]] ;; *) false ;; esac
check attack_users_answered_within_2s $? "slowest user request: $slowest"
[ "$moved" = 0 ]
check attack_queue_keeps_moving $? "job $id is $(job_state) after the attack: a worker could not claim or finish it"

# every hostile connection was cut: at once (429) or at its deadline (408), never left to hold a thread
verdict() { # FILE MODE: checks of one attacker's report
	python3 - "$1" "$2" "$HEADER_TIMEOUT" "$PER_CLIENT" "$BODY_TIMEOUT" <<'EOF'
import json, sys
r = json.load(open(sys.argv[1]))
mode, timeout, per_client, body_timeout = sys.argv[2], float(sys.argv[3]), int(sys.argv[4]), float(sys.argv[5])
problems = []
if r["still_open"]:
    problems.append("%d connections still open after the attack" % r["still_open"])
if r["non_json_answers"]:
    problems.append("%d answers were not the API's JSON error" % r["non_json_answers"])
late = [t for t in r["close_seconds"] if t > (body_timeout if mode == "body" else timeout) + 2.5]
if late:
    problems.append("%d connections cut only after %.1f s" % (len(late), max(late)))
if mode in ("idle", "slow"):
    refused = r["answers"].get("429 too_many_connections", 0)
    timed_out = r["answers"].get("408 request_timeout", 0)
    if refused + timed_out != r["opened"] or timed_out > per_client:
        problems.append("answers %s: expected %d x 408 and the rest 429" % (r["answers"], per_client))
print("; ".join(problems))
sys.exit(1 if problems else 0)
EOF
}
why=$(verdict "$SVC_TMP/idle.json" idle)
check attack_silent_sockets_cut $? "$why"
why=$(verdict "$SVC_TMP/slow.json" slow)
check attack_slowloris_cut_at_header_deadline $? "$why"
why=$(verdict "$SVC_TMP/keep.json" keep)
check attack_idle_keepalive_cut $? "$why"
why=$(verdict "$SVC_TMP/body.json" body)
check attack_slow_body_cut_at_body_deadline $? "$why"

# after the attack the server is as it was
code=$(svc_req GET /healthz "" --max-time 5)
[ "$code" = 200 ] && kill -0 "$SVC_PID" 2>/dev/null
check attack_server_healthy_after $? "healthz $code"

# ---- the users' connections exhausted: the workers' are apart -----------------------------------
kill -TERM "$worker" 2>/dev/null && wait "$worker"
worker=""
svc_start apart --header-timeout-seconds 30 --max-connections 64 --max-connections-per-client 32 --lease-seconds 10
port=${SVC_URL##*:}
bob=$(svc_token apart bob user)
pool=$(svc_token apart pool worker)
code=$(svc_req POST /v1/jobs "$bob" -H 'Content-Type: application/json' --data-binary "@$SVC_TMP/job.json")
id=$(json '["id"]' < "$SVC_BODY")
python3 tests/service/sockets.py keepalive "$port" --from 127.0.1.1,127.0.1.2,127.0.1.3 --count 96 --hold 12 \
	--ready "$SVC_TMP/full.ready" > "$SVC_TMP/full.json" 2> "$SVC_TMP/full.err" &
full_pid=$!
wait_for 10 test -s "$SVC_TMP/full.ready"
full=$(svc_req GET /v1/jobs "$bob" --max-time 5)
full_code=$(json '["error"]["code"]' < "$SVC_BODY")
"$build/poro-worker" --server "$SVC_URL" --token "$pool" --work "$SVC_TMP/work2" --solver "$SVC_TMP/poro-solve" \
	--name apart > "$SVC_TMP/worker2.log" 2>&1 &
worker=$!
ended() { # the job's state, read straight from the database (users cannot get in)
	python3 -c "
import sqlite3, sys
db = sqlite3.connect('file:' + sys.argv[1] + '/poro.db?mode=ro', uri=True)
print(db.execute('SELECT state FROM jobs WHERE id = ?', (int(sys.argv[2]),)).fetchone()[0])" "$SVC_STATE" "$id"
}
job_done() { [ "$(ended)" = succeeded ]; }
wait_for 30 job_done
done_status=$?
state=$(ended)
wait "$full_pid"
echo "INFO attack on the users' budget: a user got $full ($full_code) while 64 idle connections held it; the job was $state"
[ "$code" = 201 ] && [ "$full" = 503 ] && [ "$full_code" = unavailable ]
check attack_user_budget_full_answered_503 $? "submission $code; with the users' connections taken a user got $full $full_code"
[ "$done_status" = 0 ]
check attack_workers_apart_from_users $? "job $id is $state: the worker could not claim and finish it"
