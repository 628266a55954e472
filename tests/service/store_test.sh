#!/usr/bin/env bash
# store_test.sh - what the server stores, against real poro-server instances over HTTP:
#   - the log cap: 40 MiB appended to one attempt of a server with --max-log-bytes 4 MiB keeps at
#     most the cap plus one chunk (read from the SQLite file, read-only); a read gives the head, one
#     marker line naming the dropped offsets and the tail, with X-Log-Next-Offset and
#     X-Log-Dropped-Bytes; a chunk at a dropped offset is accepted without change;
#   - `poro logs -f` across the dropped range and a broken stream (a proxy cuts the connection in
#     the tail): the marker once, every tail byte once;
#   - four concurrent readers of a 48 MiB log raise the server's peak RSS (VmHWM) by less than a
#     stated bound: reads are streamed;
#   - listing cost: the SQLite VM steps of a user's listing (poro_job_list_vm_steps_total) are the
#     same among 500 and among 5,000 other jobs, with no full-scan step and no sort, for every
#     listing shape;
#   - the storage quota: a submission past the user's stored bytes is 429 naming the bytes, uploads
#     are never refused, DELETE of a finished job frees its bytes, rows and files, DELETE of a queued
#     or running job is 409, ids of deleted jobs are not reused, `poro rm`;
#   - temporary upload files: a client that disconnects mid-upload leaves none; a server killed with
#     -9 mid-upload leaves one, which the next start removes (and says so in one line).
#   bash tests/service/store_test.sh BUILD_DIR      (from the repository root)
set -u
build=${1:-build}
cd "$(dirname "$0")/../.."
. tests/service/lib.sh
svc_init "$build"
tmp=$SVC_TMP
MIB=1048576
CAP=$((4 * MIB))

python3 -c "import json; json.dump({'case': json.load(open('tests/cases/terzaghi.json'))}, open('$tmp/case.json', 'w'))"
submit() { # TOKEN [curl args...] -> status; body in $SVC_BODY
	local t=$1
	shift
	svc_req POST /v1/jobs "$t" -H 'Content-Type: application/json' --data-binary "@$tmp/case.json" "$@"
}
claim() { # WORKER_TOKEN -> job id of the claimed job (attempt 1 for a fresh job)
	svc_req POST /v1/worker/claim "$1" -d '{"worker": "store-test:1", "wait_seconds": 5}' > /dev/null
	json '["job"]["id"]' < "$SVC_BODY"
}
finish() { # WORKER_TOKEN JOB OUTCOME (a success would need a stored result.h5: the tests end jobs failed)
	svc_req POST "/v1/worker/jobs/$2/finish" "$1" -d "{\"attempt\": 1, \"outcome\": \"$3\"}"
}
metric() { # NAME -> value from /metrics of the current server (admin token in $admin)
	svc_req GET /metrics "$admin" > /dev/null
	awk -v n="$1" '$1 == n { print $2 }' "$SVC_BODY"
}
sql() { # QUERY -> rows of the current server's database, opened read-only
	python3 - "$SVC_STATE/poro.db" "$1" <<'EOF'
import sqlite3, sys
db = sqlite3.connect("file:%s?mode=ro" % sys.argv[1], uri=True)
for row in db.execute(sys.argv[2]):
    print(" ".join(str(v) for v in row))
EOF
}

# appendlog WORKER_TOKEN JOB FROM_OFFSET BYTES TEXTFILE: appends BYTES of numbered 100-byte lines in
# chunks of 2,621 lines (262,100 bytes, whole lines as poro-worker sends them) as the worker, and
# appends the same text to TEXTFILE, the expected log.
cat > "$tmp/append.py" <<'EOF'
import http.client, json, sys, urllib.parse
url, token, job, offset, nbytes, path = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4]), int(sys.argv[5]), sys.argv[6]
u = urllib.parse.urlsplit(url)
conn = http.client.HTTPConnection(u.hostname, u.port, timeout=60)
line = 0 if offset == 0 else offset // 100
out = open(path, "ab")
end = offset + nbytes
while end - offset >= 100:
    n = min(2621, (end - offset) // 100)
    text = "".join(("job %d line %09d " % (job, line + i)).ljust(99, "x") + "\n" for i in range(n))
    assert len(text) == 100 * n
    body = json.dumps({"attempt": 1, "offset": offset, "text": text})
    conn.request("POST", "/v1/worker/jobs/%d/log" % job, body, {"Authorization": "Bearer " + token, "Content-Type": "application/json"})
    r = conn.getresponse()
    answer = r.read()
    if r.status != 200:
        sys.exit("append at %d: %d %s" % (offset, r.status, answer[:300]))
    out.write(text.encode())
    offset += len(text)
    line += n
print(offset)
EOF
appendlog() { python3 "$tmp/append.py" "$SVC_URL" "$1" "$2" "$3" "$4" "$5"; }
size_at_least() { [ "$(wc -c < "$1")" -ge "$2" ]; } # FILE BYTES

# expected TEXTFILE FROM TO END ATTEMPT OUT: the log as a reader from offset 0 sees it: bytes
# [0, FROM), the marker for FROM..TO, bytes [TO, END)
expected() {
	python3 - "$@" <<'EOF'
import sys
text, a, b, end, attempt, out = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4]), sys.argv[5], sys.argv[6]
data = open(text, "rb").read()
marker = ("[poro-server: log bytes %d..%d of attempt %s were dropped: an attempt keeps its first 2 MiB"
          " and last 2 MiB (--max-log-bytes)]\n" % (a, b, attempt)).encode()
open(out, "wb").write(data[:a] + marker + data[b:end])
EOF
}

# serve NAME [poro-server flags...]: starts instance NAME (or stops the test) and makes the tokens
# $admin, $alice (user) and $worker for it
serve() {
	svc_start "$@" || { echo "FAIL start_$1: server did not start"; exit 1; }
	admin=$(svc_token "$1" root admin)
	alice=$(svc_token "$1" alice user)
	worker=$(svc_token "$1" w1 worker)
}

# ---- the log cap ---------------------------------------------------------------------------------
serve cap --max-log-bytes "$CAP" --lease-seconds 300
submit "$alice" > /dev/null
job=$(claim "$worker")
end=$(appendlog "$worker" "$job" 0 $((40 * MIB)) "$tmp/full.log")
read -r stored chunk_max <<< "$(sql "SELECT sum(length(text)), max(length(text)) FROM log_chunks WHERE job_id = $job")"
read -r rec_end from to <<< "$(sql "SELECT end_offset, dropped_from, dropped_to FROM log_attempts WHERE job_id = $job")"
echo "INFO log cap: 40 MiB appended, $stored bytes stored (cap $CAP, largest chunk $chunk_max), dropped $from..$to"
[ "${end:-0}" -eq $((40 * MIB / 100 * 100)) ] && [ "$stored" -le $((CAP + chunk_max)) ] && [ "$stored" -eq $((end - (to - from))) ] &&
	[ "$from" -le $((CAP / 2)) ] && [ $((end - to)) -ge $((CAP / 2)) ] && [ "$rec_end" -eq "$end" ]
check log_cap_stores_at_most_cap_plus_one_chunk $? "appended to ${end:-?}, stored $stored, end $rec_end, dropped $from..$to"

code=$(svc_req GET "/v1/jobs/$job/log" "$alice")
expected "$tmp/full.log" "$from" "$to" "$end" 1 "$tmp/want.log"
cmp -s "$SVC_BODY" "$tmp/want.log"
check log_read_head_marker_tail $? "status $code, $(wc -c < "$SVC_BODY") bytes, wanted $(wc -c < "$tmp/want.log"): $(head -c 200 "$SVC_BODY" | tail -c 100)"
[ "$code" = 200 ] && [ "$(svc_header X-Log-Next-Offset)" = "$end" ] && [ "$(svc_header X-Log-Dropped-Bytes)" = $((to - from)) ] &&
	[ "$(svc_header X-Log-Attempt)" = 1 ]
check log_read_headers $? "X-Log-Next-Offset '$(svc_header X-Log-Next-Offset)' X-Log-Dropped-Bytes '$(svc_header X-Log-Dropped-Bytes)', wanted $end and $((to - from))"

inside=$((from + 5 * MIB + 37))
code=$(svc_req GET "/v1/jobs/$job/log?offset=$inside" "$alice")
python3 - "$tmp/full.log" "$inside" "$to" "$end" "$SVC_BODY" <<'EOF'
import sys
data, a, b, end, got = open(sys.argv[1], "rb").read(), int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4]), open(sys.argv[5], "rb").read()
marker = b"[poro-server: log bytes %d..%d of attempt 1 were dropped: an attempt keeps its first 2 MiB and last 2 MiB (--max-log-bytes)]\n" % (a, b)
sys.exit(0 if got == marker + data[b:end] else 1)
EOF
check log_read_from_dropped_offset_marker_then_tail $? "status $code: $(head -c 200 "$SVC_BODY")"

code=$(svc_req GET "/v1/jobs/$job/log?offset=$((end - 250))" "$alice")
[ "$code" = 200 ] && [ "$(cat "$SVC_BODY")" = "$(tail -c 250 "$tmp/full.log")" ] && [ "$(svc_header X-Log-Next-Offset)" = "$end" ]
check log_read_from_tail_offset $? "status $code: $(head -c 200 "$SVC_BODY")"

code=$(svc_req POST "/v1/worker/jobs/$job/log" "$worker" -d "{\"attempt\": 1, \"offset\": $((from + 262100)), \"text\": \"replayed\\n\"}")
[ "$code" = 200 ] && [ "$(json '["next_offset"]' < "$SVC_BODY")" = "$end" ] &&
	[ "$(sql "SELECT sum(length(text)) FROM log_chunks WHERE job_id = $job")" = "$stored" ]
check log_append_at_dropped_offset_accepted_unchanged $? "status $code: $(cat "$SVC_BODY")"

code=$(svc_req GET "/v1/jobs/$job" "$alice")
[ "$(json '["logs"]' < "$SVC_BODY")" = "[{\"attempt\": 1, \"bytes\": $end, \"dropped_bytes\": $((to - from))}]" ]
check job_shows_log_dropped_bytes $? "logs: $(json '["logs"]' < "$SVC_BODY")"

# ---- poro logs -f across the dropped range and a broken stream ---------------------------------
# The proxy forwards to the server and cuts, once, the first connection that has carried 3 MiB
# to the client: the follower has then seen the head (2 MiB), the marker and part of the tail, and
# must resume in the tail, at the log offset after the marker plus the tail bytes it received.
cat > "$tmp/proxy.py" <<'EOF'
import socket, sys, threading
target = (sys.argv[1], int(sys.argv[2]))
cut_after, portfile = int(sys.argv[3]), sys.argv[4]
cut = threading.Event()
lsock = socket.socket()
lsock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
lsock.bind(("127.0.0.1", 0))
lsock.listen(16)
open(portfile, "w").write(str(lsock.getsockname()[1]))
def pump(src, dst, count):
    total = 0
    try:
        while True:
            data = src.recv(65536)
            if not data:
                break
            if count and not cut.is_set() and total + len(data) >= cut_after:
                cut.set()
                dst.sendall(data[:cut_after - total])
                break
            total += len(data)
            dst.sendall(data)
    except OSError:
        pass
    for s in (src, dst):
        try:
            s.shutdown(socket.SHUT_RDWR)
        except OSError:
            pass
def serve(client):
    server = socket.create_connection(target)
    threading.Thread(target=pump, args=(client, server, False), daemon=True).start()
    pump(server, client, True)
while True:
    c, _ = lsock.accept()
    threading.Thread(target=serve, args=(c,), daemon=True).start()
EOF
port=${SVC_URL##*:}
python3 "$tmp/proxy.py" 127.0.0.1 "$port" $((3 * MIB)) "$tmp/proxy.port" &
proxy=$!
wait_for 10 test -s "$tmp/proxy.port"
submit "$alice" > /dev/null
job2=$(claim "$worker")
end2=$(appendlog "$worker" "$job2" 0 $((20 * MIB)) "$tmp/full2.log")
read -r from2 to2 <<< "$(sql "SELECT dropped_from, dropped_to FROM log_attempts WHERE job_id = $job2")"
PORO_SERVER="http://127.0.0.1:$(cat "$tmp/proxy.port")" PORO_TOKEN=$alice "$build/poro" logs -f "$job2" > "$tmp/follow.out" 2> "$tmp/follow.err" &
follower=$!
expected "$tmp/full2.log" "$from2" "$to2" "$end2" 1 "$tmp/want2.log"
wait_for 60 size_at_least "$tmp/follow.out" "$(wc -c < "$tmp/want2.log")"
# once the follower has everything so far, more lines (the tail moves on) and the end of the job
end3=$(appendlog "$worker" "$job2" "$end2" $((MIB / 2)) "$tmp/full2.log")
finish "$worker" "$job2" failed > /dev/null
wait_for 30 eval "! kill -0 $follower 2>/dev/null"
wait "$follower" 2>/dev/null
status=$?
kill "$proxy" 2>/dev/null
wait "$proxy" 2>/dev/null
expected "$tmp/full2.log" "$from2" "$to2" "$end3" 1 "$tmp/want3.log"
markers=$(grep -c '^\[poro-server: log bytes' "$tmp/follow.out")
# the job ended failed, so the follower exits 7 (poro --help, "Exit status")
[ "$status" = 7 ] && cmp -s "$tmp/follow.out" "$tmp/want3.log" && [ "$markers" = 1 ]
check logs_follow_marker_once_and_whole_tail_across_broken_stream $? "exit $status, $markers markers, $(wc -c < "$tmp/follow.out") bytes, wanted $(wc -c < "$tmp/want3.log"); $(cmp "$tmp/follow.out" "$tmp/want3.log" 2>&1 | head -1); $(head -c 300 "$tmp/follow.err")"
svc_stop cap

# ---- four concurrent readers of a big log --------------------------------------------------------
READERS_BOUND_MIB=32   # four streamed readers: one 256 KiB block and a read connection each
# under AddressSanitizer (make test SAN=1) freed memory waits in a quarantine of 256 MiB, which
# counts as the server's; 16 MiB keeps the measure about the server (other builds ignore this)
saved_asan=${ASAN_OPTIONS-}
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}quarantine_size_mb=16"
serve big --max-log-bytes $((256 * MIB)) --lease-seconds 300
export ASAN_OPTIONS=$saved_asan
submit "$alice" > /dev/null
job=$(claim "$worker")
end=$(appendlog "$worker" "$job" 0 $((48 * MIB)) "$tmp/big.log")
# the peak is measured from here: clear_refs 5 resets VmHWM to the current RSS where the kernel
# allows it; otherwise the rise of VmHWM itself is taken
vm() { awk -v k="$1:" '$1 == k { print $2 }' "/proc/$SVC_PID/status"; }
if echo 5 2> /dev/null > "/proc/$SVC_PID/clear_refs"; then base=$(vm VmRSS); else base=$(vm VmHWM); fi
readers=()
for i in 1 2 3 4; do
	curl -s --limit-rate 16M -H "Authorization: Bearer $alice" -o "$tmp/reader$i.log" "$SVC_URL/v1/jobs/$job/log" &
	readers+=($!)
done
wait "${readers[@]}"
peak=$(vm VmHWM)
rise=$(((peak - base) / 1024))
echo "INFO four concurrent readers of a log of $end bytes: server VmHWM rose by $rise MiB (from $((base / 1024)) MiB; bound $READERS_BOUND_MIB MiB)"
ok=0
for i in 1 2 3 4; do cmp -s "$tmp/reader$i.log" "$tmp/big.log" || ok=1; done
check log_readers_get_whole_log $ok "sizes: $(wc -c "$tmp"/reader*.log | tr '\n' ' ')"
[ "$rise" -lt "$READERS_BOUND_MIB" ]
check log_four_readers_bounded_memory $? "VmHWM rose by $rise MiB, bound $READERS_BOUND_MIB MiB"
svc_stop big

# ---- listing cost does not grow with the table ---------------------------------------------------
serve list --user-max-queued 100000
small=$(svc_token list small user)
bulk=$(svc_token list bulk user)
load() { # TOKEN COUNT PREFIX
	"$build/poro-load" submit --server "$SVC_URL" --token "$1" --case tests/cases/terzaghi.json --clients 8 --count "$2" \
		--key-prefix "$3" > /dev/null
}
load "$small" 10 small
for i in 1 2 3; do # some of the small user's jobs end, so state filters have something to find
	id=$(claim "$worker")
	finish "$worker" "$id" failed > /dev/null
done
load "$bulk" 500 bulk-a
smallest=$(sql "SELECT min(id) FROM jobs WHERE user_id = (SELECT id FROM users WHERE name = 'small')")
listings() { # prints "name steps fullscan sorts" for each listing shape
	local name tok q s0 f0 o0
	while read -r name tok q; do
		s0=$(metric poro_job_list_vm_steps_total)
		f0=$(metric poro_job_list_fullscan_steps_total)
		o0=$(metric poro_job_list_sorts_total)
		svc_req GET "/v1/jobs?$q" "${!tok}" > /dev/null
		echo "$name $(($(metric poro_job_list_vm_steps_total) - s0)) $(($(metric poro_job_list_fullscan_steps_total) - f0)) $(($(metric poro_job_list_sorts_total) - o0))"
	done <<EOF
user_all small limit=100
user_states small state=queued,failed&limit=100
user_after small after=$((smallest + 5))&limit=100
admin_first admin limit=20
admin_states admin state=failed,cancelled&limit=20
EOF
}
listings > "$tmp/steps500"
load "$bulk" 4500 bulk-b
listings > "$tmp/steps5000"
echo "INFO listing VM steps among 500 / 5,000 other jobs: $(paste -d' ' "$tmp/steps500" "$tmp/steps5000" | awk '{printf "%s %s/%s; ", $1, $2, $6}')"
python3 - "$tmp/steps500" "$tmp/steps5000" <<'EOF'
import sys
a = [l.split() for l in open(sys.argv[1])]
b = [l.split() for l in open(sys.argv[2])]
bad = [(x[0], x[1:], y[1:]) for x, y in zip(a, b)
       if int(x[1]) <= 0 or abs(int(x[1]) - int(y[1])) > 8 or x[2:] != ["0", "0"] or y[2:] != ["0", "0"]]
if bad:
    print("; ".join("%s: %s then %s (steps, fullscan, sorts)" % t for t in bad))
sys.exit(1 if bad or len(a) != 5 or len(b) != 5 else 0)
EOF
check listing_steps_do_not_grow_with_table $? "$(paste -d' ' "$tmp/steps500" "$tmp/steps5000")"
code=$(svc_req GET "/v1/jobs?limit=3" "$small")
[ "$(json '["jobs"]' < "$SVC_BODY" | python3 -c 'import json,sys; print([j["user"] for j in json.load(sys.stdin)])')" = "['small', 'small', 'small']" ] &&
	[ -n "$(json '["next_after"]' < "$SVC_BODY")" ]
check listing_user_sees_own_newest_first $? "$(head -c 300 "$SVC_BODY")"
code=$(svc_req GET "/v1/jobs?state=failed,queued&limit=1000" "$small")
python3 - "$SVC_BODY" <<'EOF'
import json, sys
jobs = json.load(open(sys.argv[1]))["jobs"]
ids = [j["id"] for j in jobs]
states = sorted(j["state"] for j in jobs)
sys.exit(0 if ids == sorted(ids, reverse=True) and states == ["failed"] * 3 + ["queued"] * 7 else 1)
EOF
check listing_state_filter_merged_newest_first $? "$(head -c 300 "$SVC_BODY")"
svc_req GET /metrics "$admin" > /dev/null
grep -q '^poro_jobs{state="queued"} 5007$' "$SVC_BODY" && grep -q '^poro_jobs{state="failed"} 3$' "$SVC_BODY"
check metrics_job_counts_from_counters $? "$(grep '^poro_jobs' "$SVC_BODY" | tr '\n' ' ')"
svc_stop list

# ---- storage quota and deletion ------------------------------------------------------------------
svc_start probe || { echo "FAIL start_probe: server did not start"; exit 1; }
submit "$(svc_token probe p user)" > /dev/null
C=$(sql "SELECT length(CAST(case_json AS BLOB)) FROM jobs")
svc_stop probe
# two jobs with 4,000 bytes of log and files fit, a third case does not; with the first job
# deleted (and 2,000 bytes of files on the second) two cases fit again
QUOTA=$((2 * C + 4000 + C / 2))
serve quota --user-max-stored-bytes "$QUOTA" --lease-seconds 300
bob=$(svc_token quota bob user)
submit "$alice" -H 'Idempotency-Key: q-1' > /dev/null
j1=$(json '["id"]' < "$SVC_BODY")
[ "$(claim "$worker")" = "$j1" ]
python3 -c "print('x' * 2999)" > "$tmp/log3000"
svc_req POST "/v1/worker/jobs/$j1/log" "$worker" -d "{\"attempt\": 1, \"offset\": 0, \"text\": \"$(cat "$tmp/log3000")\\n\"}" > /dev/null
head -c 1000 /dev/urandom > "$tmp/f1000"
upload() { # JOB FILE NAME -> status
	svc_req PUT "/v1/worker/jobs/$1/files/$3?attempt=1" "$worker" -H "X-Checksum-Sha256: $(sha256sum "$2" | cut -d' ' -f1)" \
		--data-binary "@$2"
}
upload "$j1" "$tmp/f1000" result.xdmf > /dev/null
finish "$worker" "$j1" failed > /dev/null
code=$(svc_req GET "/v1/jobs/$j1" "$alice")
[ "$(json '["stored_bytes"]' < "$SVC_BODY")" = $((C + 4000)) ]
check job_stored_bytes_case_log_files $? "stored_bytes $(json '["stored_bytes"]' < "$SVC_BODY"), wanted $((C + 4000))"
submit "$alice" > /dev/null
j2=$(json '["id"]' < "$SVC_BODY")
jobs_before=$(sql "SELECT count(*) FROM jobs")
code=$(submit "$alice")
msg=$(json '["error"]["message"]' < "$SVC_BODY")
[ "$code" = 429 ] && [ "$(json '["error"]["code"]' < "$SVC_BODY")" = quota_exceeded ] &&
	[[ "$msg" == *"stores $((2 * C + 4000)) bytes"* && "$msg" == *"case of $C bytes"* && "$msg" == *"quota of $QUOTA bytes"* ]] &&
	[ "$(sql "SELECT count(*) FROM jobs")" = "$jobs_before" ]
check quota_submit_429_names_bytes $? "status $code: $(cat "$SVC_BODY")"
[ "$(claim "$worker")" = "$j2" ]
head -c 2000 /dev/urandom > "$tmp/f2000"
code=$(upload "$j2" "$tmp/f2000" checkpoint.h5)
[ "$code" = 201 ]
check quota_never_refuses_uploads $? "status $code: $(cat "$SVC_BODY")"
code=$(svc_req DELETE "/v1/jobs/$j2" "$alice")
[ "$code" = 409 ] && [ "$(json '["error"]["code"]' < "$SVC_BODY")" = not_deletable ]
check delete_running_409 $? "status $code: $(cat "$SVC_BODY")"
code=$(svc_req DELETE "/v1/jobs/$j1" "$bob")
[ "$code" = 404 ]
check delete_other_users_job_404 $? "status $code: $(cat "$SVC_BODY")"
[ -d "$SVC_STATE/files/$j1" ]
had_files=$?
code=$(svc_req DELETE "/v1/jobs/$j1" "$alice")
[ "$code" = 200 ] && [ "$(json '["freed_bytes"]' < "$SVC_BODY")" = $((C + 4000)) ] && [ "$(json '["files"]' < "$SVC_BODY")" = 1 ] &&
	[ "$(json '["log_chunks"]' < "$SVC_BODY")" = 1 ] && [ "$(json '["idempotency_keys"]' < "$SVC_BODY")" = 1 ] &&
	[ "$(json '["events"]' < "$SVC_BODY")" -ge 3 ]
check delete_finished_200_says_what_was_freed $? "status $code: $(cat "$SVC_BODY")"
left=$(sql "SELECT (SELECT count(*) FROM jobs WHERE id = $j1) + (SELECT count(*) FROM events WHERE job_id = $j1)
	+ (SELECT count(*) FROM log_chunks WHERE job_id = $j1) + (SELECT count(*) FROM log_attempts WHERE job_id = $j1)
	+ (SELECT count(*) FROM files WHERE job_id = $j1) + (SELECT count(*) FROM idempotency WHERE job_id = $j1)")
[ "$had_files" = 0 ] && [ ! -e "$SVC_STATE/files/$j1" ] && [ "$left" = 0 ] && [ "$(svc_req GET "/v1/jobs/$j1" "$alice")" = 404 ]
check delete_removes_rows_and_files $? "had files $had_files, $left rows left, files dir: $(ls "$SVC_STATE/files")"
code=$(submit "$alice" -H 'Idempotency-Key: q-1')
j3=$(json '["id"]' < "$SVC_BODY")
[ "$code" = 201 ] && [ "$j3" -gt "$j2" ]
check quota_after_delete_submission_passes $? "status $code: $(cat "$SVC_BODY")"
code=$(svc_req DELETE "/v1/jobs/$j3" "$alice")
[ "$code" = 409 ]
check delete_queued_409 $? "status $code: $(cat "$SVC_BODY")"
svc_req POST "/v1/jobs/$j3/cancel" "$alice" > /dev/null
PORO_SERVER=$SVC_URL PORO_TOKEN=$alice "$build/poro" rm "$j3" > "$tmp/rm.out" 2>&1
status=$?
[ "$status" = 0 ] && grep -q "^job $j3 removed: $C bytes freed" "$tmp/rm.out" && [ "$(svc_req DELETE "/v1/jobs/$j3" "$alice")" = 404 ]
check poro_rm_deletes_finished_job $? "exit $status: $(cat "$tmp/rm.out")"
gone=$(svc_req GET "/v1/jobs/$j3" "$admin")
submit "$alice" > /dev/null
[ "$gone" = 404 ] && [ "$(json '["id"]' < "$SVC_BODY")" -gt "$j3" ]
check deleted_job_id_not_reused $? "GET of deleted job $j3: $gone; new id $(json '["id"]' < "$SVC_BODY")"
code=$(svc_req POST /v1/users "$admin" -d "{\"name\": \"carol\", \"max_stored_bytes\": $((C + 10))}")
[ "$code" = 201 ] && [ "$(json '["max_stored_bytes"]' < "$SVC_BODY")" = $((C + 10)) ]
check users_create_max_stored_bytes $? "status $code: $(cat "$SVC_BODY")"
svc_req POST /v1/tokens "$admin" -d '{"user": "carol"}' > /dev/null
carol=$(json '["token"]' < "$SVC_BODY")
first=$(submit "$carol")
second=$(submit "$carol")
[ "$first" = 201 ] && [ "$second" = 429 ] && [[ "$(json '["error"]["message"]' < "$SVC_BODY")" == *"quota of $((C + 10)) bytes"* ]]
check quota_per_user_override $? "statuses $first $second: $(cat "$SVC_BODY")"
bad=$(sql "SELECT u.name FROM users u WHERE u.stored_bytes != coalesce((SELECT sum(j.stored_bytes) FROM jobs j WHERE j.user_id = u.id), 0)
	UNION ALL SELECT 'job ' || j.id FROM jobs j WHERE j.stored_bytes != length(CAST(j.case_json AS BLOB))
	+ coalesce((SELECT sum(length(l.text)) FROM log_chunks l WHERE l.job_id = j.id), 0)
	+ coalesce((SELECT sum(f.size) FROM files f WHERE f.job_id = j.id), 0)" 2>&1) || bad="the query failed: $bad"
[ -z "$bad" ]
check stored_bytes_counters_match_contents $? "mismatch: $bad"

svc_stop quota

# ---- temporary files of interrupted uploads ------------------------------------------------------
serve tmpfiles --lease-seconds 300
head -c $((8 * MIB)) /dev/urandom > "$tmp/big.bin"
sha=$(sha256sum "$tmp/big.bin" | cut -d' ' -f1)
submit "$alice" > /dev/null
j4=$(claim "$worker")
slow_upload() {
	curl -s --limit-rate 256K -X PUT -H "Authorization: Bearer $worker" -H "X-Checksum-Sha256: $sha" \
		--data-binary "@$tmp/big.bin" "$SVC_URL/v1/worker/jobs/$j4/files/result.h5?attempt=1" > /dev/null &
	uploader=$!
}
tmpfiles() { find "$SVC_STATE/files" -name '.tmp-*' | wc -l; }
no_tmpfiles() { [ "$(tmpfiles)" -eq 0 ]; }
tmpfile_growing() { [ "$(find "$SVC_STATE/files" -name '.tmp-*' -size +100k | wc -l)" -ge 1 ]; }
slow_upload
wait_for 20 tmpfile_growing
kill -9 "$uploader"
wait "$uploader" 2> /dev/null
wait_for 20 no_tmpfiles
check upload_client_disconnect_leaves_no_tmp $? "$(find "$SVC_STATE/files" -name '.tmp-*')"
slow_upload
wait_for 20 tmpfile_growing
kill -9 "$SVC_PID"
wait "$SVC_PID" 2> /dev/null
unset "SVC_PIDS[tmpfiles]"
kill "$uploader" 2> /dev/null
wait "$uploader" 2> /dev/null
left=$(tmpfiles)
bytes=$(find "$SVC_STATE/files" -name '.tmp-*' -printf '%s\n' | awk '{s += $1} END {print s + 0}')
# what a deletion interrupted between its commit and the removal of the files would leave
mkdir -p "$SVC_STATE/files/999999/1" && echo orphan > "$SVC_STATE/files/999999/1/result.h5"
svc_start tmpfiles --lease-seconds 300 || { echo "FAIL restart_tmpfiles: server did not start"; exit 1; }
grep -q "removed temporary upload files: 1 ($bytes bytes); directories of deleted jobs: 1 (7 bytes)" "$tmp/tmpfiles.err"
swept=$?
[ "$left" = 1 ] && no_tmpfiles && [ "$swept" = 0 ] && [ ! -e "$SVC_STATE/files/999999" ] && [ -d "$SVC_STATE/files/$j4/1" ]
check start_up_sweep_removes_tmp_after_kill9 $? "before restart $left temporary files ($bytes bytes), after $(tmpfiles); $(grep sweep "$tmp/tmpfiles.err")"
echo "INFO $(grep 'start-up sweep' "$tmp/tmpfiles.err")"
svc_stop tmpfiles
