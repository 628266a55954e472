#!/usr/bin/env bash
# validation_test.sh - what a submission's validation costs and refuses, against a real poro-server:
# a case of 1000 bad probes is answered 422 with at most CASE_PROBLEMS_MAX (100) problems and the
# total stated; threads above --max-job-threads is 422 naming /threads and the limit; cases over a
# limit of docs/case-spec.md "Limits" (a reported 1.6e9 cells, an end time of 1e12 s, 40,000
# probes) are 422 naming the limit; a case of 10,000 probes (the limit) is accepted; a valid case's
# warnings (a friction angle that reads as radians) come back with its 201, and a case without one
# gets an empty list. The server's
# peak RSS (VmHWM) and the time of each answer are printed as INFO lines, never asserted; nothing
# refused is stored. Runs in a few seconds.
#   bash tests/service/validation_test.sh BUILD_DIR      (from the repository root)
set -u
build=${1:-build}
cd "$(dirname "$0")/../.."
. tests/service/lib.sh
svc_init "$build"
tmp=$SVC_TMP

# body FILE PYTHON: a submission of tests/cases/terzaghi.json as "case", after the python statement
# PYTHON run with b (the body) and c (the case)
body() {
	python3 - "$1" "$2" <<'PYEOF'
import json, sys
c = json.load(open("tests/cases/terzaghi.json"))
b = {"case": c}
exec(sys.argv[2])
json.dump(b, open(sys.argv[1], "w"), separators=(",", ":"))
PYEOF
}
submit() { # FILE: sets $code; the answer in $SVC_BODY; prints its time as INFO
	local t0 t1
	t0=$(date +%s%N)
	code=$(svc_req POST /v1/jobs "$alice" -H 'Content-Type: application/json' --data-binary "@$1")
	t1=$(date +%s%N)
	echo "INFO $(basename "$1" .json): HTTP $code in $(( (t1 - t0) / 1000000 )) ms for $(wc -c < "$1") bytes"
}
error_field() { json "[\"error\"][\"$1\"]" < "$SVC_BODY"; }
peak_rss() { echo "INFO server peak RSS after $1: $(awk '/VmHWM/ {print $2 / 1024 " MiB"}' "/proc/$SVC_PID/status")"; }
job_count() {
	svc_req GET "/v1/jobs?limit=1000" "$alice" > /dev/null
	json '["jobs"]' < "$SVC_BODY" | python3 -c 'import json, sys; print(len(json.load(sys.stdin)))'
}

svc_start main --max-job-threads 8 || { echo "FAIL start_main: server did not start"; exit 1; }
alice=$(svc_token main alice user)
peak_rss start

# ---- 1000 bad probes: the first 100 problems and the total --------------------------------------
body "$tmp/bad_probes.json" 'c["probes"] = [{"name": "p%d" % i, "kind": "pore_pressure"} for i in range(1000)]'
submit "$tmp/bad_probes.json"
listed=$(json '["error"]["problems"]' < "$SVC_BODY" | python3 -c 'import json, sys; print(len(json.load(sys.stdin)))')
message=$(error_field message)
[ "$code" = 422 ] && [ "$(error_field code)" = invalid_case ] && [ "$listed" -le 100 ] && [ "$listed" -ge 1 ]
check bad_probes_list_at_most_100_problems $? "status $code, $listed problems listed: $(head -c 300 "$SVC_BODY")"
case $message in "case is invalid: 1000 problems (the first 100 listed), first: missing required key") r=0 ;; *) r=1 ;; esac
check bad_probes_message_states_the_total $r "message '$message'"
[ "$(error_field field)" = /case/probes/0/point ] &&
	[ "$(json '["error"]["problems"][99]["field"]' < "$SVC_BODY")" = /case/probes/99/point ]
check bad_probes_problems_in_document_order $? "$(head -c 300 "$SVC_BODY")"
peak_rss "1000 bad probes"

# ---- threads above --max-job-threads -------------------------------------------------------------
body "$tmp/threads_9.json" 'b["threads"] = 9'
submit "$tmp/threads_9.json"
[ "$code" = 422 ] && [ "$(error_field field)" = /threads ] && [ "$(error_field code)" = invalid_request ] &&
	case $(error_field message) in *"at most 8"*max-job-threads*"got 9") true ;; *) false ;; esac
check threads_above_max_job_threads_refused $? "status $code: $(head -c 300 "$SVC_BODY")"
body "$tmp/threads_8.json" 'b["threads"] = 8'
submit "$tmp/threads_8.json"
[ "$code" = 201 ] && [ "$(json '["threads"]' < "$SVC_BODY")" = 8 ]
check threads_at_max_job_threads_accepted $? "status $code: $(head -c 300 "$SVC_BODY")"

# ---- cases over a limit ------------------------------------------------------------------------
over_limit() { # NAME PYTHON FIELD MESSAGE
	body "$tmp/$1.json" "$2"
	submit "$tmp/$1.json"
	[ "$code" = 422 ] && [ "$(error_field field)" = "$3" ] &&
		[ "$(json '["error"]["problems"][0]["message"]' < "$SVC_BODY")" = "$4" ]
	check "$1_refused_naming_the_limit" $? "status $code: $(head -c 400 "$SVC_BODY")"
	peak_rss "$1"
}
over_limit cells_1.6e9 'c["grid"]["extent"] = [1000.0, 1000.0]' /case/grid \
	"must have at most 100000000 cells (the case limit), got 1600000000"
over_limit end_1e12 'c["time"]["end"] = 1e12; c["output"]["frame_interval"] = 0' /case/time/end \
	"must take at most 1000000000 steps of /time/dt (the case limit), got 1e+16"
over_limit dt_above_cfl 'c["time"]["dt"] = 2e-3' /case/time/dt \
	"must be at most 0.000426 s, 1.25 times the soil skeleton's CFL step h / c_p = 0.00034 s (c_p = sqrt((K + 4G/3) / ((1 - n) rho_s)) = 73.42 m/s in body 'column'), got 0.002 (or write \"auto\")"
over_limit probes_40000 \
	'c["probes"] = [{"name": "p%d" % i, "kind": "pore_pressure", "point": [0.05, 0.5]} for i in range(40000)]' \
	/case/probes "must list at most 10000 probes (the case limit), got 40000"
[ "$(job_count)" = 1 ]
check refused_cases_store_nothing $? "jobs: $(head -c 300 "$SVC_BODY")"

# ---- the most probes the limits allow: accepted ------------------------------------------------
body "$tmp/probes_10000.json" \
	'c["probes"] = [{"name": "p%d" % i, "kind": "pore_pressure", "point": [0.05, 0.5]} for i in range(10000)]'
submit "$tmp/probes_10000.json"
check probes_at_the_limit_accepted $(( code != 201 )) "status $code: $(head -c 300 "$SVC_BODY")"
peak_rss "10000 probes"
# ---- a valid case's warnings come back with the job ----------------------------------------------
body "$tmp/radians.json" 'c["materials"][0].update(model="mohr_coulomb", cohesion=1.2e4, friction_angle=0.38, dilation_angle=0)'
submit "$tmp/radians.json"
[ "$code" = 201 ] && [ "$(json '["warnings"][0]["field"]' < "$SVC_BODY")" = /case/materials/0/friction_angle ] &&
	case $(json '["warnings"][0]["message"]' < "$SVC_BODY") in *"0.38 degrees"*"write 21.77") true ;; *) false ;; esac &&
	[ "$(json '["warnings"]' < "$SVC_BODY" | python3 -c 'import json, sys; print(len(json.load(sys.stdin)))')" = 1 ]
check case_warnings_answered_with_the_job $? "status $code: $(head -c 400 "$SVC_BODY")"
id=$(json '["id"]' < "$SVC_BODY")
svc_req GET "/v1/jobs/$id" "$alice" > /dev/null
python3 -c 'import json, sys; sys.exit("warnings" in json.load(sys.stdin))' < "$SVC_BODY"
check case_warnings_not_stored_with_the_job $? "$(head -c 300 "$SVC_BODY")"
body "$tmp/no_warning.json" 'c["title"] = "no warning"'
submit "$tmp/no_warning.json"
[ "$code" = 201 ] && [ "$(json '["warnings"]' < "$SVC_BODY")" = "[]" ]
check case_without_warnings_answered_with_an_empty_list $? "status $code: $(head -c 300 "$SVC_BODY")"

svc_req GET /healthz "" > /dev/null
check server_alive_after_the_submissions $? "healthz did not answer"
