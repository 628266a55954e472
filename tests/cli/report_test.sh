#!/usr/bin/env bash
# report_test.sh - drives `poro-solve report` (solver/output/report.h, docs/report.md) on real runs of
# the Terzaghi column (tests/cases/terzaghi.json and its single-point twin, shortened to 0.01 s,
# a frame every 0.005 s) and on bad input.
#
# Oracles: the run's own data read with h5dump, and Terzaghi's closed form.
#   - crest settlement at x = 0.05 (the column's top) against the probe settlement_top, the
#     displacement of the top point nearest x = 0.05, at every frame time: 1-D consolidation
#     settles the whole top row alike;
#   - the line along the column's axis against a brute-force mean of the water points' pore
#     pressures within h, computed here from the frame's datasets, and against Terzaghi's pore
#     pressure (000 Eqs. 84-86) at the sample's depth;
#   - the table's shape: a header, a row per frame, "nan" where a quantity is undefined (the
#     oscillation index before any stress, the pressure pattern index before any pressure, the
#     gap in single point); the pressure pattern index of a column that consolidates in one
#     dimension near 0.
# Bad input: exit 4 for a missing file, exit 2 with the subject named for a file that is not a
# result (text, checkpoint.h5), a rectangle body without --ground, a malformed --line, an unknown
# option, a value that is not a number, --at outside the run; no output file is left behind.
# Prints "PASS name" / "FAIL name: why". Runs in about 2 s.
#   bash tests/cli/report_test.sh BUILD_DIR      (from the repository root)
set -u
cd "$(dirname "$0")/../.."
. tests/cli/lib.sh
cli_setup "${1:-build}"

SHORT='c["time"]["end"] = 0.01; c["output"]["frame_interval"] = 0.005; c["checkpoint"] = {"interval": 0.005}'
derive_case double tests/cases/terzaghi.json "$SHORT"
derive_case single tests/cases/terzaghi_single_point.json "$SHORT"
for kind in double single; do
	run_derived "$kind" "terzaghi_${kind}_point_run"
done

# dump FILE DATASET: the dataset's values, one per line, in $tmp/dump.txt (empty when unreadable)
dump() {
	: > "$tmp/dump.txt"
	h5dump -d "$2" -y -w 0 -m %.17g -o "$tmp/dump.txt" "$1" > /dev/null 2>&1
	tr -s ', ' '\n\n' < "$tmp/dump.txt" | sed '/^$/d'
}

# ---- the report of the double-point run --------------------------------------------------------

run=$tmp/double
"$solve" report "$run/result.h5" --ground 0.5 --crest 0.05 --out "$tmp/table.csv" \
	--line 0.05,0.05,0.05,0.95,19 --line-out "$tmp/line.csv" --at 0.0099 > "$tmp/stdout" 2> "$tmp/err"
rc=$?
check report_exits_0 $rc "exit $rc: $(head -c 300 "$tmp/err")"
grep -q "^report: 3 frames, ground y = 0.5 m, crest x = 0.05 m, tolerance 0.003125 m: " "$tmp/stdout" &&
	grep -q "^line: 19 samples at the frame of t = 0.01 s: " "$tmp/stdout"
check report_summary_names_settings_and_frame $? "stdout: $(head -c 300 "$tmp/stdout")"

dump "$run/result.h5" /probes/settlement_top/time > "$tmp/probe_t.txt"
dump "$run/result.h5" /probes/settlement_top/value > "$tmp/probe_u.txt"
dump "$run/result.h5" /frames/000002/water/x > "$tmp/water_x.txt"
dump "$run/result.h5" /frames/000002/water/pore_pressure > "$tmp/water_p.txt"

python3 - "$tmp" <<'EOF'
import csv, math, sys
tmp = sys.argv[1]
H_CELL = 0.025                       # the case's cell_size: the line's averaging radius
Q, K, E, RHO_W, G, HEIGHT = 1.0e4, 1.0e-3, 1.0e7, 1000.0, 9.81, 1.0   # terzaghi.json, nu = 0
CLOSED_FORM_TOL = 0.01               # of q; measured 0.005, largest 0.25 m below the top (the front at Tv = 0.01)
PATTERN_NONE = 0.01                  # pressure pattern index of a smooth field; the slope's pattern scores 0.3-0.5

def report(name, ok, why):
    print(("PASS %s" % name) if ok else ("FAIL %s: %s" % (name, why)))

def numbers(name):
    return [float(v) for v in open("%s/%s" % (tmp, name)).read().split()]

rows = list(csv.reader(open(tmp + "/table.csv")))
header = ["time", "toe_x", "runout", "front_x", "bulk_front_x", "crest_settlement", "max_gap", "max_gap_x", "oscillation_index",
          "pressure_pattern_index"]
table = [dict(zip(header, map(float, r))) for r in rows[1:]]
report("table_header_and_a_row_per_frame",
       rows[0] == header and [r["time"] for r in table] == [0.0, 0.005, 0.01] and all(len(r) == 10 for r in rows),
       "rows %s" % rows)
report("table_oscillation_nan_before_stress_then_finite",
       math.isnan(table[0]["oscillation_index"]) and all(math.isfinite(r["oscillation_index"]) for r in table[1:]),
       [r["oscillation_index"] for r in table])
# the column's pore pressure consolidates as in one dimension: nothing varies along x, no pattern
report("table_pressure_pattern_nan_before_pressure_then_none",
       math.isnan(table[0]["pressure_pattern_index"]) and
       all(0.0 <= r["pressure_pattern_index"] < PATTERN_NONE for r in table[1:]),
       [r["pressure_pattern_index"] for r in table])
report("table_gap_finite_in_double_point", all(math.isfinite(r["max_gap"]) for r in table),
       [r["max_gap"] for r in table])

# crest settlement against the probe at the frame times (samples are every step)
t, u = numbers("probe_t.txt"), numbers("probe_u.txt")
worst, ok = 0.0, len(t) == len(u) and len(t) > 0
for r in table:
    k = min(range(len(t)), key=lambda i: abs(t[i] - r["time"])) if ok else 0
    ok = ok and abs(t[k] - r["time"]) < 1e-9
    worst = max(worst, abs(r["crest_settlement"] + u[k]) if ok else math.inf)
settled = table[-1]["crest_settlement"]
print("INFO terzaghi crest settlement at t = 0.01 s: %.6e m, largest difference to the probe %.2e m" % (settled, worst))
report("crest_settlement_equals_top_probe", ok and settled > 1e-6 and worst <= 1e-12,
       "settlement %g, worst difference %g" % (settled, worst))

# the line against a brute-force mean of the water points and against Terzaghi
x, p = numbers("water_x.txt"), numbers("water_p.txt")
line = [dict(zip(["distance", "x", "y", "pore_pressure", "points"], map(float, r)))
        for r in list(csv.reader(open(tmp + "/line.csv")))[1:]]
brute_ok, worst_brute = len(line) == 19 and 2 * len(p) == len(x), 0.0
for s in line:
    near = [p[i] for i in range(len(p)) if math.hypot(x[2 * i] - s["x"], x[2 * i + 1] - s["y"]) <= H_CELL]
    brute_ok = brute_ok and len(near) == s["points"] and len(near) > 0
    if near:
        worst_brute = max(worst_brute, abs(sum(near) / len(near) - s["pore_pressure"]) / Q)
report("line_equals_brute_force_mean_of_water_points", brute_ok and worst_brute < 1e-12,
       "%d samples, worst %.3g of q" % (len(line), worst_brute))

mv = 1.0 / E
Tv = K / (RHO_W * G * mv) * 0.01 / HEIGHT ** 2
def terzaghi(z):
    return Q * sum(2.0 / M * math.sin(M * z / HEIGHT) * math.exp(-M * M * Tv)
                   for M in ((m + 0.5) * math.pi for m in range(400)))
worst_cf = max(abs(s["pore_pressure"] - terzaghi(HEIGHT - s["y"])) / Q for s in line) if line else math.inf
print("INFO terzaghi line at t = 0.01 s (Tv = %.4f): largest difference to the closed form %.4f of q" % (Tv, worst_cf))
report("line_follows_terzaghi_closed_form", worst_cf < CLOSED_FORM_TOL, "%.4f of q" % worst_cf)
report("line_distance_and_positions",
       all(abs(s["distance"] - 0.05 * k) < 1e-12 and s["x"] == 0.05 and abs(s["y"] - 0.05 - 0.05 * k) < 1e-12
           for k, s in enumerate(line)), line[:2])
EOF

# ---- single point: the table to stdout, no gap, the line on the soil points ----------------------

"$solve" report "$tmp/single/result.h5" --ground 0.5 --crest 0.05 > "$tmp/single.csv" 2> "$tmp/err"
rc=$?
[ "$rc" -eq 0 ] && [ "$(wc -l < "$tmp/single.csv")" -eq 4 ] &&
	head -1 "$tmp/single.csv" | grep -qx "time,toe_x,runout,front_x,bulk_front_x,crest_settlement,max_gap,max_gap_x,oscillation_index,pressure_pattern_index" &&
	[ "$(cut -d, -f7,8 "$tmp/single.csv" | sort -u)" = "$(printf 'max_gap,max_gap_x\nnan,nan')" ]
check single_point_table_to_stdout_gap_nan $? "exit $rc: $(head -c 400 "$tmp/single.csv") $(head -c 200 "$tmp/err")"
"$solve" report "$tmp/single/result.h5" --ground 0.5 --crest 0.05 --line 0.05,0.3,0.05,0.7,3 \
	--line-out "$tmp/single_line.csv" > /dev/null 2> "$tmp/err"
rc=$?
[ "$rc" -eq 0 ] && [ "$(cut -d, -f5 "$tmp/single_line.csv" | sed 1d | sort -u)" = 12 ]
check single_point_line_uses_soil_points $? "exit $rc: $(cat "$tmp/single_line.csv") $(head -c 200 "$tmp/err")"

# ---- bad input ---------------------------------------------------------------------------------

# refused CODE NAME TEXT ARGS...: report ARGS exits CODE and its stderr holds TEXT; no --out file
refused() {
	local code=$1 name=$2 text=$3 rc
	shift 3
	rm -f "$tmp/refused.csv"
	"$solve" report "$@" > /dev/null 2> "$tmp/err"
	rc=$?
	grep -qF -- "$text" "$tmp/err" && [ "$rc" -eq "$code" ] && [ ! -e "$tmp/refused.csv" ]
	check "$name" $? "exit $rc (want $code), stderr: $(head -c 300 "$tmp/err")"
}
good=(--ground 0.5 --crest 0.05 --out "$tmp/refused.csv")
printf 'time,toe_x\n0,1\n' > "$tmp/text.h5"
refused 4 missing_file_exits_4_naming_it "'$tmp/absent.h5'" "$tmp/absent.h5" "${good[@]}"
refused 2 text_file_exits_2_not_a_result_file "'$tmp/text.h5' is not a result file" "$tmp/text.h5" "${good[@]}"
refused 2 checkpoint_exits_2_not_a_result_file "'$run/checkpoint.h5' is not a result file" "$run/checkpoint.h5" \
	"${good[@]}"
refused 2 rectangle_body_without_ground_exits_2 "body 'column' is a rectangle" "$run/result.h5" \
	--out "$tmp/refused.csv"
refused 2 malformed_line_exits_2_naming_it "malformed line '0,1,2'" "$run/result.h5" "${good[@]}" \
	--line 0,1,2 --line-out "$tmp/l.csv"
refused 2 unknown_option_exits_2_naming_it "unrecognized option '--frobnicate'" "$run/result.h5" "${good[@]}" \
	--frobnicate 1
refused 2 ground_not_a_number_exits_2 "--ground: 'five' is not a number" "$run/result.h5" --ground five --crest 0.05
refused 2 at_outside_run_exits_2 "time 5 s is outside the run" "$run/result.h5" "${good[@]}" \
	--line 0,0.1,0.1,0.1 --line-out "$tmp/refused.csv" --at 5
refused 2 line_without_line_out_exits_2 "--line-out" "$run/result.h5" "${good[@]}" --line 0,0.1,0.1,0.1
refused 2 at_without_line_exits_2 "no --line for '--at'" "$run/result.h5" "${good[@]}" --at 0.005
refused 4 unwritable_out_exits_4 "cannot create '$tmp/no/dir.csv'" "$run/result.h5" --ground 0.5 --crest 0.05 \
	--out "$tmp/no/dir.csv"
