#!/usr/bin/env bash
# limits_test.sh - what one request may cost a real poro-server, and malformed HTTP answered in JSON:
#   - every malformed head gets the API's JSON error (libmicrohttpd alone answers those with HTML);
#   - HEAD is answered on every GET route;
#   - an oversized chunked body is read to its end and answered 413, not reset;
#   - a body with too many values or too deep is refused while it streams, before any tree is
#     built, and the server's peak memory stays within a stated bound while eight clients send
#     4 MiB bodies of every hostile shape at once;
#   - a route's own body limit holds (a heartbeat is not a 4 MiB body);
#   - a token may have only so many requests in progress (429 beyond);
#   - a server whose memory runs out answers 503, stays up and loses nothing it acknowledged.
#   bash tests/service/limits_test.sh BUILD_DIR
set -u
build=${1:-build}
cd "$(dirname "$0")/../.."
. tests/service/lib.sh
svc_init "$build"

SUBMISSIONS=2          # submissions validated at once in the memory check
VALUES=200000          # values a submission's body may hold there
RSS_BOUND_MB=320       # the server's peak resident memory allowed over its start (see below)

svc_start main --max-concurrent-submissions $SUBMISSIONS --max-body-values $VALUES --max-requests-per-token 8 \
	--lease-seconds 300
check limits_server_starts $? "no server"
port=${SVC_URL##*:}
alice=$(svc_token main alice user)
bob=$(svc_token main bob user)
pool=$(svc_token main pool worker)

# ---- malformed HTTP: JSON errors ------------------------------------------------------------------
python3 - "$port" > "$SVC_TMP/raw.txt" <<'EOF'
import json, socket, sys
port = int(sys.argv[1])
cases = [
    ("no_host", b"GET /healthz HTTP/1.1\r\n\r\n", 400, "malformed_request"),
    ("bad_request_line", b"GARBAGE\r\n\r\n", 400, "malformed_request"),
    ("http2", b"GET /healthz HTTP/2.0\r\nHost: x\r\n\r\n", 505, "http_version_not_supported"),
    ("huge_header", b"GET /healthz HTTP/1.1\r\nHost: x\r\nX-Pad: " + b"a" * 20000 + b"\r\n\r\n", 431,
     "header_fields_too_large"),
    ("long_target", b"GET /" + b"a" * 9000 + b" HTTP/1.1\r\nHost: x\r\n\r\n", 414, "uri_too_long"),
    ("bad_content_length", b"POST /v1/jobs HTTP/1.1\r\nHost: x\r\nContent-Length: 1x\r\n\r\n", 400,
     "malformed_request"),
    ("folded_header", b"GET /healthz HTTP/1.1\r\nHost: x\r\nX-A: 1\r\n folded\r\n\r\n", 400, "malformed_request"),
    ("unknown_coding", b"POST /v1/jobs HTTP/1.1\r\nHost: x\r\nTransfer-Encoding: gzip\r\n\r\n", 501,
     "not_implemented"),
    ("nul_in_header", b"GET /healthz HTTP/1.1\r\nHost: x\r\nX-A: a\x00b\r\n\r\n", 400, "malformed_request"),
]
for name, data, want_status, want_code in cases:
    s = socket.create_connection(("127.0.0.1", port))
    s.settimeout(5)
    s.sendall(data)
    got = b""
    try:
        while True:
            more = s.recv(65536)
            if not more:
                break
            got += more
    except OSError:
        pass
    head, _, body = got.partition(b"\r\n\r\n")
    try:
        status = int(head.split(b" ")[1])
        code = json.loads(body)["error"]["code"]
    except Exception:
        status, code = head[:40], "not JSON: " + repr(body[:60])
    ok = status == want_status and code == want_code
    print("%s %s %s %s" % ("ok" if ok else "bad", name, status, code))
EOF
bad=$(grep -c '^bad' "$SVC_TMP/raw.txt")
check limits_malformed_http_answered_in_json "$bad" "$(grep '^bad' "$SVC_TMP/raw.txt" | tr '\n' ';')"

read -r code size <<< "$(curl -s -o /dev/null -D "$SVC_HEADERS" -w '%{http_code} %{size_download}' -I "$SVC_URL/healthz")"
[ "$code" = 200 ] && [ "$size" = 0 ] && [ "$(svc_header Content-Type)" = application/json ]
check limits_head_healthz_200 $? "HEAD /healthz: $code, body $size bytes, $(svc_header Content-Type)"
code=$(curl -s -o /dev/null -w '%{http_code}' -I -H "Authorization: Bearer $alice" "$SVC_URL/v1/jobs")
[ "$code" = 200 ]
check limits_head_on_get_routes $? "HEAD /v1/jobs: $code"

# ---- bodies -----------------------------------------------------------------------------------------
python3 - "$SVC_TMP" <<'EOF'
import json, sys
d = sys.argv[1]
c = json.load(open("tests/cases/terzaghi.json"))
open(d + "/chunked.json", "w").write(" " * (40 << 20))                 # 40 MiB: ten times the limit
json.dump({"case": dict(c, junk=[0] * 1000000)}, open(d + "/numbers.json", "w"))   # a million values, 3 MB
deep = "[" * 3000 + "]" * 3000
open(d + "/deep.json", "w").write('{"case": %s}' % deep)
probes = [{"name": "p%d" % i, "kind": "pore_pressure", "point": [9e9, 0]} for i in range(20000)]
json.dump({"case": dict(c, probes=probes)}, open(d + "/probes.json", "w"))   # 1.5 MB, 180k values
json.dump({"case": c}, open(d + "/ok.json", "w"))
open(d + "/heartbeat.json", "w").write('{"attempt": 1, "progress": {"pad": "%s"}}' % ("x" * (1 << 20)))
EOF
code=$(svc_req POST /v1/jobs "$alice" -H 'Transfer-Encoding: chunked' --data-binary "@$SVC_TMP/chunked.json" --max-time 60)
expect_code() { # NAME STATUS CODE GOT
	[ "$4" = "$2" ] && [ "$(json '["error"]["code"]' < "$SVC_BODY")" = "$3" ]
	check "$1" $? "status $4: $(head -c 300 "$SVC_BODY")"
}
expect_code limits_oversized_chunked_body_413 413 body_too_large "$code"
code=$(svc_req POST /v1/jobs "$alice" --data-binary "@$SVC_TMP/numbers.json")
expect_code limits_too_many_values_413 413 body_too_complex "$code"
json '["error"]["message"]' < "$SVC_BODY" | grep -q "more than $VALUES values"
check limits_too_many_values_names_the_limit $? "$(head -c 300 "$SVC_BODY")"
code=$(svc_req POST /v1/jobs "$alice" --data-binary "@$SVC_TMP/deep.json")
expect_code limits_too_deep_413 413 body_too_complex "$code"
code=$(svc_req POST /v1/jobs "$alice" --data-binary '{"case": {"schema": 1}, }')
expect_code limits_invalid_json_400_line_column 400 invalid_json "$code"
json '["error"]["message"]' < "$SVC_BODY" | grep -q 'line 1 column 25'
check limits_invalid_json_names_position $? "$(head -c 300 "$SVC_BODY")"

# a heartbeat is a small body: 64 KiB at most, whatever --max-body-bytes allows a submission
code=$(svc_req POST /v1/worker/jobs/1/heartbeat "$pool" --data-binary "@$SVC_TMP/heartbeat.json")
expect_code limits_small_route_body_limit_413 413 body_too_large "$code"

# ---- memory: eight clients at once with every hostile shape ---------------------------------------
# The bound: what a submission may cost is its tree (jansson: at most about 0.5 KiB per value, keys
# included, for objects of three keys, the worst shape) and the solver's loader, at most
# --max-concurrent-submissions at once; bodies the pre-scan refuses cost their bytes only while
# they stream. 2 submissions x 200,000 values x ~0.5 KiB is about 200 MB; RSS_BOUND_MB leaves room
# for the bodies in flight and the allocator's slack.
rss() { awk -v k="$1:" '$1 == k {print int($2 / 1024)}' "/proc/$SVC_PID/status"; }
base=$(rss VmRSS)
clients=()
for round in 1 2; do
	for f in numbers deep probes probes probes chunked numbers probes; do
		tok=$alice; [ $((RANDOM % 2)) = 0 ] && tok=$bob
		curl -s -o /dev/null -w '%{http_code}\n' --max-time 120 -H "Authorization: Bearer $tok" \
			--data-binary "@$SVC_TMP/$f.json" "$SVC_URL/v1/jobs" >> "$SVC_TMP/barrage.txt" &
		clients+=($!)
	done
	wait "${clients[@]}"   # not a bare wait: the server is a child of this shell too
	clients=()
done
peak=$(rss VmHWM)
after=$(rss VmRSS)
echo "INFO memory: server RSS $base MB at the start, peak $peak MB under 16 hostile 4 MiB bodies (8 at once), $after MB after; answers $(sort "$SVC_TMP/barrage.txt" | uniq -c | tr -s ' \n' ' ')"
[ $((peak - base)) -lt $RSS_BOUND_MB ]
check limits_peak_memory_bounded $? "peak $peak MB, $((peak - base)) MB over the start (bound $RSS_BOUND_MB MB)"
! grep -qv -e '^413$' -e '^422$' -e '^429$' -e '^503$' "$SVC_TMP/barrage.txt"
check limits_barrage_answered $? "answers: $(sort "$SVC_TMP/barrage.txt" | uniq -c | tr -s ' \n' ' ')"

# ---- per-token requests in progress ---------------------------------------------------------------
# a running job (claimed by hand) whose log ten followers hold open: eight may, the rest get 429
code=$(svc_req POST /v1/jobs "$alice" --data-binary "@$SVC_TMP/ok.json")
job=$(json '["id"]' < "$SVC_BODY")
svc_req POST /v1/worker/claim "$pool" -d '{"worker": "w:1", "wait_seconds": 5}' > /dev/null
for i in $(seq 10); do
	curl -s -o /dev/null -w '%{http_code}\n' --max-time 3 -H "Authorization: Bearer $alice" \
		"$SVC_URL/v1/jobs/$job/log?follow=1" >> "$SVC_TMP/follow.txt" &
	clients+=($!)
done
sleep 1
code=$(svc_req GET "/v1/jobs/$job" "$alice")
busy=$(json '["error"]["code"]' < "$SVC_BODY")
code_bob=$(svc_req GET "/v1/jobs?limit=1" "$bob")
wait "${clients[@]}"
clients=()
held=$(grep -c '^200' "$SVC_TMP/follow.txt")
echo "INFO per token: $held of 10 followers held open, the next request of the same token got $code ($busy)"
[ "$held" = 8 ] && [ "$code" = 429 ] && [ "$busy" = too_many_requests ] && [ "$code_bob" = 200 ]
check limits_requests_per_token $? "$held followers held; alice's next request $code $busy; bob's $code_bob"

# ---- out of memory ---------------------------------------------------------------------------------
# A server whose address space is capped at 200 MB (prlimit --as: malloc then fails, as it never does
# under Linux's overcommit), eight submissions of 3-4 MiB bodies at once beside eight small ones:
# every request is answered (503 when memory ran out, never a reset or a 500), the server stays up,
# a normal submission works afterwards, and every job it acknowledged is there, in an intact database.
svc_stop main
if svc_asan "$build/poro-server"; then
	echo "INFO out of memory not checked: an AddressSanitizer build cannot run under an address space limit"
	exit 0
fi
SVC_WRAP=(prlimit --as=200000000)
svc_start small --max-concurrent-submissions 8 --max-body-values 1000000 --max-requests-per-token 64
started=$?
SVC_WRAP=()
check limits_capped_server_starts $started "no server under the cap"
carol=$(svc_token small carol user)
python3 -c "
import json
c = json.load(open('tests/cases/terzaghi.json'))
json.dump({'case': dict(c, junk=[0.5] * 700000)}, open('$SVC_TMP/floats.json', 'w'))"
for i in $(seq 8); do
	heavy=floats; [ $((i % 2)) = 0 ] && heavy=probes
	curl -s -o "$SVC_TMP/heavy.$i" -w '%{http_code}\n' --max-time 120 -H "Authorization: Bearer $carol" \
		--data-binary "@$SVC_TMP/$heavy.json" "$SVC_URL/v1/jobs" >> "$SVC_TMP/oom.txt" &
	clients+=($!)
	curl -s -o "$SVC_TMP/small.$i" -w '%{http_code}\n' --max-time 120 -H "Authorization: Bearer $carol" \
		--data-binary "@$SVC_TMP/ok.json" "$SVC_URL/v1/jobs" >> "$SVC_TMP/oom.txt" &
	clients+=($!)
done
wait "${clients[@]}"
acknowledged=$(for i in $(seq 8); do json '["id"]' < "$SVC_TMP/small.$i" 2>/dev/null; done | sort -n | tr '\n' ' ')
answers=$(sort "$SVC_TMP/oom.txt" | uniq -c | tr -s ' \n' ' ')
echo "INFO out of memory (200 MB address space): answers $answers; acknowledged jobs: $acknowledged"
for f in "$SVC_TMP"/heavy.[0-9]* "$SVC_TMP"/small.[0-9]*; do
	grep -q '"code":"internal"' "$f" && echo "INFO answered 500: $(head -c 300 "$f")"
	grep -q -e '"id":' -e '"code":"unavailable"' -e '"code":"body_too_' -e '"code":"invalid_case"' \
		-e '"code":"invalid_request"' -e '"code":"too_many_requests"' "$f" ||
		echo "INFO an answer other than 201, 413, 422, 429 or 503: $(head -c 300 "$f")"
done
kill -0 "$SVC_PID" && ! grep -qv -e '^201$' -e '^413$' -e '^422$' -e '^429$' -e '^503$' "$SVC_TMP/oom.txt"
check limits_out_of_memory_answered_503 $? "server alive: $(kill -0 "$SVC_PID" 2>/dev/null && echo yes || echo no); answers $answers"
code=$(svc_req POST /v1/jobs "$carol" --data-binary "@$SVC_TMP/ok.json")
[ "$code" = 201 ]
check limits_out_of_memory_recovers $? "a normal submission after the burst: $code $(head -c 200 "$SVC_BODY")"
svc_req GET "/v1/jobs?limit=100" "$carol" > /dev/null
listed=$(json '["jobs"]' < "$SVC_BODY" | python3 -c "import json, sys; print(' '.join(str(j['id']) for j in json.load(sys.stdin)))")
missing=""
for id in $acknowledged; do [[ " $listed " == *" $id "* ]] || missing="$missing $id"; done
svc_stop small
integrity=$(python3 -c "
import sqlite3, sys
print(sqlite3.connect(sys.argv[1] + '/poro.db').execute('PRAGMA integrity_check').fetchone()[0])" "$SVC_STATE")
[ -z "$missing" ] && [ "$integrity" = ok ]
check limits_out_of_memory_loses_nothing $? "acknowledged but missing:$missing; integrity_check: $integrity"
