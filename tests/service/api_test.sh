#!/usr/bin/env bash
# api_test.sh - drives a real poro-server over HTTP with curl: every route of schemas/openapi.yaml,
# the worker protocol (claim, heartbeat, log, upload with right and wrong checksum, download with
# Range, finish), fair share, idempotent submission, lease expiry and stale attempts, cancel, and
# every kind of bad input, checking the status, the error code and field, and that nothing stored
# changed. Two servers run: "main" (300 s leases) and "short" (1 s leases, for expiry). Prints one
# line per check, "PASS name" or "FAIL name: why". Runs in about 15 s.
#   bash tests/service/api_test.sh BUILD_DIR      (from the repository root)
set -u
build=${1:-build}
cd "$(dirname "$0")/../.."
. tests/service/lib.sh
svc_init "$build"
tmp=$SVC_TMP

# The submission body: tests/cases/terzaghi.json as "case", with optional python edits of b.
body() { # FILE [PYTHON]
	python3 - "$1" "${2:-}" <<'PYEOF'
import json, sys
b = {"case": json.load(open("tests/cases/terzaghi.json"))}
exec(sys.argv[2])
json.dump(b, open(sys.argv[1], "w"))
PYEOF
}
body "$tmp/case.json"
bodyfile=$tmp/case.json

# the main server's leases outlast any pause a loaded machine makes between a claim and its
# finish (at 30 s, with a solver run beside the suite, they lapsed mid-test); expiry itself is
# tested on the short server below
svc_start main --max-body-bytes 262144 --lease-seconds 300 || { echo "FAIL start_main: server did not start"; exit 1; }
grep -q "^poro-server listening on http://127.0.0.1:[0-9]*$" "$tmp/main.out"
check start_prints_listening_url $? "stdout: $(cat "$tmp/main.out")"
admin=$(svc_token main root admin)
alice=$(svc_token main alice user)
bob=$(svc_token main bob user)
worker=$(svc_token main w1 worker)
[ ${#alice} -eq 48 ] && [ "$(svc_token main alice user | wc -l)" -eq 1 ]
check token_create_prints_only_token $? "got '$alice'"

submit() { # TOKEN FILE [curl args...] -> status; body in $SVC_BODY
	local t=$1 f=$2
	shift 2
	svc_req POST /v1/jobs "$t" -H 'Content-Type: application/json' --data-binary "@$f" "$@"
}
snapshot() { # the whole visible state of alice and the admin view, for before/after comparisons
	svc_req GET "/v1/jobs?limit=1000" "$admin" > /dev/null
	cat "$SVC_BODY"
	for i in $(json '["jobs"]' < "$SVC_BODY" | python3 -c 'import json,sys; print(" ".join(str(j["id"]) for j in json.load(sys.stdin)))'); do
		svc_req GET "/v1/jobs/$i" "$admin" > /dev/null
		cat "$SVC_BODY"
	done
}
expect_error() { # NAME WANT_STATUS WANT_CODE WANT_FIELD STATUS
	local name=$1 status=$2 code=$3 field=$4 got=$5 gcode gfield
	gcode=$(json '["error"]["code"]' < "$SVC_BODY")
	gfield=$(json '["error"]["field"]' < "$SVC_BODY")
	[ -z "$field" ] && field=null
	[ "$got" = "$status" ] && [ "$gcode" = "$code" ] && { [ "$field" = "*" ] || [ "$gfield" = "$field" ]; }
	check "$name" $? "status $got code '$gcode' field '$gfield', wanted $status $code '$field': $(head -c 300 "$SVC_BODY")"
}

# ---- operators -----------------------------------------------------------------------------------
code=$(svc_req GET /healthz "")
[ "$code" = 200 ] && [ "$(json '["status"]' < "$SVC_BODY")" = ok ] && [ "$(json '["database"]' < "$SVC_BODY")" = ok ]
check healthz_ok_without_token $? "status $code: $(cat "$SVC_BODY")"

code=$(svc_req POST /v1/users "$admin" -d '{"name": "carol", "role": "user", "max_queued": 2, "max_running": 1}')
[ "$code" = 201 ] && [ "$(json '["max_queued"]' < "$SVC_BODY")" = 2 ]
check users_create_201 $? "status $code: $(cat "$SVC_BODY")"
code=$(svc_req POST /v1/users "$admin" -d '{"name": "carol"}')
expect_error users_create_duplicate_409 409 already_exists /name "$code"
code=$(svc_req POST /v1/users "$alice" -d '{"name": "eve"}')
expect_error users_create_by_user_403 403 forbidden Authorization "$code"
code=$(svc_req POST /v1/tokens "$admin" -d '{"user": "carol"}')
carol=$(json '["token"]' < "$SVC_BODY")
[ "$code" = 201 ] && [ "$(svc_req GET /v1/jobs "$carol")" = 200 ]
check tokens_create_201_and_token_works $? "status $code: $(cat "$SVC_BODY")"
code=$(svc_req POST /v1/tokens "$admin" -d '{"user": "nobody"}')
expect_error tokens_create_unknown_user_422 422 invalid_request /user "$code"

# ---- submit, idempotency, quota ------------------------------------------------------------------
code=$(submit "$alice" "$bodyfile" -H 'Idempotency-Key: k-2.385')
id1=$(json '["id"]' < "$SVC_BODY")
# case_sha256 oracle: jansson's JSON_COMPACT | JSON_SORT_KEYS encoding (reals as %.17g, ".0" added
# to integral reals, exponent without "+" and leading zeros), hashed with python's hashlib
sha=$(python3 - <<'PYEOF'
import hashlib, json, re
def real(x):
    t = "%.17g" % x
    if not re.search(r"[.e]", t):
        t += ".0"
    return re.sub(r"e([-+]?)0*(\d)", lambda m: "e" + m.group(1).replace("+", "") + m.group(2), t)
def enc(v):
    if isinstance(v, dict):
        return "{" + ",".join(json.dumps(k, ensure_ascii=False) + ":" + enc(v[k]) for k in sorted(v)) + "}"
    if isinstance(v, list):
        return "[" + ",".join(enc(x) for x in v) + "]"
    if isinstance(v, float):
        return real(v)
    return json.dumps(v, ensure_ascii=False)
print(hashlib.sha256(enc(json.load(open("tests/cases/terzaghi.json"))).encode()).hexdigest())
PYEOF
)
[ "$code" = 201 ] && [ "$(json '["state"]' < "$SVC_BODY")" = queued ] && [ "$(json '["case_sha256"]' < "$SVC_BODY")" = "$sha" ] \
	&& [ "$(svc_header Location)" = "/v1/jobs/$id1" ]
check submit_201_queued_with_case_hash $? "status $code: $(head -c 400 "$SVC_BODY")"
before=$(snapshot)
code=$(submit "$alice" "$bodyfile" -H 'Idempotency-Key: k-2.385')
[ "$code" = 200 ] && [ "$(json '["id"]' < "$SVC_BODY")" = "$id1" ] && [ "$(snapshot)" = "$before" ]
check submit_idempotent_retry_same_job $? "status $code: $(head -c 300 "$SVC_BODY")"
body "$tmp/other.json" 'b["priority"] = 7'
code=$(submit "$alice" "$tmp/other.json" -H 'Idempotency-Key: k-2.385')
expect_error submit_key_reuse_other_body_409 409 idempotency_conflict Idempotency-Key "$code"
[ "$(snapshot)" = "$before" ]
check submit_key_reuse_changes_nothing $? "stored state changed"

code=$(submit "$carol" "$bodyfile")
code2=$(submit "$carol" "$bodyfile")
code=$(submit "$carol" "$bodyfile")
expect_error submit_over_user_queue_cap_429 429 quota_exceeded "*" "$code"

# ---- bad input: nothing stored changes ------------------------------------------------------------
before=$(snapshot)
printf '{"case": {"schema": "poro-case/1",\n  "title": }' > "$tmp/malformed.json"
code=$(submit "$alice" "$tmp/malformed.json")
expect_error bad_malformed_json_400 400 invalid_json "" "$code"
json '["error"]["message"]' < "$SVC_BODY" | grep -q "line 2 column"
check bad_malformed_json_names_line_column $? "$(cat "$SVC_BODY")"
body "$tmp/bad_case.json" 'b["case"]["grid"]["cell_size"] = "0.025"'
code=$(submit "$alice" "$tmp/bad_case.json")
expect_error bad_case_schema_422 422 invalid_case /case/grid/cell_size "$code"
[ "$(json '["error"]["problems"][0]["field"]' < "$SVC_BODY")" = /case/grid/cell_size ]
check bad_case_problems_list_pointer $? "$(head -c 300 "$SVC_BODY")"
body "$tmp/bad_prio.json" 'b["priority"] = 2385'
code=$(submit "$alice" "$tmp/bad_prio.json")
expect_error bad_priority_range_422 422 invalid_request /priority "$code"
body "$tmp/bad_key.json" 'b["colour"] = "red"'
code=$(submit "$alice" "$tmp/bad_key.json")
expect_error bad_unknown_key_422 422 invalid_request /colour "$code"
code=$(submit "$alice" "$bodyfile" -H "Idempotency-Key: $(printf 'x%.0s' $(seq 201))")
expect_error bad_idempotency_key_400 400 invalid_header Idempotency-Key "$code"
head -c 300000 /dev/zero | tr '\0' ' ' > "$tmp/big.json"
code=$(submit "$alice" "$tmp/big.json")
expect_error bad_oversize_content_length_413 413 body_too_large "" "$code"
code=$(submit "$alice" "$tmp/big.json" -H 'Transfer-Encoding: chunked')
expect_error bad_oversize_chunked_413 413 body_too_large "" "$code"
code=$(svc_req GET /v1/nothing "$alice")
expect_error bad_unknown_route_404 404 not_found "" "$code"
code=$(svc_req PATCH "/v1/jobs/$id1" "$alice")
allow=$(svc_header Allow)
expect_error bad_wrong_method_405 405 method_not_allowed "" "$code"
[ "$allow" = "GET, HEAD, DELETE" ]
check bad_wrong_method_allow_header $? "Allow '$allow'"
code=$(svc_req GET /v1/jobs "")
expect_error bad_missing_token_401 401 unauthorized Authorization "$code"
svc_header WWW-Authenticate | grep -q '^Bearer'
check bad_missing_token_www_authenticate $? "headers: $(cat "$SVC_HEADERS")"
code=$(svc_req GET /v1/jobs "poro_not-a-token")
expect_error bad_invalid_token_401 401 unauthorized Authorization "$code"
code=$(svc_req GET "/v1/jobs/$id1" "$bob")
expect_error bad_foreign_job_show_404 404 not_found "" "$code"
code=$(svc_req POST "/v1/jobs/$id1/cancel" "$bob")
expect_error bad_foreign_job_cancel_404 404 not_found "" "$code"
code=$(svc_req GET "/v1/jobs/$id1/log" "$bob")
expect_error bad_foreign_job_log_404 404 not_found "" "$code"
code=$(svc_req GET "/v1/jobs/$id1/probes" "$bob")
expect_error bad_foreign_job_probes_404 404 not_found "" "$code"
code=$(svc_req GET "/v1/jobs/$id1/probes" "$alice")
expect_error probes_without_result_404 404 not_found "" "$code"
code=$(svc_req GET "/v1/jobs?state=sleeping" "$alice")
expect_error bad_query_state_400 400 invalid_parameter state "$code"
code=$(svc_req GET "/v1/jobs?limit=0" "$alice")
expect_error bad_query_limit_400 400 invalid_parameter limit "$code"
code=$(svc_req GET "/v1/jobs?after=abc" "$alice")
expect_error bad_query_after_400 400 invalid_parameter after "$code"
code=$(svc_req POST /v1/worker/claim "$alice" -d '{"worker": "x:1"}')
expect_error bad_user_on_worker_route_403 403 forbidden Authorization "$code"
code=$(svc_req GET /v1/jobs "$worker")
expect_error bad_worker_on_user_route_403 403 forbidden Authorization "$code"
code=$(svc_req GET /metrics "$alice")
expect_error bad_user_on_metrics_403 403 forbidden Authorization "$code"
[ "$(snapshot)" = "$before" ]
check bad_input_changes_nothing_stored $? "stored state changed"

# ---- list and show -----------------------------------------------------------------------------
submit "$alice" "$bodyfile" > /dev/null
id2=$(json '["id"]' < "$SVC_BODY")
code=$(svc_req GET "/v1/jobs?state=queued&limit=1" "$alice")
[ "$code" = 200 ] && [ "$(json '["jobs"][0]["id"]' < "$SVC_BODY")" = "$id2" ] && [ "$(json '["next_after"]' < "$SVC_BODY")" = "$id2" ]
check list_newest_first_with_next_after $? "$(head -c 300 "$SVC_BODY")"
code=$(svc_req GET "/v1/jobs?state=queued&limit=1&after=$id2" "$alice")
[ "$code" = 200 ] && [ "$(json '["jobs"][0]["id"]' < "$SVC_BODY")" = "$id1" ]
check list_after_pages $? "$(head -c 300 "$SVC_BODY")"
code=$(svc_req GET /v1/jobs "$bob")
[ "$code" = 200 ] && [ "$(json '["jobs"]' < "$SVC_BODY")" = "[]" ]
check list_shows_only_own_jobs $? "$(head -c 300 "$SVC_BODY")"

# ---- cancel a queued job -------------------------------------------------------------------------
submit "$alice" "$bodyfile" > /dev/null
id3=$(json '["id"]' < "$SVC_BODY")
code=$(svc_req POST "/v1/jobs/$id3/cancel" "$alice")
[ "$code" = 200 ] && [ "$(json '["state"]' < "$SVC_BODY")" = cancelled ]
check cancel_queued_is_immediate $? "status $code: $(head -c 300 "$SVC_BODY")"
code=$(svc_req POST "/v1/jobs/$id3/cancel" "$alice")
expect_error cancel_terminal_409 409 not_cancellable "" "$code"
svc_req GET "/v1/jobs/$id3" "$alice" > /dev/null
[ "$(json '["events"][-1]["actor"]' < "$SVC_BODY")" = alice ] && [ "$(json '["events"][-1]["to"]' < "$SVC_BODY")" = cancelled ] \
	&& [ "$(json '["events"][0]["detail"]' < "$SVC_BODY")" = submitted ]
check events_record_actor $? "$(json '["events"]' < "$SVC_BODY")"

# ---- worker protocol ---------------------------------------------------------------------------
claim() { # TOKEN [WAIT]
	svc_req POST /v1/worker/claim "$1" -H 'Content-Type: application/json' \
		-d "{\"worker\": \"host-a:4242\", \"host\": \"host-a\", \"threads\": 2, \"wait_seconds\": ${2:-0}}"
}
code=$(claim "$worker")
cid=$(json '["job"]["id"]' < "$SVC_BODY")
att=$(json '["job"]["attempt"]' < "$SVC_BODY")
[ "$code" = 200 ] && [ "$cid" = "$id1" ] && [ "$att" = 1 ] && [ "$(json '["job"]["case"]["schema"]' < "$SVC_BODY")" = poro-case/1 ] \
	&& [ "$(json '["job"]["checkpoint"]' < "$SVC_BODY")" = null ] && [ "$(json '["job"]["lease_seconds"]' < "$SVC_BODY")" = 300 ]
check claim_returns_oldest_job_attempt_1 $? "status $code: $(head -c 300 "$SVC_BODY")"
code=$(svc_req POST "/v1/worker/jobs/$cid/heartbeat" "$worker" -d '{"attempt": 1, "progress": {"step": 12, "time": 0.5, "us_per_mp_step": 2.385, "fraction": 0.25}, "solver_version": "v1.2-test"}')
[ "$code" = 200 ] && [ "$(json '["cancel"]' < "$SVC_BODY")" = false ] && json '["lease_expires_at"]' < "$SVC_BODY" | grep -q 'Z$'
check heartbeat_renews_lease $? "status $code: $(cat "$SVC_BODY")"
svc_req GET "/v1/jobs/$cid" "$alice" > /dev/null
[ "$(json '["state"]' < "$SVC_BODY")" = running ] && [ "$(json '["progress"]["step"]' < "$SVC_BODY")" = 12 ] \
	&& [ "$(json '["solver_version"]' < "$SVC_BODY")" = v1.2-test ] && [ "$(json '["worker_host"]' < "$SVC_BODY")" = host-a ] \
	&& [ "$(json '["events"][-1]["actor"]' < "$SVC_BODY")" = host-a:4242 ]
check job_records_progress_version_host $? "$(head -c 600 "$SVC_BODY")"
code=$(svc_req POST "/v1/worker/jobs/$cid/heartbeat" "$worker" -d '{"attempt": 2}')
expect_error heartbeat_wrong_attempt_409 409 stale_attempt /attempt "$code"

logpost() { svc_req POST "/v1/worker/jobs/$cid/log" "$worker" -d "{\"attempt\": $1, \"offset\": $2, \"text\": \"$3\"}"; }
code=$(logpost 1 0 'step 1\n')
[ "$code" = 200 ] && [ "$(json '["next_offset"]' < "$SVC_BODY")" = 7 ]
check log_append_200 $? "status $code: $(cat "$SVC_BODY")"
code=$(logpost 1 0 'step 1\n')
[ "$code" = 200 ] && [ "$(json '["next_offset"]' < "$SVC_BODY")" = 7 ]
check log_append_same_offset_idempotent $? "status $code: $(cat "$SVC_BODY")"
code=$(logpost 1 99 'late\n')
expect_error log_gap_409 409 log_gap /offset "$code"
[ "$(json '["error"]["expected_offset"]' < "$SVC_BODY")" = 7 ]
check log_gap_names_expected_offset $? "$(cat "$SVC_BODY")"
logpost 1 7 'step 2\n' > /dev/null
code=$(svc_req GET "/v1/jobs/$cid/log" "$alice")
[ "$code" = 200 ] && [ "$(cat "$SVC_BODY")" = "$(printf 'step 1\nstep 2\n')" ]
check log_get_text $? "status $code: $(cat "$SVC_BODY")"
code=$(svc_req GET "/v1/jobs/$cid/log?offset=7" "$alice")
[ "$code" = 200 ] && [ "$(cat "$SVC_BODY")" = "step 2" ]
check log_get_from_offset $? "status $code: '$(cat "$SVC_BODY")'"
code=$(svc_req GET "/v1/jobs/$cid/log?follow=2" "$alice")
expect_error log_bad_follow_400 400 invalid_parameter follow "$code"

# follow: a background reader gets a chunk appended later and ends when the attempt ends
curl -s -N -H "Authorization: Bearer $alice" "$SVC_URL/v1/jobs/$cid/log?follow=1&offset=14" > "$tmp/follow.txt" &
follower=$!

# uploads
head -c 70001 /dev/urandom > "$tmp/result.h5"
fsha=$(sha256sum "$tmp/result.h5" | cut -d' ' -f1)
upload() { # NAME [SHA] [FILE] [curl args...]
	local n=$1 s=${2:-$fsha} f=${3:-$tmp/result.h5}
	shift 3 2>/dev/null || shift $#
	svc_req PUT "/v1/worker/jobs/$cid/files/$n?attempt=1" "$worker" -H "X-Checksum-Sha256: $s" --data-binary "@$f" "$@"
}
code=$(upload result.h5)
[ "$code" = 201 ] && [ "$(json '["sha256"]' < "$SVC_BODY")" = "$fsha" ] && [ "$(json '["size"]' < "$SVC_BODY")" = 70001 ] \
	&& cmp -s "$tmp/result.h5" "$SVC_STATE/files/$cid/1/result.h5"
check upload_201_stored $? "status $code: $(cat "$SVC_BODY")"
files_before=$(find "$SVC_STATE/files" -type f | sort)
before=$(snapshot)
code=$(upload checkpoint.h5 "$(printf '0%.0s' $(seq 64))")
expect_error upload_wrong_checksum_400 400 checksum_mismatch X-Checksum-Sha256 "$code"
for hostile in '../../etc/passwd' '%2e%2e%2fetc%2fpasswd' '..' 'a%2Fb' 'abc%00def' '' '.hidden' 'a..b' \
	"$(printf 'n%.0s' $(seq 129))" 'sp%20ace'; do
	code=$(upload "$hostile")
	expect_error "upload_hostile_name_400 '${hostile:0:24}'" 400 invalid_file_name name "$code"
done
code=$(svc_req PUT "/v1/worker/jobs/$cid/files/x.h5?attempt=1" "$worker" --data-binary "@$tmp/result.h5")
expect_error upload_missing_checksum_400 400 invalid_header X-Checksum-Sha256 "$code"
code=$(svc_req PUT "/v1/worker/jobs/$cid/files/x.h5?attempt=zz" "$worker" -H "X-Checksum-Sha256: $fsha" --data-binary "@$tmp/result.h5")
expect_error upload_bad_attempt_400 400 invalid_parameter attempt "$code"
code=$(svc_req PUT "/v1/worker/jobs/$cid/files/x.h5?attempt=2" "$worker" -H "X-Checksum-Sha256: $fsha" --data-binary "@$tmp/result.h5")
expect_error upload_stale_attempt_409 409 stale_attempt /attempt "$code"
[ "$(find "$SVC_STATE/files" -type f | sort)" = "$files_before" ] && [ "$(snapshot)" = "$before" ] && [ ! -e /etc/passwd.h5 ]
check upload_refusals_write_nothing $? "files now: $(find "$SVC_STATE/files" -type f)"

code=$(svc_req GET "/v1/jobs/$cid/files/result.h5" "$alice" -H 'Range: bytes=100-2484')
[ "$code" = 206 ] && [ "$(svc_header X-Checksum-Sha256)" = "$fsha" ] && [ "$(svc_header Content-Range)" = "bytes 100-2484/70001" ] \
	&& cmp -s "$SVC_BODY" <(tail -c +101 "$tmp/result.h5" | head -c 2385)
check download_range_206 $? "status $code, headers: $(tr -d '\r' < "$SVC_HEADERS" | tr '\n' ' ')"
code=$(svc_req GET "/v1/jobs/$cid/files/result.h5" "$alice")
[ "$code" = 200 ] && cmp -s "$SVC_BODY" "$tmp/result.h5"
check download_whole_200 $? "status $code"
code=$(svc_req GET "/v1/jobs/$cid/files/result.h5" "$alice" -H 'Range: bytes=70001-')
[ "$code" = 416 ]
check download_range_past_end_416 $? "status $code"
code=$(svc_req GET "/v1/jobs/$cid/files/..%2fporo.db" "$alice")
expect_error download_hostile_name_400 400 invalid_file_name name "$code"
code=$(svc_req GET "/v1/jobs/$cid/files/checkpoint.h5" "$alice")
expect_error download_unindexed_404 404 not_found "" "$code"
code=$(svc_req GET "/v1/worker/jobs/$cid/files/result.h5" "$worker")
[ "$code" = 200 ] && cmp -s "$SVC_BODY" "$tmp/result.h5" && [ "$(svc_header X-Checksum-Sha256)" = "$fsha" ]
check worker_download_200 $? "status $code"

# the server never reads result.h5: probes come from the probes.json a worker uploads
code=$(svc_req GET "/v1/jobs/$cid/probes" "$alice")
expect_error probes_without_probes_json_404 404 not_found "" "$code"
grep -q "job $cid has no probes yet" "$SVC_BODY"
check probes_error_names_the_job $? "$(head -c 300 "$SVC_BODY")"

sleep 0.3
logpost 1 14 'step 3\n' > /dev/null
code=$(svc_req POST "/v1/worker/jobs/$cid/finish" "$worker" -d '{"attempt": 1, "outcome": "succeeded", "message": "done", "exit_code": 0, "solver_version": "v1.2-test", "artifacts": [{"name": "result.h5", "size": 70001, "sha256": "'"$fsha"'"}]}')
[ "$code" = 200 ] && [ "$(json '["state"]' < "$SVC_BODY")" = succeeded ] && [ "$(json '["finished_at"]' < "$SVC_BODY")" != null ]
check finish_succeeded $? "status $code: $(head -c 300 "$SVC_BODY")"
for i in $(seq 50); do kill -0 "$follower" 2>/dev/null || break; sleep 0.1; done
! kill -0 "$follower" 2>/dev/null && [ "$(cat "$tmp/follow.txt")" = "step 3" ]
check log_follow_streams_and_ends $? "follower alive or got '$(cat "$tmp/follow.txt")'"
kill "$follower" 2>/dev/null
before=$(snapshot)
code=$(svc_req POST "/v1/worker/jobs/$cid/heartbeat" "$worker" -d '{"attempt": 1}')
expect_error heartbeat_after_finish_409 409 stale_attempt /attempt "$code"
code=$(logpost 1 21 'ghost\n')
expect_error log_after_finish_409 409 stale_attempt /attempt "$code"
code=$(svc_req POST "/v1/worker/jobs/$cid/finish" "$worker" -d '{"attempt": 1, "outcome": "failed"}')
expect_error finish_twice_409 409 stale_attempt /attempt "$code"
code=$(svc_req POST "/v1/worker/jobs/$cid/finish" "$worker" -d '{"attempt": 1, "outcome": "exploded"}')
expect_error finish_bad_outcome_422 422 invalid_request /outcome "$code"
code=$(svc_req GET "/v1/worker/jobs/$cid/files/result.h5" "$worker")
expect_error worker_download_without_lease_409 409 stale_attempt "*" "$code"
[ "$(snapshot)" = "$before" ]
check stale_writes_change_nothing $? "stored state changed"

# cancel of a running job: heartbeat answers cancel, the worker confirms
code=$(claim "$worker")
rid=$(json '["job"]["id"]' < "$SVC_BODY")
code=$(svc_req POST "/v1/jobs/$rid/cancel" "$admin")
[ "$code" = 200 ] && [ "$(json '["state"]' < "$SVC_BODY")" = running ] && [ "$(json '["cancel_requested"]' < "$SVC_BODY")" = true ]
check cancel_running_requests $? "status $code: $(head -c 300 "$SVC_BODY")"
code=$(svc_req POST "/v1/worker/jobs/$rid/heartbeat" "$worker" -d '{"attempt": 1}')
[ "$code" = 200 ] && [ "$(json '["cancel"]' < "$SVC_BODY")" = true ]
check heartbeat_answers_cancel $? "status $code: $(cat "$SVC_BODY")"
code=$(svc_req POST "/v1/worker/jobs/$rid/finish" "$worker" -d '{"attempt": 1, "outcome": "cancelled", "message": "stopped on request"}')
[ "$code" = 200 ] && [ "$(json '["state"]' < "$SVC_BODY")" = cancelled ]
check finish_cancelled $? "status $code: $(head -c 300 "$SVC_BODY")"

# long-poll: nothing to claim -> 204 after the wait; a submission wakes a waiting claim
while [ "$(claim "$worker")" = 200 ]; do
	j=$(json '["job"]["id"]' < "$SVC_BODY")
	svc_req POST "/v1/worker/jobs/$j/finish" "$worker" -d '{"attempt": 1, "outcome": "failed", "message": "solver diverged at step 2385", "exit_code": 3}' > /dev/null
done
[ "$(json '["state"]' < "$SVC_BODY" 2>/dev/null)" != x ]
svc_req GET "/v1/jobs/$j" "$admin" > /dev/null
[ "$(json '["state"]' < "$SVC_BODY")" = failed ] && [ "$(json '["message"]' < "$SVC_BODY")" = "solver diverged at step 2385" ]
check finish_failed_is_final_with_message $? "$(head -c 300 "$SVC_BODY")"
start=$(date +%s%N)
code=$(claim "$worker" 1)
ms=$(( ($(date +%s%N) - start) / 1000000 ))
[ "$code" = 204 ] && [ "$ms" -ge 900 ]
check claim_long_poll_204_after_wait $? "status $code after $ms ms"
( sleep 0.5; curl -s -o /dev/null -H "Authorization: Bearer $bob" --data-binary "@$bodyfile" "$SVC_URL/v1/jobs" ) &
start=$(date +%s%N)
submitter=$!
code=$(claim "$worker" 20)
ms=$(( ($(date +%s%N) - start) / 1000000 ))
[ "$code" = 200 ] && [ "$ms" -lt 5000 ]
check claim_long_poll_woken_by_submit $? "status $code after $ms ms"
wait "$submitter"

code=$(svc_req GET /metrics "$admin")
grep -q '^poro_jobs{state="succeeded"} 1$' "$SVC_BODY" && grep -q '^poro_claim_latency_seconds_count ' "$SVC_BODY" \
	&& grep -q '^poro_commit_seconds_bucket' "$SVC_BODY" && grep -q 'poro_http_requests_total{code="404"}' "$SVC_BODY" \
	&& grep -q '^poro_worker_heartbeat_age_seconds{worker="host-a:4242",user="w1"}' "$SVC_BODY" \
	&& grep -q '^poro_worker_heartbeat_age_seconds{worker="w1",user="w1"}' "$SVC_BODY" && grep -q '^poro_job_duration_seconds_count' "$SVC_BODY"
check metrics_prometheus_text $? "status $code: $(head -c 400 "$SVC_BODY")"
[ "$(svc_req GET /metrics "$worker")" = 200 ]
check metrics_worker_token_200 $? "worker token refused"

# ---- restart: SIGTERM exits 0, everything acknowledged is still there -----------------------------
before=$(snapshot)
svc_stop main
status=$SVC_STATUS
[ "$status" = 0 ]
check sigterm_exits_0 $? "exit status $status: $(tail -3 "$tmp/main.err")"
svc_start main --max-body-bytes 262144 > /dev/null
[ "$(snapshot)" = "$before" ]
check restart_keeps_every_job $? "state differs after restart"
svc_stop main

# ---- fair share and lease expiry on a server with 1 s leases --------------------------------------
svc_start short --lease-seconds 1 --max-backoff-seconds 1 || { echo "FAIL start_short: server did not start"; exit 1; }
ua=$(svc_token short usera user)
ub=$(svc_token short userb user)
wk=$(svc_token short w2 worker)
for i in $(seq 20); do submit "$ua" "$bodyfile" > /dev/null; done
submit "$ub" "$bodyfile" > /dev/null
bjob=$(json '["id"]' < "$SVC_BODY")
claim "$wk" > /dev/null
first=$(json '["job"]["id"]' < "$SVC_BODY")
claim "$wk" > /dev/null
second=$(json '["job"]["id"]' < "$SVC_BODY")
[ "$first" = 1 ] && [ "$second" = "$bjob" ]
check fair_share_second_claim_is_other_user $? "claims got $first then $second, user b's job is $bjob"

job_state() { svc_req GET "/v1/jobs/$1" "$2" > /dev/null && [ "$(json '["state"]' < "$SVC_BODY")" = "$3" ]; }
wait_for 10 job_state "$first" "$ua" queued   # the reaper's pass after the 1 s lease
code=$(svc_req POST "/v1/worker/jobs/$first/heartbeat" "$wk" -d '{"attempt": 1}')
expect_error stale_attempt_after_lease_expiry_409 409 stale_attempt /attempt "$code"
code=$(svc_req POST "/v1/worker/jobs/$first/log" "$wk" -d '{"attempt": 1, "offset": 0, "text": "late"}')
expect_error stale_log_after_lease_expiry_409 409 stale_attempt /attempt "$code"
svc_req GET "/v1/jobs/$first" "$ua" > /dev/null
[ "$(json '["state"]' < "$SVC_BODY")" = queued ] && [ "$(json '["attempt"]' < "$SVC_BODY")" = 1 ] \
	&& [ "$(json '["events"][-1]["actor"]' < "$SVC_BODY")" = reaper ] \
	&& json '["events"][-1]["detail"]' < "$SVC_BODY" | grep -q "lease expired"
check lease_expiry_requeues_with_event $? "$(head -c 600 "$SVC_BODY")"

# a cancel requested before the lease expires ends cancelled, not re-queued
claim "$wk" > /dev/null
cj=$(json '["job"]["id"]' < "$SVC_BODY")
svc_req POST "/v1/jobs/$cj/cancel" "$ua" > /dev/null
wait_for 10 job_state "$cj" "$ua" cancelled
svc_req GET "/v1/jobs/$cj" "$ua" > /dev/null
[ "$(json '["state"]' < "$SVC_BODY")" = cancelled ]
check lease_expiry_with_cancel_requested_cancels $? "job $cj: $(head -c 300 "$SVC_BODY")"
svc_stop short

# ---- priority within a user, and a per-user cap on running jobs ----------------------------------
svc_start prio || { echo "FAIL start_prio: server did not start"; exit 1; }
boss=$(svc_token prio boss admin)
dave=$(svc_token prio dave user)
wp=$(svc_token prio wp worker)
for prio in 1 5 -3 3; do
	body "$tmp/prio$prio.json" "b['priority'] = $prio"
	submit "$dave" "$tmp/prio$prio.json" > /dev/null
done
order=""
for i in 1 2 3 4; do
	claim "$wp" > /dev/null
	order="$order $(json '["job"]["id"]' < "$SVC_BODY")"
done
[ "$order" = " 2 4 1 3" ]
check priority_orders_a_users_jobs $? "claimed job ids$order, expected priorities 5, 3, 1, -3 (jobs 2 4 1 3)"
svc_req POST /v1/users "$boss" -d '{"name": "erin", "role": "user", "max_running": 1}' > /dev/null
svc_req POST /v1/tokens "$boss" -d '{"user": "erin"}' > /dev/null
erin=$(json '["token"]' < "$SVC_BODY")
submit "$erin" "$bodyfile" > /dev/null
submit "$erin" "$bodyfile" > /dev/null
claim "$wp" > /dev/null
e1=$(json '["job"]["id"]' < "$SVC_BODY")
e1a=$(json '["job"]["attempt"]' < "$SVC_BODY")
code=$(claim "$wp")
[ -n "$e1" ] && [ "$code" = 204 ]
check running_cap_holds_second_job $? "first claim got '$e1', second claim answered $code"
svc_req POST "/v1/worker/jobs/$e1/finish" "$wp" -d "{\"attempt\": $e1a, \"outcome\": \"failed\", \"message\": null, \"exit_code\": 3}" > /dev/null
code=$(claim "$wp")
e2=$(json '["job"]["id"]' < "$SVC_BODY")
[ "$code" = 200 ] && [ -n "$e2" ] && [ "$e2" != "$e1" ]
check running_cap_releases_after_finish $? "claim after the finish answered $code with job '$e2'"
svc_stop prio

# ---- a database newer than the binary is refused ------------------------------------------------
sqlite3 "$SVC_TMP/short/poro.db" "INSERT INTO schema_migrations (version, applied_at) VALUES (999, 0)"
"$build/poro-server" --listen 127.0.0.1:0 --state "$SVC_TMP/short" > /dev/null 2> "$tmp/newer.err"
rc=$?
[ "$rc" -ne 0 ] && grep -q "newer than this poro-server" "$tmp/newer.err"
check newer_schema_refused $? "exit $rc: $(cat "$tmp/newer.err")"
"$build/poro-server" --help | grep -q -- "--lease-seconds"
check help_documents_flags $? "--help lacks --lease-seconds"
