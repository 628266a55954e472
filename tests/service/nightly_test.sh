#!/usr/bin/env bash
# nightly_test.sh - benchmark nightlies through real processes (docs/benchmarks.md): a real
# poro-server and real poro-workers on 127.0.0.1, `poro nightly` on the reduced suite
# tests/service/nightly/suite.json (a short Terzaghi column by the semi-implicit and by the implicit
# scheme, a Mohr-Coulomb element test, and a short column timed in 5 repeats). What it shows, in the order of docs/benchmarks.md "Tests":
#   a. the suite run twice: two stored runs, each with its machine and fingerprint and every
#      figure with its samples; `poro nightly compare` puts them side by side; every job carries
#      the run's label; on a worker with two slots an exclusive (timing) job never ran beside
#      another job (its log, in order: no solver started while an exclusive one ran, and none
#      beside it);
#   b. ten unchanged reruns of the timing case on this shared machine flag nothing (the false
#      alarms are counted and printed); the test knob PORO_DEBUG_SLOWDOWN=1.5 on the worker is
#      flagged as regressed (or, when the machine's own range in those reruns is wider than
#      1.5 / 1.1, a slowdown 1.25 times beyond that range: a change inside it is no evidence); an accuracy loss (the Terzaghi case without its pore-pressure
#      smoothing) is flagged against its band; a job made to fail is reported failed, and a case
#      refused at submission did_not_run, each named, the run "failed";
#   c. the JUnit XML of those runs read by a real consumer (Debian's python3-junitparser) with the
#      right failures, errors and skips; the HTML report opened in Debian's headless chromium, its
#      screenshot saved in BUILD/nightly-report.png and its plots found drawn in it (the series'
#      colour in the pixels);
#   d. a worker restricted to one processor (taskset) is another machine fingerprint: its timing
#      figure is judged against no sample of the two-processor machine, the series of each
#      machine holds only its own runs, a timing series asked for without a machine is refused,
#      and compare says the two runs' timings are not compared;
#   and bad input to the new routes, the submission keys and the CLI, each refused naming it.
# No assertion on a time: the detector's verdicts are asserted; the timings are printed.
#   bash tests/service/nightly_test.sh BUILD_DIR
set -u
build=${1:-build}
cd "$(dirname "$0")/../.."
. tests/service/lib.sh
svc_init "$build"
root=$PWD
PY3=/usr/bin/python3   # Debian's, where python3-junitparser and python3-pil install
suite=tests/service/nightly/suite.json
workers=()
cleanup_workers() {
	for w in "${workers[@]}"; do kill -TERM "$w" 2>/dev/null; kill -TERM "$w" 2>/dev/null; done
	for w in "${workers[@]}"; do wait "$w" 2>/dev/null; done
	svc_cleanup
}
trap cleanup_workers EXIT

cp "$build/poro-solve" "$SVC_TMP/poro-solve"   # a rebuild of the tree cannot fail a start
svc_start main --lease-seconds 15
check server_starts $? "no server"
user=$(svc_token main nightly user)
other=$(svc_token main other user)
pool=$(svc_token main pool worker)
(umask 077 && printf '%s\n' "$pool" > "$SVC_TMP/pool.token")
export PORO_SERVER=$SVC_URL PORO_TOKEN=$user OMP_WAIT_POLICY=passive

start_worker() { # NAME SLOTS [command prefix...]: pid in $worker_pid, log in $SVC_TMP/NAME.log
	local name=$1 slots=$2
	shift 2
	"$@" "$build/poro-worker" --server "$SVC_URL" --token-file "$SVC_TMP/pool.token" --work "$SVC_TMP/work-$name" \
		--slots "$slots" --threads "$slots" --solver "$SVC_TMP/poro-solve" --name "$name" > "$SVC_TMP/$name.log" 2>&1 &
	worker_pid=$!
	workers+=("$worker_pid")
}
stop_worker() { # PID: drains it (it is idle between runs) and waits for it
	kill -TERM "$1" 2>/dev/null
	wait "$1" 2>/dev/null
}
nightly() { # NAME ARGS...: poro nightly ARGS, stdout in $SVC_TMP/NAME.out, stderr .err, status in $rc
	local name=$1
	shift
	"$build/poro" nightly "$@" > "$SVC_TMP/$name.out" 2> "$SVC_TMP/$name.err"
	rc=$?
}
run_json() { # ID: the run as the API answers, into $SVC_TMP/run-ID.json
	svc_req GET "/v1/benchmarks/$1" "$user" > /dev/null && cp "$SVC_BODY" "$SVC_TMP/run-$1.json"
}
last_run_id() { sed -n 's/^benchmark run \([0-9]*\):.*/\1/p' "$SVC_TMP/$1.out" | head -1; }

# ---- a. the reduced suite twice -------------------------------------------------------------------
start_worker wA 2
wA=$worker_pid
for k in 1 2; do
	nightly "suite$k" run "$suite" --junit "$SVC_TMP/suite$k.xml"
	check "a_suite_run_${k}_passes" $rc "exit $rc: $(tail -5 "$SVC_TMP/suite$k.err") $(tail -12 "$SVC_TMP/suite$k.out")"
done
run1=$(last_run_id suite1)
run2=$(last_run_id suite2)
run_json "$run1"
run_json "$run2"
python3 - "$SVC_TMP/run-$run1.json" "$SVC_TMP/run-$run2.json" <<'PY' > "$SVC_TMP/py" 2>&1
import json, re, sys
for path in sys.argv[1:]:
    run = json.load(open(path))
    assert run["state"] == "passed", run["state"]
    assert re.fullmatch(r"[0-9a-f]{16}", run["fingerprint"] or ""), run["fingerprint"]
    m = run["machine"]
    for k in ("cpu_model", "cores", "memory_mb", "kernel", "compiler", "blas"):
        assert m.get(k), "machine has no " + k
    figs = {f["figure"]: f for f in run["figures"]}
    assert len(figs) == 16, sorted(figs)
    assert len(figs["speed/relative_step_cost"]["samples"]) == 5, figs["speed/relative_step_cost"]
    assert figs["speed/relative_step_cost"]["machine"] == run["fingerprint"]
    assert len(figs["terzaghi/terzaghi_rms"]["samples"]) == 1 and figs["terzaghi/terzaghi_rms"]["status"] == "ok"
    assert figs["mohr_coulomb/mohr_coulomb_peak_error"]["median"] < 1e-6
    newton = figs["implicit/newton_iterations"]
    assert newton["status"] == "ok" and newton["samples"] == [20], newton   # one a step: linear, elastic tangent
    assert figs["implicit/terzaghi_rms"]["status"] == "ok", figs["implicit/terzaghi_rms"]
    assert all(f["status"] in ("ok", "recorded", "no_history") for f in run["figures"]), \
        [(f["figure"], f["status"]) for f in run["figures"]]
    assert run["commit"] and run["label"].startswith("reduced-") and run["solver_version"]
print("ok")
PY
check a_runs_stored_with_machine_and_samples $? "$(tail -3 "$SVC_TMP/py")"
svc_req GET "/v1/benchmarks?suite=reduced" "$user" > /dev/null
[ "$(json '["runs"].__len__()' < "$SVC_BODY")" = 2 ]
check a_list_holds_two_runs $? "$(head -c 300 "$SVC_BODY")"

nightly compare compare "$run1" "$run2"
ok=0
for figure in terzaghi/terzaghi_rms speed/relative_step_cost mohr_coulomb/peak_q; do
	grep -Eq "^$figure +[0-9.e+-]+ +[0-9.e+-]+ +[+-][0-9.]+% +[a-z_]+ +[a-z_]+" "$SVC_TMP/compare.out" || ok=1
done
check a_compare_side_by_side $(( rc != 0 || ok )) "exit $rc: $(head -20 "$SVC_TMP/compare.out")"
sed -n '1,4p' "$SVC_TMP/compare.out" | sed 's/^/INFO compare: /'

label=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['label'])" "$SVC_TMP/run-$run1.json")
speed_job=$(python3 -c "import json,sys; r=json.load(open(sys.argv[1])); print([c for c in r['cases'] if c['name']=='speed'][0]['jobs'][0])" "$SVC_TMP/run-$run1.json")
svc_req GET "/v1/jobs/$speed_job" "$user" > /dev/null
[ "$(json '["batch"]' < "$SVC_BODY")" = "$label" ] && [ "$(json '["exclusive"]' < "$SVC_BODY")" = true ]
check a_jobs_carry_label_and_exclusive $? "$(head -c 400 "$SVC_BODY")"

# the worker's log, in order: an exclusive job's solver starts only when no other runs, and no
# other starts while it runs
python3 - "$SVC_TMP/wA.log" <<'PY' > "$SVC_TMP/py" 2>&1
import re, sys
running, exclusive, seen = set(), set(), 0
for line in open(sys.argv[1]):
    m = re.search(r"(job \d+ attempt \d+): (claimed|solver started|finished)", line)
    if not m:
        continue
    job, what = m.groups()
    if what == "claimed" and "exclusive)" in line:
        exclusive.add(job)
    elif what == "solver started":
        assert not (job in exclusive and running), "%s started beside %s" % (job, running)
        assert not (running & exclusive), "%s started beside exclusive %s" % (job, running & exclusive)
        running.add(job)
        seen += job in exclusive
    elif what == "finished":
        running.discard(job)
assert seen >= 10, "only %d exclusive jobs ran" % seen
print(seen)
PY
check a_exclusive_jobs_ran_alone $? "$(tail -3 "$SVC_TMP/py")"

# ---- b. ten unchanged reruns, the slowdown, the accuracy loss, a failure ----------------------------
alarms=0 judged=0
for k in $(seq 10); do
	nightly "rerun$k" run "$suite" --only speed
	line=$(grep '^speed/relative_step_cost' "$SVC_TMP/rerun$k.out")
	case "$line" in *regressed*) alarms=$((alarms + 1)) ;; esac
	case "$line" in *" ok") judged=$((judged + 1)) ;; esac
	raw=$(grep '^speed/median_cpu_us_per_point_step' "$SVC_TMP/rerun$k.out" | awk '{print $3}')
	echo "INFO rerun $k: $(echo "$line" | tr -s ' ') (the median step itself: $raw us)"
done
echo "INFO false alarms: $alarms in 10 unchanged reruns of speed/relative_step_cost ($judged judged ok)"
check b_ten_unchanged_reruns_flag_nothing $(( alarms != 0 || judged != 10 )) \
	"$alarms false alarms, $judged judged ok: $(grep -h '^  speed' "$SVC_TMP"/rerun*.out | head -3)"

stop_worker "$wA"
# The slowdown to inject: 1.5x, unless this machine's own range over the history the slowed run is
# judged against (the latest 10 runs) is wider than 1.5 / 1.1: the verdict counts a change only
# beyond the machine's range by the minimum effect (docs/benchmarks.md, "A machine with two
# speeds"), so a 1.5x slowdown inside it is, correctly, no evidence; then a slowdown 1.25 times
# beyond the range is injected and must be flagged, and the range is printed.
fp=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['fingerprint'])" "$SVC_TMP/run-$run1.json")
svc_req GET "/v1/benchmarks/series?suite=reduced&figure=speed/relative_step_cost&machine=$fp" "$user" > /dev/null
python3 -c "
import json, math, sys
s = [x for p in json.load(open(sys.argv[1]))['points'][-10:] for x in p['samples']]
r = max(s) / min(s)
f = 1.5 if r <= 1.5 / 1.1 else math.ceil(1.25 * 1.1 * r * 10) / 10
print(f)
print('INFO the machine\'s range before the slowdown: [%.4g, %.4g] over %d samples, %.3gx: injecting %gx%s' % (min(s), max(s), len(s), r, f, '' if f == 1.5 else ' (1.5x lies inside the machine\'s own range)'), file=sys.stderr)
" "$SVC_BODY" > "$SVC_TMP/factor"
factor=$(cat "$SVC_TMP/factor")
start_worker wSlow 2 env PORO_DEBUG_SLOWDOWN="${factor:-1.5}"
wSlow=$worker_pid
nightly slow run "$suite" --only speed --junit "$SVC_TMP/slow.xml"
slow=$(last_run_id slow)
grep -q '^speed/relative_step_cost .* regressed$' "$SVC_TMP/slow.out"
check b_slowdown_flagged $(( rc != 9 || $? != 0 )) "${factor}x: exit $rc: $(cat "$SVC_TMP/slow.out" | head -12)"
# the verdict's detail and the samples, whatever the verdict, and each earlier run of the series
# (its median and range): what to read when this check fails
run_json "$slow"
svc_req GET "/v1/benchmarks/series?suite=reduced&figure=speed/relative_step_cost&machine=$fp" "$user" > /dev/null
python3 -c "import json,sys; print('INFO series before the slowdown (run: median [min, max]): ' + ', '.join('%d: %.4g [%.4g, %.4g]' % (p['run'], p['median'], min(p['samples']), max(p['samples'])) for p in json.load(open(sys.argv[1]))['points'][:-1]))" "$SVC_BODY"
python3 -c "import json,sys; f=[f for f in json.load(open(sys.argv[1]))['figures'] if f['figure']=='speed/relative_step_cost'][0]; print('INFO slowdown %sx: %s: %s; samples %s' % (sys.argv[2], f['status'], f['detail'], f['samples']))" "$SVC_TMP/run-$slow.json" "$factor"
stop_worker "$wSlow"

start_worker wA 2
wA=$worker_pid
# the same suite, its Terzaghi column without pore-pressure smoothing (an accuracy loss), a case
# that fails in its first steps and one the server refuses
python3 - "$suite" "$SVC_TMP/broken.json" "$root/tests/cases" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
cases = sys.argv[3]
for c in s["cases"]:
    c["case"] = cases + "/" + c["case"].split("/")[-1]
s["cases"] = [c for c in s["cases"] if c["name"] == "terzaghi"]
s["cases"][0]["patch"]["formulation"] = {"pore_pressure_smoothing": False}
s["cases"].append({"name": "crash", "case": cases + "/terzaghi.json",
                   "patch": {"time": {"end": 0.05}, "loads": [{"body": "column", "face": "top", "traction": [0, -1e12]}],
                             "materials": [{"name": "soil", "model": "linear_elastic", "density": 2650,
                                            "youngs_modulus": 1e3, "poisson_ratio": 0}]},
                   "figures": {"max_displacement": {"band": [0, 1]}}})
s["cases"].append({"name": "refused", "case": cases + "/terzaghi.json", "patch": {"time": {"dt": -1}},
                   "figures": {"steps": {}}})
json.dump(s, open(sys.argv[2], "w"), indent=1)
PY
nightly broken run "$SVC_TMP/broken.json" --junit "$SVC_TMP/broken.xml" --html "$SVC_TMP/broken.html"
broken=$(last_run_id broken)
run_json "$broken"
python3 - "$SVC_TMP/run-$broken.json" <<'PY' > "$SVC_TMP/py" 2>&1
import json, sys
run = json.load(open(sys.argv[1]))
figs = {f["figure"]: f for f in run["figures"]}
assert run["state"] == "failed", run["state"]
f = figs["terzaghi/terzaghi_rms"]
assert f["status"] == "regressed" and f["median"] > 0.01 and "outside its band" in f["detail"], f
assert figs["terzaghi/steps"]["status"] == "ok"
c = figs["crash/max_displacement"]
assert c["status"] == "failed" and "failed" in c["detail"] and c["samples"] == [], c
d = figs["refused/steps"]
assert d["status"] == "did_not_run" and "/case/time/dt" in d["detail"], d
assert run["summary"] == {"ok": 1, "regressed": 1, "recorded": 2, "failed": 1, "did_not_run": 1}, run["summary"]
print(f["median"])
PY
check b_accuracy_loss_failure_and_refusal_told_apart $(( rc != 9 || $? != 0 )) "exit $rc: $(tail -3 "$SVC_TMP/py")"
echo "INFO accuracy loss: terzaghi_rms $(tail -1 "$SVC_TMP/py") without smoothing, band [0, 0.01]"
grep -q "crash/max_displacement failed: job [0-9]* failed:" "$SVC_TMP/broken.out"
check b_failed_job_named_in_show $? "$(grep crash "$SVC_TMP/broken.out")"

# ---- c. the reports in real consumers ---------------------------------------------------------------
"$PY3" - "$SVC_TMP/broken.xml" "$SVC_TMP/slow.xml" "$SVC_TMP/suite1.xml" <<'PY' > "$SVC_TMP/py" 2>&1
import sys
from junitparser import JUnitXml, Failure, Error, Skipped
def kinds(path):
    x = JUnitXml.fromfile(path)
    out = {}
    for suite in x:
        assert suite.name == "reduced", suite.name
        props = {p.name: p.value for p in suite.properties()}
        assert props["machine_fingerprint"] and props["commit"] and props["label"], props
        for case in suite:
            r = [type(e).__name__ for e in case.result]
            out["%s.%s" % (case.classname, case.name)] = r[0] if r else "passed"
    return out
b = kinds(sys.argv[1])
assert b["reduced.terzaghi.terzaghi_rms"] == "Failure", b
assert b["reduced.crash.max_displacement"] == "Error", b
assert b["reduced.refused.steps"] == "Skipped", b
assert b["reduced.terzaghi.steps"] == "passed", b
s = kinds(sys.argv[2])
assert s["reduced.speed.relative_step_cost"] == "Failure", s
a = kinds(sys.argv[3])
assert len(a) == 16 and set(a.values()) == {"passed"}, a
print("ok")
PY
check c_junit_read_by_junitparser $? "$(tail -4 "$SVC_TMP/py")"

nightly report report "$slow" --html "$SVC_TMP/report.html"
check c_report_html_written $rc "exit $rc: $(cat "$SVC_TMP/report.err")"
shot="$root/$build/nightly-report.png"
rm -f "$shot"
timeout 120 chromium --headless --no-sandbox --disable-gpu --hide-scrollbars --window-size=1000,1600 \
	--screenshot="$shot" "file://$SVC_TMP/report.html" > "$SVC_TMP/chromium.log" 2>&1
"$PY3" - "$shot" "$SVC_TMP/report.html" <<'PY' > "$SVC_TMP/py" 2>&1
import sys, xml.etree.ElementTree as ET
from PIL import Image
img = Image.open(sys.argv[1]).convert("RGB")
w, h = img.size
px = img.load()
def near(c, want, tol=40):
    return all(abs(a - b) <= tol for a, b in zip(c, want))
blue = sum(1 for x in range(0, w, 2) for y in range(0, h, 2) if near(px[x, y], (0x1f, 0x77, 0xb4)))
red = sum(1 for x in range(0, w, 2) for y in range(0, h, 2) if near(px[x, y], (0xc6, 0x28, 0x28)))
html = open(sys.argv[2]).read()
svgs = html.count("<svg ")
assert svgs == 6, "%d plots in the page" % svgs
assert "<script" not in html and "http://" not in html.replace("http://www.w3.org/2000/svg", ""), "not self-contained"
assert blue > 100 and red > 20, "series pixels: %d blue, %d red" % (blue, red)
print("%dx%d, %d plots, %d series pixels, %d regression pixels" % (w, h, svgs, blue, red))
PY
check c_html_plots_drawn_in_chromium $? "$(tail -3 "$SVC_TMP/py") $(tail -3 "$SVC_TMP/chromium.log")"
echo "INFO chromium screenshot $build/nightly-report.png: $(tail -1 "$SVC_TMP/py")"

# ---- d. another machine fingerprint -------------------------------------------------------------------
stop_worker "$wA"
# nproc counts OMP_NUM_THREADS as the processors available: the processors are what is asked
if [ "$(env -u OMP_NUM_THREADS -u OMP_THREAD_LIMIT nproc)" -ge 2 ]; then
	start_worker wOne 1 taskset -c 0
	wOne=$worker_pid
	nightly one run "$suite" --only speed
	one=$(last_run_id one)
	run_json "$one"
	python3 - "$SVC_TMP/run-$one.json" "$SVC_TMP/run-$run1.json" <<'PY' > "$SVC_TMP/py" 2>&1
import json, sys
one, two = (json.load(open(p)) for p in sys.argv[1:])
assert one["machine"]["cores"] == 1 and two["machine"]["cores"] >= 2, (one["machine"], two["machine"])
assert one["fingerprint"] != two["fingerprint"]
f = [f for f in one["figures"] if f["figure"] == "speed/relative_step_cost"][0]
assert f["status"] == "no_history" and f["stats"]["history_samples"] == 0 and f["machine"] == one["fingerprint"], f
print(one["fingerprint"], two["fingerprint"])
PY
	check d_other_machine_not_judged_against_first $(( rc != 0 || $? != 0 )) "exit $rc: $(tail -3 "$SVC_TMP/py")"
	read -r fp1 fp2 < <(tail -1 "$SVC_TMP/py")
	echo "INFO fingerprints: $fp2 (2 processors), $fp1 (taskset -c 0)"
	ok=0
	for fp in "$fp1" "$fp2"; do
		svc_req GET "/v1/benchmarks/series?suite=reduced&figure=speed/relative_step_cost&machine=$fp" "$user" > /dev/null
		python3 -c "import json,sys; d=json.load(open(sys.argv[1])); sys.exit(0 if d['points'] and all(p['machine']==sys.argv[2] for p in d['points']) else 1)" "$SVC_BODY" "$fp" || ok=1
	done
	svc_req GET "/v1/benchmarks/series?suite=reduced&figure=speed/relative_step_cost&machine=$fp1" "$user" > /dev/null
	[ "$(json '["points"].__len__()' < "$SVC_BODY")" = 1 ] || ok=1
	check d_series_of_one_machine_only $ok "$(head -c 300 "$SVC_BODY")"
	code=$(svc_req GET "/v1/benchmarks/series?suite=reduced&figure=speed/relative_step_cost" "$user")
	[ "$code" = 400 ] && [ "$(json '["error"]["field"]' < "$SVC_BODY")" = machine ]
	check d_timing_series_needs_a_machine $? "$code $(head -c 300 "$SVC_BODY")"
	nightly compare2 compare "$run1" "$one"
	grep -q "^speed/relative_step_cost .*not compared: machines differ" "$SVC_TMP/compare2.out" &&
		grep -q "their timing figures are not compared" "$SVC_TMP/compare2.out"
	check d_compare_refuses_two_machines $(( rc != 0 || $? != 0 )) "$(head -12 "$SVC_TMP/compare2.out")"
	stop_worker "$wOne"
else
	echo "INFO d skipped: one processor, so no second fingerprint by taskset"
fi

# ---- bad input ----------------------------------------------------------------------------------------
bad_post() { # NAME BODY WANT-STATUS WANT-FIELD
	local code
	code=$(svc_req POST /v1/benchmarks "$user" -H 'Content-Type: application/json' --data-binary "$2")
	[ "$code" = "$3" ] && [ "$(json '["error"]["field"]' < "$SVC_BODY")" = "$4" ]
	check "bad_plan_$1" $? "got $code $(head -c 300 "$SVC_BODY")"
}
job=$(python3 -c "import json,sys; r=json.load(open(sys.argv[1])); print(r['cases'][0]['jobs'][0])" "$SVC_TMP/run-$run1.json")
case_ok='{"name": "t", "jobs": ['$job'], "figures": [{"kind": "steps", "check": "none"}]}'
bad_post no_suite '{"label": "x", "commit": "c", "cases": ['"$case_ok"']}' 422 /suite
bad_post bad_label '{"suite": "s", "label": "a b", "commit": "c", "cases": ['"$case_ok"']}' 422 /label
bad_post unknown_key '{"suite": "s", "label": "'"$label"'", "commit": "c", "cases": ['"$case_ok"'], "x": 1}' 422 /x
bad_post bad_alpha '{"suite": "s", "label": "'"$label"'", "commit": "c", "settings": {"alpha": 2}, "cases": ['"$case_ok"']}' 422 /settings/alpha
bad_post no_cases '{"suite": "s", "label": "'"$label"'", "commit": "c", "cases": []}' 422 /cases
bad_post unknown_figure '{"suite": "s", "label": "'"$label"'", "commit": "c", "cases": [{"name": "t", "jobs": ['$job'], "figures": [{"kind": "speed", "check": "none"}]}]}' 422 /cases/0/figures/0/kind
bad_post history_of_accuracy '{"suite": "s", "label": "'"$label"'", "commit": "c", "cases": [{"name": "t", "jobs": ['$job'], "figures": [{"kind": "terzaghi_rms", "check": "history"}]}]}' 422 /cases/0/figures/0/check
bad_post band_reversed '{"suite": "s", "label": "'"$label"'", "commit": "c", "cases": [{"name": "t", "jobs": ['$job'], "figures": [{"kind": "steps", "check": "band", "band": [2, 1]}]}]}' 422 /cases/0/figures/0/band
bad_post foreign_label '{"suite": "s", "label": "other-label", "commit": "c", "cases": ['"$case_ok"']}' 422 /cases/0/jobs/0
bad_post missing_job '{"suite": "s", "label": "'"$label"'", "commit": "c", "cases": [{"name": "t", "jobs": [999999], "figures": [{"kind": "steps", "check": "none"}]}]}' 422 /cases/0/jobs/0
bad_post no_jobs_no_reason '{"suite": "s", "label": "x1", "commit": "c", "cases": [{"name": "t", "jobs": [], "figures": [{"kind": "steps", "check": "none"}]}]}' 422 /cases/0/error
bad_post label_taken '{"suite": "s", "label": "'"$label"'", "commit": "c", "cases": ['"$case_ok"']}' 409 /label
code=$(svc_req POST /v1/benchmarks "$other" -H 'Content-Type: application/json' \
	--data-binary '{"suite": "s", "label": "'"$label"'", "commit": "c", "cases": ['"$case_ok"']}')
[ "$code" = 422 ] && [ "$(json '["error"]["field"]' < "$SVC_BODY")" = /cases/0/jobs/0 ]
check bad_plan_another_users_job $? "got $code $(head -c 300 "$SVC_BODY")"
code=$(svc_req POST /v1/benchmarks "$pool" -H 'Content-Type: application/json' --data-binary '{}')
check bad_plan_worker_token_forbidden $([ "$code" = 403 ]; echo $?) "got $code"

# a run whose job has not ended cannot finish; another user may not finish it
code=$(svc_req POST /v1/jobs "$user" -H 'Content-Type: application/json' \
	--data-binary '{"case": '"$(cat tests/cases/terzaghi.json)"', "batch": "pending-run"}')
pending=$(json '["id"]' < "$SVC_BODY")
code=$(svc_req POST /v1/benchmarks "$user" -H 'Content-Type: application/json' --data-binary \
	'{"suite": "reduced", "label": "pending-run", "commit": "c", "cases": [{"name": "t", "jobs": ['"$pending"'], "figures": [{"kind": "steps", "check": "none"}]}]}')
open_run=$(json '["id"]' < "$SVC_BODY")
check open_run_created $([ "$code" = 201 ]; echo $?) "got $code $(head -c 300 "$SVC_BODY")"
code=$(svc_req POST "/v1/benchmarks/$open_run/finish" "$user")
[ "$code" = 409 ] && [ "$(json '["error"]["code"]' < "$SVC_BODY")" = not_finished ] && grep -q "$pending" "$SVC_BODY"
check finish_refused_while_jobs_run $? "got $code $(head -c 300 "$SVC_BODY")"
code=$(svc_req GET "/v1/benchmarks/$open_run" "$user")
[ "$code" = 200 ] && [ "$(json '["progress"]["jobs"]' < "$SVC_BODY")" = 1 ] && [ "$(json '["jobs"][0]["state"]' < "$SVC_BODY")" = queued ]
check running_run_shows_its_jobs $? "got $code $(head -c 300 "$SVC_BODY")"
code=$(svc_req POST "/v1/benchmarks/$open_run/finish" "$other")
check finish_by_another_user_forbidden $([ "$code" = 403 ]; echo $?) "got $code $(head -c 200 "$SVC_BODY")"
svc_req POST "/v1/jobs/$pending/cancel" "$user" > /dev/null
code=$(svc_req POST "/v1/benchmarks/$open_run/finish" "$user" -H 'Content-Type: application/json' --data-binary '{}')
[ "$code" = 200 ] && [ "$(json '["figures"][0]["status"]' < "$SVC_BODY")" = did_not_run ] && [ "$(json '["state"]' < "$SVC_BODY")" = failed ]
check cancelled_job_did_not_run $? "got $code $(head -c 300 "$SVC_BODY")"
code=$(svc_req POST "/v1/benchmarks/$open_run/finish" "$user")
check finish_again_answers_as_stored $([ "$code" = 200 ] && [ "$(json '["state"]' < "$SVC_BODY")" = failed ]; echo $?) "got $code"
code=$(svc_req POST "/v1/benchmarks/$open_run/finish" "$user" -H 'Content-Type: application/json' --data-binary '{"x": 1}')
check finish_unknown_key_refused $([ "$code" = 422 ]; echo $?) "got $code"

for q in "suite=reduced" "figure=speed/relative_step_cost" "suite=reduced&figure=speed/nothing" \
	"suite=re%20duced&figure=terzaghi/terzaghi_rms" "suite=reduced&figure=terzaghi/terzaghi_rms&limit=0" \
	"suite=reduced&figure=terzaghi/terzaghi_rms&machine=xyz%2F"; do
	code=$(svc_req GET "/v1/benchmarks/series?$q" "$user")
	check "series_bad_query_${q//[^a-z0-9]/_}" $([ "$code" = 400 ]; echo $?) "got $code $(head -c 200 "$SVC_BODY")"
done
code=$(svc_req GET "/v1/benchmarks/series?suite=reduced&figure=terzaghi/terzaghi_rms" "$user")
[ "$code" = 200 ] && [ "$(json '["points"].__len__()' < "$SVC_BODY")" = 3 ] && [ "$(json '["points"][2]["status"]' < "$SVC_BODY")" = regressed ]
check series_of_accuracy_figure_over_runs $? "got $code $(head -c 300 "$SVC_BODY")"
check show_unknown_run_404 $([ "$(svc_req GET /v1/benchmarks/999999 "$user")" = 404 ]; echo $?) "$(head -c 200 "$SVC_BODY")"
check list_bad_limit_400 $([ "$(svc_req GET '/v1/benchmarks?limit=5000' "$user")" = 400 ]; echo $?) "$(head -c 200 "$SVC_BODY")"
check list_bad_suite_400 $([ "$(svc_req GET '/v1/benchmarks?suite=a%20b' "$user")" = 400 ]; echo $?) "$(head -c 200 "$SVC_BODY")"
check list_without_token_401 $([ "$(svc_req GET /v1/benchmarks "")" = 401 ]; echo $?) "$(head -c 200 "$SVC_BODY")"

submit_bad() { # NAME EXTRA-MEMBERS WANT-FIELD
	local code
	code=$(svc_req POST /v1/jobs "$user" -H 'Content-Type: application/json' \
		--data-binary '{"case": '"$(cat tests/cases/terzaghi.json)"', '"$2"'}')
	[ "$code" = 422 ] && [ "$(json '["error"]["field"]' < "$SVC_BODY")" = "$3" ]
	check "submit_$1_refused" $? "got $code $(head -c 200 "$SVC_BODY")"
}
submit_bad bad_batch '"batch": "a/b"' /batch
submit_bad long_batch '"batch": "'"$(printf 'x%.0s' $(seq 129))"'"' /batch
submit_bad exclusive_not_boolean '"exclusive": "yes"' /exclusive
code=$(svc_req POST /v1/worker/claim "$pool" -H 'Content-Type: application/json' \
	--data-binary '{"worker": "w", "exclusive": 1}')
check claim_exclusive_not_boolean_refused $([ "$code" = 422 ] && [ "$(json '["error"]["field"]' < "$SVC_BODY")" = /exclusive ]; echo $?) "got $code"
code=$(svc_req POST /v1/jobs "$user" -H 'Content-Type: application/json' \
	--data-binary '{"case": {"schema": "poro-element/1", "material": {"model": "mohr_coulomb"}, "test": "drained"}}')
[ "$code" = 422 ] && grep -q '/case/confining_pressure' "$SVC_BODY"
check submit_invalid_element_case_lists_problems $? "got $code $(head -c 300 "$SVC_BODY")"

# the suites against schemas/suite.schema.json (Debian's python3-jsonschema), and every case of the
# nightly's bench/suite.json as `poro nightly check` would submit it, valid for the solver
"$PY3" - schemas/suite.schema.json bench/suite.json "$suite" <<'PY' > "$SVC_TMP/py" 2>&1
import json, sys, jsonschema
schema = json.load(open(sys.argv[1]))
jsonschema.Draft202012Validator.check_schema(schema)
for path in sys.argv[2:]:
    jsonschema.validate(json.load(open(path)), schema)
print("ok")
PY
check suites_match_their_schema $? "$(tail -3 "$SVC_TMP/py")"
nightly check check bench/suite.json --out "$SVC_TMP/plan"
ok=0 n=0
for f in "$SVC_TMP"/plan/*.json; do
	"$build/poro-solve" validate "$f" > /dev/null 2> "$SVC_TMP/validate.err" || { ok=1; cat "$SVC_TMP/validate.err"; }
	n=$((n + 1))
done
check nightly_suite_cases_all_valid $(( rc != 0 || ok || n < 20 )) "exit $rc, $n cases: $(head -5 "$SVC_TMP/check.err")"
echo "INFO bench/suite.json: $n cases, $(grep -c exclusive "$SVC_TMP/check.out") timed against history"
# the nightly covers every case of tests/cases/ (each verification case of the three schemes and
# each element test), so a case added there without a place in the suite shows here
python3 - bench/suite.json tests/cases <<'PY' > "$SVC_TMP/py" 2>&1
import glob, json, os, sys
suite = json.load(open(sys.argv[1]))
named = {os.path.normpath(os.path.join(os.path.dirname(sys.argv[1]), c["case"])) for c in suite["cases"]}
files = sorted(glob.glob(os.path.join(sys.argv[2], "*.json")))
missing = [f for f in files if os.path.normpath(f) not in named]
assert not missing, "not in the suite: " + " ".join(missing)
schemes = set()
for f in files:
    case = json.load(open(f))
    if case.get("schema") == "poro-case/1":
        schemes.add(case.get("formulation", {}).get("scheme", "semi_implicit"))
assert schemes == {"semi_implicit", "explicit", "implicit_upU"}, schemes
print("%d case files, schemes %s" % (len(files), " ".join(sorted(schemes))))
PY
check nightly_suite_covers_every_case_file $? "$(tail -2 "$SVC_TMP/py")"
echo "INFO bench/suite.json covers $(tail -1 "$SVC_TMP/py")"

# the CLI: a bad suite is refused before anything is sent, every problem named
cp tests/cases/terzaghi.json "$SVC_TMP/terzaghi.json"
python3 - "$SVC_TMP/bad-suite.json" "$SVC_TMP/terzaghi.json" <<'PY'
import json, sys
json.dump({"schema": "poro-suite/1", "name": "bad suite", "settings": {"alpha": 3},
           "cases": [{"name": "a", "case": "/nonexistent/case.json", "figures": {"terzaghi_rms": {}}},
                     {"name": "b", "case": sys.argv[2], "figures": {}},
                     {"name": "c", "case": sys.argv[2],
                      "figures": {"cpu_us_per_point_step": {"history": True}, "nothing": {}, "steps": {"history": True}}}]},
          open(sys.argv[1], "w"))
PY
jobs_before=$(svc_req GET /v1/jobs "$user" > /dev/null; json '["jobs"][0]["id"]' < "$SVC_BODY")
nightly badsuite run "$SVC_TMP/bad-suite.json"
ok=0
for p in /name /settings/alpha /cases/0/case /cases/1/figures /cases/2/figures/nothing /cases/2/figures/steps /cases/2/repeats; do
	grep -q ": $p: " "$SVC_TMP/badsuite.err" || { ok=1; echo "INFO missing $p"; }
done
jobs_after=$(svc_req GET /v1/jobs "$user" > /dev/null; json '["jobs"][0]["id"]' < "$SVC_BODY")
check cli_bad_suite_lists_every_problem $(( rc != 6 || ok || jobs_before != jobs_after )) \
	"exit $rc: $(cat "$SVC_TMP/badsuite.err")"
printf 'suite: not JSON\n' > "$SVC_TMP/notjson.txt"
nightly notjson run "$SVC_TMP/notjson.txt"
check cli_suite_not_json $(( rc != 6 )) "exit $rc: $(cat "$SVC_TMP/notjson.err")"
nightly onlymissing run "$suite" --only nosuchcase
grep -q "no case named 'nosuchcase'" "$SVC_TMP/onlymissing.err"
check cli_only_unknown_case $(( rc != 6 || $? != 0 )) "exit $rc: $(cat "$SVC_TMP/onlymissing.err")"
for args in "report 1" "show x" "compare 1" "run" "frob" "ls --label x" "run $suite --label a/b" "show 1 --junit x.xml" \
	"check" "show --out x"; do
	# shellcheck disable=SC2086 # the words are arguments
	nightly usage $args
	check "cli_usage_${args//[^a-z0-9]/_}" $(( rc != 2 )) "exit $rc: $(cat "$SVC_TMP/usage.err")"
done
nightly shownone show 999999
check cli_show_unknown_run $(( rc != 5 )) "exit $rc: $(cat "$SVC_TMP/shownone.err")"
nightly showlast show
grep -q "^benchmark run $open_run: " "$SVC_TMP/showlast.out"
check cli_show_defaults_to_latest $(( rc != 9 || $? != 0 )) "exit $rc: $(head -3 "$SVC_TMP/showlast.out")"
nightly lsjson ls --suite reduced --json --limit 2
[ "$(json '["runs"].__len__()' < "$SVC_TMP/lsjson.out")" = 2 ]
check cli_ls_json $(( rc != 0 || $? != 0 )) "exit $rc: $(head -c 300 "$SVC_TMP/lsjson.out")"
PORO_SERVER=http://127.0.0.1:1 "$build/poro" nightly ls > /dev/null 2> "$SVC_TMP/unreach.err"
check cli_server_unreachable $(( $? != 3 )) "$(cat "$SVC_TMP/unreach.err")"
