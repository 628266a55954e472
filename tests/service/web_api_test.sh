#!/usr/bin/env bash
# web_api_test.sh - the routes the dashboard reads (docs/web.md), over HTTP with curl against a
# real poro-server and a real poro-worker: the static files (no token; names that could leave the
# web root refused; the page's security headers), POST /v1/cases/validate (problems at their
# fields, nothing stored), GET /v1/jobs/{id}/case, the frames of a run (GET .../frames, the index;
# GET .../frames/{frame}, one frame's floats, checked against poro-solve frames run here on the
# job's result.h5), GET /v1/admin/workers (admin only; the worker with its slots), and the jobs
# search (user, name, title, dates, order) with its bad parameters. The browser test
# (tests/web/dashboard_test.sh) drives the same routes from the pages.
#   bash tests/service/web_api_test.sh BUILD_DIR
set -u
build=${1:-build}
cd "$(dirname "$0")/../.."
. tests/service/lib.sh
svc_init "$build"
tmp=$SVC_TMP

web=$(mktemp -d -p "$tmp")
mkdir -p "$web/app"
printf '<!doctype html><title>t</title>\n' > "$web/index.html"
printf 'export const x = 1;\n' > "$web/app/x.js"
printf 'secret\n' > "$tmp/outside.txt"
printf 'hidden\n' > "$web/.hidden.js"
svc_start main --web-root "$web" --lease-seconds 300 || { echo "FAIL start_main: server did not start"; exit 1; }
admin=$(svc_token main root admin)
alice=$(svc_token main alice user)
bob=$(svc_token main bob user)
pool=$(svc_token main pool worker)
(umask 077 && printf '%s\n' "$pool" > "$tmp/pool.token")

status_is() { # NAME WANT GOT
	check "$1" "$([ "$3" = "$2" ]; echo $?)" "status $3, wanted $2: $(head -c 300 "$SVC_BODY")"
}

# ---- static files ----
code=$(svc_req GET / "")
[ "$code" = 200 ] && grep -q '<title>t</title>' "$SVC_BODY" && svc_header Content-Type | grep -q '^text/html' &&
	svc_header Content-Security-Policy | grep -q "script-src 'self'" && [ "$(svc_header X-Frame-Options)" = DENY ]
check web_index_served_without_token $? "status $code, headers: $(tr -d '\r' < "$SVC_HEADERS" | tr '\n' ' ')"
code=$(svc_req GET /web/app/x.js "")
[ "$code" = 200 ] && svc_header Content-Type | grep -q '^text/javascript' && [ "$(svc_header X-Content-Type-Options)" = nosniff ]
check web_module_served_as_javascript $? "status $code $(svc_header Content-Type)"
code=$(svc_req HEAD /web/app/x.js "")
status_is web_file_answers_head 200 "$code"
for bad in /web/../outside.txt /web/%2e%2e/outside.txt /web/app/..%2f..%2foutside.txt /web/.hidden.js /web/app/x.sh \
	/web/app//x.js /web/%00x.js /web/app/missing.js; do
	code=$(svc_req GET "$bad" "")
	[ "$code" = 404 ] && ! grep -q secret "$SVC_BODY"
	check "web_file_refused_${bad//[^A-Za-z0-9]/_}" $? "status $code: $(head -c 200 "$SVC_BODY")"
done

# ---- validation without a job ----
python3 - tests/cases/terzaghi.json "$tmp" <<'PY'
import json, sys
c = json.load(open(sys.argv[1]))
c["time"]["end"] = 0.02
c["output"]["frame_interval"] = 0.005
json.dump({"case": c, "name": "web-api-run"}, open(sys.argv[2] + "/good.json", "w"))
c["grid"]["cell_size"] = -1
c["bodies"][0]["porosity"] = 2
json.dump({"case": c}, open(sys.argv[2] + "/bad.json", "w"))
slope = json.load(open("tests/cases/mc_slope_k1e-3_single_point.json"))
slope["materials"][0]["friction_angle"] = 0.52   # valid, but most likely meant as radians
json.dump({"case": slope}, open(sys.argv[2] + "/warned.json", "w"))
PY
code=$(svc_req POST /v1/cases/validate "$alice" --data-binary @"$tmp/bad.json")
fields=$(json '["error"]["problems"]' < "$SVC_BODY" | python3 -c 'import json, sys; print(" ".join(p["field"] for p in json.load(sys.stdin)))')
[ "$code" = 422 ] && [ "$(json '["error"]["code"]' < "$SVC_BODY")" = invalid_case ] &&
	echo "$fields" | grep -q /case/grid/cell_size && echo "$fields" | grep -q /case/bodies/0/porosity
check validate_lists_problems_at_their_fields $? "status $code, fields '$fields'"
code=$(svc_req POST /v1/cases/validate "$alice" --data-binary @"$tmp/good.json")
[ "$code" = 200 ] && [ "$(json '["valid"]' < "$SVC_BODY")" = true ] && json '["title"]' < "$SVC_BODY" | grep -q Terzaghi
check validate_accepts_valid_case $? "status $code: $(head -c 300 "$SVC_BODY")"
[ "$code" = 200 ] && [ "$(json '["warnings"]' < "$SVC_BODY")" = "[]" ]
check validate_answers_no_warning_for_a_plain_case $? "status $code: $(head -c 300 "$SVC_BODY")"
code=$(svc_req POST /v1/cases/validate "$alice" --data-binary @"$tmp/warned.json")
[ "$code" = 200 ] && json '["warnings"]' < "$SVC_BODY" | grep -q '"field": "/case/materials/0/friction_angle"'
check validate_answers_warnings_at_their_fields $? "status $code: $(head -c 300 "$SVC_BODY")"
code=$(svc_req GET "/v1/jobs" "$alice")
[ "$code" = 200 ] && [ "$(json '["jobs"]' < "$SVC_BODY")" = "[]" ]
check validate_stores_no_job $? "status $code: $(head -c 300 "$SVC_BODY")"
code=$(svc_req POST /v1/cases/validate "" --data-binary @"$tmp/good.json")
status_is validate_needs_token 401 "$code"

# ---- a run, its case and its frames ----
code=$(svc_req POST /v1/jobs "$alice" --data-binary @"$tmp/good.json")
job=$(json '["id"]' < "$SVC_BODY")
[ "$code" = 201 ] && json '["case_title"]' < "$SVC_BODY" | grep -q Terzaghi
check job_carries_case_title $? "status $code: $(head -c 300 "$SVC_BODY")"
code=$(svc_req GET "/v1/jobs/$job/frames" "$alice")
[ "$code" = 404 ] && grep -q "no frames yet" "$SVC_BODY"
check frames_404_before_any_upload $? "status $code: $(head -c 200 "$SVC_BODY")"
"$build/poro-worker" --server "$SVC_URL" --token-file "$tmp/pool.token" --solver "$build/poro-solve" --work "$tmp/work" \
	--threads 1 --name web-api-worker > "$tmp/worker.log" 2>&1 &
worker_pid=$!
done_ok() { svc_req GET "/v1/jobs/$job" "$alice" > /dev/null && [ "$(json '["state"]' < "$SVC_BODY")" = succeeded ]; }
wait_for 120 done_ok
check run_succeeded $? "state $(json '["state"]' < "$SVC_BODY"): $(json '["message"]' < "$SVC_BODY")"

code=$(svc_req GET "/v1/jobs/$job/case" "$alice")
[ "$code" = 200 ] && [ "$(json '["time"]["end"]' < "$SVC_BODY")" = 0.02 ]
check case_route_answers_stored_case $? "status $code: $(head -c 200 "$SVC_BODY")"
code=$(svc_req GET "/v1/jobs/$job/case" "$bob")
status_is case_route_other_user_404 404 "$code"

code=$(svc_req GET "/v1/jobs/$job/frames" "$alice")
cp "$SVC_BODY" "$tmp/index.json"
[ "$code" = 200 ] && [ "$(json '["format"]' < "$tmp/index.json")" = poro-frames/1 ] &&
	[ -n "$(svc_header X-Checksum-Sha256)" ]
check frames_index_served $? "status $code: $(head -c 300 "$SVC_BODY")"
frames=$(json '["frames"]' < "$tmp/index.json" | python3 -c 'import json, sys; print(len(json.load(sys.stdin)))')
[ "${frames:-0}" -ge 5 ]
check frames_index_lists_every_frame $? "$frames frames"
# the last frame's bytes, against poro-solve frames run here on the job's own result.h5
svc_req GET "/v1/jobs/$job/files/result.h5" "$alice" > /dev/null && cp "$SVC_BODY" "$tmp/result.h5"
mkdir -p "$tmp/mine" && "$build/poro-solve" frames "$tmp/result.h5" --out "$tmp/mine" --job "$job" --attempt 1 > /dev/null
last=$((frames - 1))
code=$(svc_req GET "/v1/jobs/$job/frames/$last" "$alice")
python3 - "$tmp/mine" "$SVC_BODY" "$last" <<'PY'
import json, sys
idx = json.load(open(sys.argv[1] + "/frames.json"))
f = idx["frames"][int(sys.argv[3])]
want = open(sys.argv[1] + "/frames.bin", "rb").read()[f["offset"]:f["offset"] + f["length"]]
got = open(sys.argv[2], "rb").read()
n = sum(f["counts"][s] * len(idx["sets"][s]) for s in idx["sets"])
sys.exit(0 if got == want and len(got) == 4 * n else 1)
PY
check frame_bytes_are_the_runs $? "status $code, $(wc -c < "$SVC_BODY") bytes"
[ "$(svc_header Content-Type)" = application/octet-stream ] && [ "$(svc_header X-Frames-Attempt)" = 1 ]
check frame_headers $? "$(tr -d '\r' < "$SVC_HEADERS" | tr '\n' ' ')"
for bad in "$frames" 999999999 01 -1 1x; do
	code=$(svc_req GET "/v1/jobs/$job/frames/$bad" "$alice")
	status_is "frame_${bad//-/minus}_not_found" 404 "$code"
done
code=$(svc_req GET "/v1/jobs/$job/frames/0" "$bob")
status_is frames_of_other_user_404 404 "$code"
code=$(svc_req GET "/v1/jobs/$job/frames/0/x" "$alice")
status_is frame_path_with_tail_404 404 "$code"

# ---- admin view ----
code=$(svc_req GET /v1/admin/workers "$admin")
python3 - "$SVC_BODY" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
w = [x for x in d["workers"] if x["worker"] == "web-api-worker"]
ok = w and w[0]["user"] == "pool" and w[0]["threads"] == 1 and w[0]["slots"] >= 1 and "queue" in d and "running" in d
sys.exit(0 if ok else 1)
PY
check admin_workers_lists_worker_and_slots $? "status $code: $(head -c 400 "$SVC_BODY")"
code=$(svc_req GET /v1/admin/workers "$alice")
status_is admin_workers_forbidden_to_users 403 "$code"
kill -TERM "$worker_pid" 2> /dev/null
wait "$worker_pid" 2> /dev/null

# ---- search ----
python3 - "$tmp" <<'PY'
import json, sys
c = json.load(open("tests/cases/hydrostatic_column.json"))
json.dump({"case": c, "name": "Second-Label"}, open(sys.argv[1] + "/second.json", "w"))
PY
svc_req POST /v1/jobs "$alice" --data-binary @"$tmp/second.json" > /dev/null
second=$(json '["id"]' < "$SVC_BODY")
svc_req POST /v1/jobs "$bob" --data-binary @"$tmp/second.json" > /dev/null
ids() { json '["jobs"]' < "$SVC_BODY" | python3 -c 'import json, sys; print(" ".join(str(j["id"]) for j in json.load(sys.stdin)))'; }
search() { # NAME QUERY TOKEN WANT_IDS
	local code got
	code=$(svc_req GET "/v1/jobs?$2" "$3")
	got=$(ids)
	check "$1" "$([ "$code" = 200 ] && [ "$got" = "$4" ]; echo $?)" "status $code, ids '$got', wanted '$4'"
}
today=$(date -u +%Y-%m-%d)
search search_by_label_any_case "name=second-LABEL" "$alice" "$second"
search search_by_case_title "title=consolidation" "$alice" "$job"
search search_by_state_and_title "state=queued&title=TERZAGHI" "$alice" "$second"
search search_oldest_first "order=oldest" "$alice" "$job $second"
search search_oldest_first_after "order=oldest&after=$job" "$alice" "$second"
search search_dates_today "created_after=$today&created_before=$today" "$alice" "$second $job"
search search_dates_before_any "created_before=2000-01-01" "$alice" ""
search search_other_user_name_is_empty "user=bob" "$alice" ""
search search_percent_is_plain_text "name=%25" "$alice" ""
code=$(svc_req GET "/v1/jobs?user=bob" "$admin")
[ "$code" = 200 ] && [ "$(json '["jobs"]' < "$SVC_BODY" | python3 -c 'import json, sys; print(set(j["user"] for j in json.load(sys.stdin)))')" = "{'bob'}" ]
check search_admin_by_user $? "status $code: $(head -c 300 "$SVC_BODY")"
code=$(svc_req GET "/v1/jobs?order=oldest&limit=1" "$admin")
[ "$code" = 200 ] && [ "$(ids)" = "$job" ] && [ "$(json '["next_after"]' < "$SVC_BODY")" = "$job" ]
check search_pages_with_next_after $? "status $code: $(head -c 300 "$SVC_BODY")"
for bad in "order=sideways" "created_after=yesterday" "created_before=2026-13-01" "created_after=2026-01-01T25:00:00Z"; do
	code=$(svc_req GET "/v1/jobs?$bad" "$alice")
	[ "$code" = 400 ] && [ "$(json '["error"]["code"]' < "$SVC_BODY")" = invalid_parameter ]
	check "search_refuses_${bad//[^a-z]/_}" $? "status $code: $(head -c 200 "$SVC_BODY")"
done
