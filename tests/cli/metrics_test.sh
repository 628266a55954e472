#!/usr/bin/env bash
# metrics_test.sh - the figures a run reports about itself (solver/verify/metrics.h,
# docs/benchmarks.md): poro-solve run writes DIR/metrics.json and result.h5's /metrics, and they
# agree value for value (h5py); a short Terzaghi column asked for terzaghi_rms reports the number
# terzaghi-error prints from the same result.h5 (one figure function, figures.h); an element case
# run by `run` (what the job service's worker does) and by `element` reports peak_q, the Newton
# iterations and its Mohr-Coulomb error within 1e-6 of the closed form, and `run` leaves a
# result.h5 whose probes are an empty set; a run that fails in a step still writes metrics.json,
# with status "failed" and its error; the test knob PORO_DEBUG_SLOWDOWN leaves every frame
# bit-identical (h5diff; the processor time it adds is printed, never asserted) and a bad value is
# refused; an implicit run asked for its Newton iterations reports the total its progress line
# gives as a mean; a figure a case cannot yield (Newton iterations of a scheme that does not
# iterate, Xie-Leo's settlement of a Hencky column), or an unknown one, is refused by validate
# naming /metrics/NAME. The JSON documents are checked against schemas/metrics.schema.json (Debian's
# python3-jsonschema; h5py is Debian's too, so /usr/bin/python3 runs these checks). Prints
# "PASS name" / "FAIL name: why".
#   bash tests/cli/metrics_test.sh BUILD_DIR      (from the repository root)
set -u
cd "$(dirname "$0")/../.."
. tests/cli/lib.sh
cli_setup "${1:-build}"
export OMP_NUM_THREADS=1 OMP_WAIT_POLICY=passive
PY3=/usr/bin/python3   # Debian's, where python3-h5py and python3-jsonschema install

# a Terzaghi column of 500 steps asked for its Terzaghi error and its step in reference-kernel units
derive_case column tests/cases/terzaghi.json \
	'c["time"]["end"] = 0.05; c["output"]["frame_interval"] = 0.025; c["metrics"] = {"terzaghi_rms": True, "relative_step_cost": True}'
run_derived column run_column_with_metrics
"$PY3" - "$tmp/column" schemas/metrics.schema.json <<'PY' > "$tmp/py" 2>&1
import json, math, sys, h5py, jsonschema
d = sys.argv[1]
m = json.load(open(d + "/metrics.json"))
jsonschema.validate(m, json.load(open(sys.argv[2])))
f = m["figures"]
assert m["status"] == "succeeded" and m["kind"] == "simulation", m["status"]
for k in ("wall_seconds", "cpu_seconds", "us_per_point_step", "cpu_us_per_point_step", "steps",
          "max_displacement", "terzaghi_rms"):
    assert k in f, "no " + k
assert f["steps"]["value"] == 500, f["steps"]
assert 0 < f["terzaghi_rms"]["value"] < 0.02, f["terzaghi_rms"]
assert f["cpu_us_per_point_step"]["class"] == "timing" and f["terzaghi_rms"]["class"] == "accuracy"
# the reference kernel was timed beside the steps, and the relative cost is the ratio it says
ref, rel, med = (f[k]["value"] for k in ("reference_kernel_us", "relative_step_cost", "median_cpu_us_per_point_step"))
assert ref > 0 and f["reference_kernel_us"]["unit"] == "us" and f["relative_step_cost"]["unit"] == "1", f
assert abs(rel / (1000 * med / ref) - 1) < 1e-12, (rel, med, ref)
for k in ("cpu_model", "cores", "memory_mb", "kernel", "compiler", "blas", "host"):
    assert m["machine"][k] not in (None, "", 0), "machine " + k
with h5py.File(d + "/result.h5", "r") as h:
    g = h["metrics"]
    assert g.attrs["schema"] == "poro-metrics/1" and g.attrs["status"] == "succeeded"
    assert int(g.attrs["cores"]) == m["machine"]["cores"] and g.attrs["blas"] == m["machine"]["blas"]
    for k, v in f.items():
        assert float(g[k][0]) == v["value"], "%s: %r in result.h5, %r in metrics.json" % (k, g[k][0], v["value"])
        assert g[k].attrs["unit"] == v["unit"], k
print("%.6f" % (100 * f["terzaghi_rms"]["value"]))
PY
check metrics_json_and_hdf5_agree $? "$(tail -3 "$tmp/py")"
rms=$(tail -1 "$tmp/py")
"$build/terzaghi-error" "$tmp/column" > "$tmp/tool" 2>&1
tool=$(sed -n 's/.*error \([0-9.]*\)% of q.*/\1/p' "$tmp/tool")
python3 -c "import sys; sys.exit(0 if abs(float('$tool') - float('$rms')) < 0.006 else 1)" 2>/dev/null
check metrics_terzaghi_rms_is_terzaghi_error $? "metrics.json $rms%, terzaghi-error: $(cat "$tmp/tool")"

# the slowdown knob: the same frames, a slower step
PORO_DEBUG_SLOWDOWN=1.5 "$solve" run "$tmp/column.json" --out "$tmp/slow" > "$tmp/slow.out" 2>&1
rc=$?
h5diff "$tmp/column/result.h5" "$tmp/slow/result.h5" /frames > "$tmp/diff" 2>&1
check slowdown_knob_leaves_results_identical $(( rc != 0 || $? != 0 )) "exit $rc; h5diff: $(head -c 300 "$tmp/diff")"
grep -q "test knob PORO_DEBUG_SLOWDOWN=1.5" "$tmp/slow.out"
check slowdown_knob_says_so $? "$(head -3 "$tmp/slow.out")"
python3 - "$tmp/column/metrics.json" "$tmp/slow/metrics.json" <<'PY'
import json, sys
for k in ("cpu_us_per_point_step", "reference_kernel_us", "relative_step_cost"):
    a, b = (json.load(open(p))["figures"][k]["value"] for p in sys.argv[1:])
    print("INFO slowdown knob 1.5: %s %.4g -> %.4g (x%.2f, printed, not asserted)" % (k, a, b, b / a))
PY
PORO_DEBUG_SLOWDOWN=0.5 "$solve" run "$tmp/column.json" --out "$tmp/bad" > /dev/null 2> "$tmp/err"
rc=$?
grep -q "PORO_DEBUG_SLOWDOWN='0.5' is not a factor" "$tmp/err"
check slowdown_knob_bad_value_refused $(( rc != 2 || $? != 0 )) "exit $rc: $(cat "$tmp/err")"

# an element case, through run (as the worker runs it) and through element
derive_element mc tests/cases/mohr_coulomb_drained.json 'c["metrics"] = {"mohr_coulomb_peak_error": True}'
for how in run element; do
	"$solve" "$how" "$tmp/mc.json" --out "$tmp/mc-$how" > /dev/null 2> "$tmp/err"
	rc=$?
	"$PY3" - "$tmp/mc-$how" "$how" schemas/metrics.schema.json <<'PY' > "$tmp/py" 2>&1
import json, os, sys, jsonschema
d, how = sys.argv[1], sys.argv[2]
m = json.load(open(d + "/metrics.json"))
jsonschema.validate(m, json.load(open(sys.argv[3])))
f = m["figures"]
assert m["kind"] == "element" and m["status"] == "succeeded"
assert f["mohr_coulomb_peak_error"]["value"] < 1e-6, f["mohr_coulomb_peak_error"]
assert f["peak_q"]["value"] > 1e5 and f["steps"]["value"] == 200
assert f["newton_iterations"]["value"] >= 0 and float(f["newton_iterations"]["value"]).is_integer()
assert os.path.exists(d + "/element.csv")
assert os.path.exists(d + "/result.h5") == (how == "run"), "result.h5 only from run"
if how == "run":
    import h5py
    with h5py.File(d + "/result.h5", "r") as h:
        assert float(h["metrics/peak_q"][0]) == f["peak_q"]["value"]
        assert h["run"].attrs["status"] == "succeeded"
PY
	check "element_by_${how}_reports_its_figures" $(( rc != 0 || $? != 0 )) "exit $rc: $(tail -3 "$tmp/py") $(head -c 200 "$tmp/err")"
done
"$solve" probes "$tmp/mc-run/result.h5" --job 3 --attempt 1 > "$tmp/probes" 2> "$tmp/err"
rc=$?
python3 -c "import json,sys; d=json.load(open('$tmp/probes')); sys.exit(0 if d == {'job': 3, 'attempt': 1, 'probes': {}} else 1)" 2>/dev/null
check element_result_has_empty_probes $(( rc != 0 || $? != 0 )) "exit $rc: $(cat "$tmp/probes" "$tmp/err" | head -c 300)"

# a run that fails in a step still says what it measured
derive_case crash tests/cases/terzaghi.json \
	'c["time"]["end"] = 0.05; c["loads"][0]["traction"] = [0.0, -1.0e12]; c["materials"][0]["youngs_modulus"] = 1.0e3'
"$solve" run "$tmp/crash.json" --out "$tmp/crash" > /dev/null 2> "$tmp/err"
rc=$?
python3 - "$tmp/crash/metrics.json" <<'PY' > "$tmp/py" 2>&1
import json, sys
m = json.load(open(sys.argv[1]))
assert m["status"] == "failed" and m["error"], m
assert "wall_seconds" in m["figures"] and "max_displacement" not in m["figures"], sorted(m["figures"])
PY
check failed_run_writes_failed_metrics $(( rc != 3 || $? != 0 )) "exit $rc (want 3): $(tail -2 "$tmp/py") $(head -c 200 "$tmp/err")"

# the implicit scheme's Newton iterations: asked for, the run's total, which poro-solve's progress
# line states as its mean a step; on this yielding footing with the consistent tangent, more than
# one a step (consolidation_001_test e holds the iterations to Newton's quadratic rate)
derive_case footing tests/cases/strip_footing_001.json 'c["grid"]["cell_size"] = 0.5
c["formulation"]["tangent"] = "consistent"
c["loads"][0]["traction"] = [0.0, -600.0]; c["loads"][0]["time_function"]["ramp_time"] = 1.0
c["time"]["end"] = 0.5; c["output"]["frame_interval"] = 0; c["metrics"] = {"newton_iterations": True}'
"$solve" run "$tmp/footing.json" --out "$tmp/footing" > "$tmp/footing.out" 2> "$tmp/err"
rc=$?
"$PY3" - "$tmp/footing/metrics.json" "$tmp/footing.out" schemas/metrics.schema.json <<'PY' > "$tmp/py" 2>&1
import json, re, sys, jsonschema
m = json.load(open(sys.argv[1]))
jsonschema.validate(m, json.load(open(sys.argv[3])))
f = m["figures"]
n, steps = f["newton_iterations"]["value"], f["steps"]["value"]
assert f["newton_iterations"]["class"] == "count" and steps == 10, (f["newton_iterations"], steps)
assert float(n).is_integer() and steps < n <= 100 * steps, (n, steps)
means = re.findall(r"Newton iterations \d+ \(mean ([0-9.]+)\)", open(sys.argv[2]).read())
assert means and abs(float(means[-1]) - n / steps) < 0.006, (means[-1:], n / steps)
print("INFO footing 001, consistent tangent: %d Newton iterations in %d steps" % (n, steps))
PY
check implicit_run_reports_its_newton_iterations $(( rc != 0 || $? != 0 )) "exit $rc: $(tail -3 "$tmp/py") $(head -c 200 "$tmp/err")"
grep '^INFO' "$tmp/py"

# figures a case cannot yield, or does not know
derive_case semi_newton tests/cases/terzaghi.json 'c["metrics"] = {"newton_iterations": True}'
expect_invalid semi_newton /metrics/newton_iterations
derive_case hencky_xie_leo tests/cases/xie_leo_hencky.json 'c["metrics"] = {"xie_leo_settlement": True}'
expect_invalid hencky_xie_leo /metrics/xie_leo_settlement
derive_case slope_terzaghi tests/cases/mc_slope_k1e-3_single_point.json 'c["metrics"] = {"terzaghi_rms": True}'
expect_invalid slope_terzaghi /metrics/terzaghi_rms
derive_case column_runout tests/cases/terzaghi.json 'c["metrics"] = {"runout": True}'
expect_invalid column_runout /metrics/runout
derive_case unknown_figure tests/cases/terzaghi.json 'c["metrics"] = {"terzaghi_rmse": True}'
expect_invalid unknown_figure /metrics/terzaghi_rmse
derive_case not_boolean tests/cases/terzaghi.json 'c["metrics"] = {"terzaghi_rms": 1}'
expect_invalid not_boolean /metrics/terzaghi_rms
derive_element element_sim_figure tests/cases/mohr_coulomb_drained.json 'c["metrics"] = {"terzaghi_rms": True}'
expect_invalid element_sim_figure /metrics/terzaghi_rms "$tmp/element_sim_figure.json"
derive_element undrained_mc tests/cases/mohr_coulomb_undrained.json 'c["metrics"] = {"mohr_coulomb_peak_error": True}'
expect_invalid undrained_mc /metrics/mohr_coulomb_peak_error "$tmp/undrained_mc.json"
