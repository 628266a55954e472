#!/usr/bin/env bash
# log_test.sh - the server's log (docs/service.md §8): one logfmt line per request and per job
# state change, through one gateway, read back from a real poro-server's stderr.
#
# Requests: a few requests of users, a worker and no one (answered 200, 201, 401, 404) each leave a
# line msg=request with their method, route pattern (never the raw path: "-" when no route
# matched), status, duration_ms and user; a token sent in a query string or as a path is in no
# line, and no line holds a '?'. State changes: a job submitted, claimed (by worker id "w-one"),
# finished as failed with a reason holding quotes, '=' and a backslash, and another cancelled while
# queued, each leave msg=job_state with job, from, to, attempt, worker and reason, in that order of
# events; a finish the server refuses (a success without its files, rolled back) leaves none.
# The journal: with JOURNAL_STREAM naming stderr's device and inode (as systemd sets it), lines
# start with "<6>" (info) or another sd-daemon(3) prefix and carry no time=; without it, or when it
# names another file, they start with time=. --access-log gets the request lines alone.
#   bash tests/service/log_test.sh BUILD_DIR      (from the repository root)
set -u
build=${1:-build}
cd "$(dirname "$0")/../.."
. tests/service/lib.sh
svc_init "$build"
tmp=$SVC_TMP

python3 -c 'import json; json.dump({"case": json.load(open("tests/cases/terzaghi.json"))}, open("'"$tmp"'/case.json", "w"))'

# lines FILE [key=value ...]: prints, as JSON, the logfmt lines of FILE (a leading "<N>" priority
# is kept as "prio"; quoted values unescaped) whose fields hold every key=value given
lines() {
	python3 - "$@" <<'PY'
import json, re, sys
pair = re.compile(r'([A-Za-z_]+)=("(?:[^"\\]|\\.)*"|\S*)')
def unquote(v):
    return json.loads(v) if v.startswith('"') else v
want = dict(a.split("=", 1) for a in sys.argv[2:])
out = []
for raw in open(sys.argv[1], errors="replace"):
    raw = raw.rstrip("\n")
    m = re.match(r"<([0-7])>", raw)
    f = {k: unquote(v) for k, v in pair.findall(raw[m.end():] if m else raw)}
    if m:
        f["prio"] = m.group(1)
    if all(f.get(k) == v for k, v in want.items()):
        out.append(f)
print(json.dumps(out))
PY
}
count() { lines "$@" | python3 -c 'import json, sys; print(len(json.load(sys.stdin)))'; }
has_line() { [ "$(count "$@")" -ge 1 ]; }

svc_start main --access-log "$tmp/access.log" --lease-seconds 300 || { echo "FAIL start_main: server did not start"; exit 1; }
err=$tmp/main.err
alice=$(svc_token main alice user)
worker=$(svc_token main pool worker)

# ---- requests -----------------------------------------------------------------------------------
c1=$(svc_req GET "/v1/jobs?limit=5" "$alice")
c2=$(svc_req GET /v1/jobs "")
c3=$(svc_req GET "/v1/jobs?token=$alice" "$alice")
c4=$(svc_req GET "/$alice" "")
c5=$(svc_req POST /v1/jobs "$alice" -H 'Content-Type: application/json' --data-binary "@$tmp/case.json")
job=$(json '["id"]' < "$SVC_BODY")
c6=$(svc_req GET /metrics "$worker")
[ "$c1 $c2 $c3 $c4 $c5 $c6" = "200 401 200 404 201 200" ]
check requests_answered $? "statuses $c1 $c2 $c3 $c4 $c5 $c6"
# a request's line is written when it ends, just after its answer: wait for the last one's
wait_for 10 has_line "$err" msg=request route=/metrics
check request_lines_written $? "no request line in $(tail -3 "$err")"

request_line() { # NAME METHOD ROUTE STATUS USER: one such line with a duration
	local got
	got=$(lines "$err" msg=request method="$2" route="$3" status="$4" user="$5")
	echo "$got" | python3 -c '
import json, sys
ls = json.load(sys.stdin)
sys.exit(0 if ls and all(float(l["duration_ms"]) >= 0 and "client" in l for l in ls) else 1)'
	check "request_line_$1" $? "no line method=$2 route=$3 status=$4 user=$5 duration_ms=N: $(grep -m3 'msg=request' "$err")"
}
request_line get_jobs GET /v1/jobs 200 alice
request_line unauthorized GET /v1/jobs 401 -
request_line no_route GET - 404 -
request_line submit POST /v1/jobs 201 alice
request_line metrics_by_worker GET /metrics 200 pool
[ "$(count "$err" msg=request method=GET route=/v1/jobs status=200 user=alice)" -eq 2 ]
check request_line_per_request $? "$(count "$err" msg=request method=GET route=/v1/jobs status=200 user=alice) lines for 2 requests"
! grep -qF -e "$alice" -e "$worker" "$err" "$tmp/access.log" "$tmp/main.out"
check no_token_in_log $? "a token is in the log (line $(grep -nF -e "$alice" -e "$worker" "$err" | cut -d: -f1 | head -3 | tr '\n' ' '))"
! grep 'msg=request' "$err" | grep -q '?'
check no_query_string_in_log $? "$(grep 'msg=request' "$err" | grep -m1 '?')"
python3 - "$err" <<'PY'
import re, sys
bad = [l for l in open(sys.argv[1]) if not re.match(r'^time=\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\.\d{3}Z level=(error|warning|notice|info) msg=', l)]
sys.exit(1 if bad else 0)
PY
check every_line_logfmt_with_time $? "$(grep -vm2 '^time=[^ ]* level=[a-z]* msg=' "$err")"

# ---- job state changes ----------------------------------------------------------------------------
has_line "$err" msg=job_state job="$job" to=queued attempt=0 actor=alice reason=submitted &&
	[ "$(lines "$err" msg=job_state job="$job" to=queued | python3 -c 'import json,sys; print("from" in json.load(sys.stdin)[0])')" = False ]
check state_line_submitted $? "$(grep -m3 'msg=job_state' "$err")"
code=$(svc_req POST /v1/worker/claim "$worker" -d '{"worker": "w-one", "host": "hostA", "wait_seconds": 5}')
[ "$code" = 200 ] && [ "$(json '["job"]["id"]' < "$SVC_BODY")" = "$job" ]
check claim_200 $? "status $code: $(head -c 200 "$SVC_BODY")"
has_line "$err" msg=job_state job="$job" from=queued to=running attempt=1 worker=w-one actor=w-one \
	reason="claimed on host 'hostA'"
check state_line_claimed $? "$(grep 'msg=job_state' "$err")"

# a success without its files is refused and rolled back: no line for it
code=$(svc_req POST "/v1/worker/jobs/$job/finish" "$worker" -d '{"attempt": 1, "outcome": "succeeded"}')
[ "$code" = 409 ] && [ "$(count "$err" msg=job_state job="$job" to=succeeded)" -eq 0 ]
check refused_finish_no_state_line $? "status $code: $(grep "job=$job .*to=succeeded" "$err")"
reason='solver failed: "NaN" at x=2.385 \ step 12'
python3 -c 'import json, sys; print(json.dumps({"attempt": 1, "outcome": "failed", "message": sys.argv[1], "exit_code": 3}))' \
	"$reason" > "$tmp/finish.json"
code=$(svc_req POST "/v1/worker/jobs/$job/finish" "$worker" --data-binary "@$tmp/finish.json")
[ "$code" = 200 ]
check finish_failed_200 $? "status $code: $(head -c 200 "$SVC_BODY")"
lines "$err" msg=job_state job="$job" from=running to=failed attempt=1 worker=w-one > "$tmp/failed.json"
python3 - "$tmp/failed.json" "$reason" <<'PY'
import json, sys
ls = json.load(open(sys.argv[1]))
sys.exit(0 if len(ls) == 1 and ls[0]["reason"] == sys.argv[2] else 1)
PY
check state_line_failed_with_reason $? "$(grep "job=$job .*to=failed" "$err")"
[ "$(grep -c "msg=job_state job=$job " "$err")" -eq 3 ] && [ "$(grep 'to=failed' "$err" | wc -l)" -eq 1 ]
check state_line_one_per_line $? "$(grep "msg=job_state job=$job " "$err")"

svc_req POST /v1/jobs "$alice" -H 'Content-Type: application/json' --data-binary "@$tmp/case.json" > /dev/null
job2=$(json '["id"]' < "$SVC_BODY")
code=$(svc_req POST "/v1/jobs/$job2/cancel" "$alice")
[ "$code" = 200 ] && has_line "$err" msg=job_state job="$job2" from=queued to=cancelled attempt=0 actor=alice &&
	[ "$(lines "$err" msg=job_state job="$job2" to=cancelled | python3 -c 'import json,sys; print("worker" in json.load(sys.stdin)[0])')" = False ]
check state_line_cancelled_no_worker $? "status $code: $(grep "job=$job2 " "$err")"
# a reason longer than a line (4096 bytes) is cut with "..." on a whole UTF-8 character, and the
# line stays one parseable line
svc_req POST /v1/jobs "$alice" -H 'Content-Type: application/json' --data-binary "@$tmp/case.json" > /dev/null
job3=$(json '["id"]' < "$SVC_BODY")
svc_req POST /v1/worker/claim "$worker" -d '{"worker": "w-one", "wait_seconds": 5}' > /dev/null
python3 -c 'import json; print(json.dumps({"attempt": 1, "outcome": "failed", "message": "\u03ba" * 4000}, ensure_ascii=False))' > "$tmp/long.json"
code=$(svc_req POST "/v1/worker/jobs/$job3/finish" "$worker" --data-binary "@$tmp/long.json")
grep "msg=job_state job=$job3 .*to=failed" "$err" > "$tmp/long.line"
python3 - "$tmp/long.line" <<'PY'
import sys
raw = open(sys.argv[1], "rb").read()
line = raw.decode("utf-8")  # fails on a cut UTF-8 sequence
body = line.split(" ", 1)[1]  # after time=
sys.exit(0 if line.count("\n") == 1 and len(body.encode()) <= 4097 and body.rstrip("\n").endswith('κ..."') else 1)
PY
check state_line_long_reason_cut_on_utf8 $? "status $code: $(head -c 100 "$tmp/long.line") ... $(tail -c 100 "$tmp/long.line")"

# the order: the lines of job 1 in the order of its events
order=$(lines "$err" msg=job_state job="$job" | python3 -c 'import json,sys; print(" ".join(l["to"] for l in json.load(sys.stdin)))')
[ "$order" = "queued running failed" ]
check state_lines_in_event_order $? "order '$order'"

# ---- --access-log: request lines alone, with their time ------------------------------------------
wait_for 10 has_line "$tmp/access.log" msg=request route=/v1/jobs/{id}/cancel
[ "$(grep -c . "$tmp/access.log")" -eq "$(grep -c 'msg=request' "$err")" ] && ! grep -q 'msg=job_state' "$tmp/access.log" &&
	! grep -qv '^time=' "$tmp/access.log"
check access_log_request_lines_only $? "$(grep -c . "$tmp/access.log") lines, $(grep -c 'msg=request' "$err") on stderr"

# ---- the journal's priority prefix ----------------------------------------------------------------
svc_stop main
check sigterm_exit_0 "$SVC_STATUS" "exit $SVC_STATUS"
has_line "$err" level=notice msg="stopped on signal 15 (Terminated)"
check stop_line_notice $? "$(tail -2 "$err")"
# nothing here went wrong: no warning or error, libmicrohttpd's own messages included (they come
# through the same gateway; one about the order of its options went to its own logger once)
! grep -qE 'level=(warning|error)' "$err"
check no_warning_in_a_clean_run $? "$(grep -m3 -E 'level=(warning|error)' "$err")"

# JOURNAL_STREAM is "DEVICE:INODE" of stderr; the file exists before the server starts
journal_start() { # NAME JOURNAL_STREAM-VALUE-OR-"self"
	local name=$1 value=$2 state="$tmp/$1"
	mkdir -p "$state"
	: > "$tmp/$name.err"
	[ "$value" = self ] && value=$(stat -c '%d:%i' "$tmp/$name.err")
	JOURNAL_STREAM=$value "$build/poro-server" --listen 127.0.0.1:0 --state "$state" > "$tmp/$name.out" 2>> "$tmp/$name.err" &
	SVC_PIDS[$name]=$!
	SVC_STATES[$name]=$state
	wait_for 10 test -s "$state/server.url" && SVC_URLS[$name]=$(cat "$state/server.url") && svc_use "$name"
}
journal_start journal self
check journal_server_starts $? "$(cat "$tmp/journal.err")"
svc_req GET /v1/jobs "" > /dev/null
svc_req GET /nothing "" > /dev/null
wait_for 10 has_line "$tmp/journal.err" msg=request status=404
svc_stop journal
has_line "$tmp/journal.err" prio=6 level=info msg=request method=GET route=/v1/jobs status=401 &&
	has_line "$tmp/journal.err" prio=5 level=notice msg="stopped on signal 15 (Terminated)" &&
	! grep -qv '^<[0-7]>level=' "$tmp/journal.err"
check journal_lines_have_priority_prefix_no_time $? "$(head -3 "$tmp/journal.err")"
other=$(stat -c '%d:%i' "$tmp/journal.out")
journal_start other "$other"
check other_server_starts $? "$(cat "$tmp/other.err")"
svc_stop other
! grep -q '^<' "$tmp/other.err" && grep -q '^time=' "$tmp/other.err"
check journal_stream_of_another_file_plain $? "$(head -2 "$tmp/other.err")"
