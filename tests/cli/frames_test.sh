#!/usr/bin/env bash
# frames_test.sh - `poro-solve frames` and `probes --frames` (solver/output/frames_export.h,
# docs/web.md "Frames") on real runs of the Terzaghi column, double and single point, shortened to
# 0.01 s with a frame every 0.0025 s, and of a slope (its report's run-out in the index).
#
# Oracle: the run's own result.h5 read with h5py (Debian's python3). Every frame's floats equal
# the file's doubles rounded to 32 bits: x, y, the pore pressure (water points in double point,
# soil points in single point), p' = -(s'xx + s'yy + s'zz) / 3, the plastic strain, |u|; the
# index's ranges are the arrays' minimum and maximum, its offsets and lengths tile frames.bin, its
# frame times are the file's. Bad input: a file that is not a result is exit 2 and leaves no frames
# file; `probes --frames` into a directory that cannot be written still writes the probes (exit 0)
# and says why there are no frames. Prints "PASS name" / "FAIL name: why".
#   bash tests/cli/frames_test.sh BUILD_DIR      (from the repository root)
set -u
cd "$(dirname "$0")/../.."
. tests/cli/lib.sh
cli_setup "${1:-build}"

SHORT='c["time"]["end"] = 0.01; c["output"]["frame_interval"] = 0.0025'
derive_case double tests/cases/terzaghi.json "$SHORT"
derive_case single tests/cases/terzaghi_single_point.json "$SHORT"
for kind in double single; do
	run_derived "$kind" "terzaghi_${kind}_point_run"
	mkdir -p "$tmp/$kind-frames"
	"$solve" frames "$tmp/$kind/result.h5" --out "$tmp/$kind-frames" --job 7 --attempt 2 > "$tmp/$kind.out" 2>&1
	check "frames_${kind}_point_exits_0" $? "$(head -c 300 "$tmp/$kind.out")"
	/usr/bin/python3 - "$tmp/$kind/result.h5" "$tmp/$kind-frames" <<'PY'
import json, os, sys
import h5py
import numpy as np
h5, out = sys.argv[1], sys.argv[2]
idx = json.load(open(out + "/frames.json"))
data = open(out + "/frames.bin", "rb").read()
bad = []
if idx["format"] != "poro-frames/1" or idx["job"] != 7 or idx["attempt"] != 2:
    bad.append("header %s" % {k: idx[k] for k in ("format", "job", "attempt")})
if idx["bin_bytes"] != len(data):
    bad.append("bin_bytes %d, file %d" % (idx["bin_bytes"], len(data)))
with h5py.File(h5, "r") as f:
    names = [n.decode() for n in f["frame_names"][:]]
    if len(names) != len(idx["frames"]):
        bad.append("%d frames in the index, %d in the file" % (len(idx["frames"]), len(names)))
    at = 0
    for n, fr in zip(names, idx["frames"]):
        g = f["frames"][n]
        if fr["offset"] != at:
            bad.append("frame %d at %d, expected %d" % (fr["index"], fr["offset"], at))
        at = fr["offset"] + fr["length"]
        if abs(fr["time"] - g.attrs["time"]) > 1e-12:
            bad.append("frame %d time %r, file %r" % (fr["index"], fr["time"], g.attrs["time"]))
        floats = np.frombuffer(data[fr["offset"]:fr["offset"] + fr["length"]], dtype="<f4")
        k = 0
        seen = {}   # a field's range over every set that carries it, as the index keeps it
        for s, arrays in idx["sets"].items():
            pts = g[s]
            count = fr["counts"][s]
            want = {"x": pts["x"][:, 0], "y": pts["x"][:, 1], "displacement": np.hypot(*pts["displacement"][:].T)}
            if "pore_pressure" in arrays:
                want["pore_pressure"] = pts["pore_pressure"][:]
            if "mean_effective_stress" in arrays:
                st = pts["stress"][:]
                want["mean_effective_stress"] = -(st[:, 0] + st[:, 1] + st[:, 3]) / 3
                want["plastic_strain"] = pts["plastic_strain"][:]
            if count != len(want["x"]):
                bad.append("frame %d %s: %d points, file %d" % (fr["index"], s, count, len(want["x"])))
            for a in arrays:
                got = floats[k:k + count]
                k += count
                if not np.array_equal(got, want[a].astype("<f4")):
                    bad.append("frame %d %s/%s differs from the file's" % (fr["index"], s, a))
                if a in fr["ranges"] and len(want[a]):
                    lo, hi = seen.get(a, (np.inf, -np.inf))
                    seen[a] = (min(lo, want[a].min()), max(hi, want[a].max()))
        for a, (lo, hi) in seen.items():
            r = fr["ranges"][a]
            if r is None or abs(r[0] - lo) > 1e-6 * max(1, abs(lo)) or abs(r[1] - hi) > 1e-6 * max(1, abs(hi)):
                bad.append("frame %d %s range %s, file [%g, %g]" % (fr["index"], a, r, lo, hi))
        if k * 4 != fr["length"]:
            bad.append("frame %d: %d floats, length %d bytes" % (fr["index"], k, fr["length"]))
if bad:
    print("; ".join(bad[:5]))
    sys.exit(1)
PY
	check "frames_${kind}_point_floats_are_the_files" $? "see above"
done
python3 -c 'import json, sys; d = json.load(open(sys.argv[1])); sys.exit(0 if "water" in d["sets"] and "pore_pressure" in d["sets"]["water"] and "pore_pressure" not in d["sets"]["soil"] and d["report"] is None else 1)' "$tmp/double-frames/frames.json"
check frames_double_point_pressure_on_water_points $? "sets $(python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["sets"])' "$tmp/double-frames/frames.json")"
python3 -c 'import json, sys; d = json.load(open(sys.argv[1])); sys.exit(0 if list(d["sets"]) == ["soil"] and "pore_pressure" in d["sets"]["soil"] else 1)' "$tmp/single-frames/frames.json"
check frames_single_point_pressure_on_soil_points $? "sets $(python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["sets"])' "$tmp/single-frames/frames.json")"

# probes --frames: both files beside the probes, the same as frames writes
mkdir -p "$tmp/both"
"$solve" probes "$tmp/double/result.h5" --job 7 --attempt 2 --out "$tmp/both/probes.json" --frames "$tmp/both" > "$tmp/both.out" 2>&1
[ $? = 0 ] && [ -s "$tmp/both/probes.json" ] && cmp -s "$tmp/both/frames.bin" "$tmp/double-frames/frames.bin" &&
	cmp -s "$tmp/both/frames.json" "$tmp/double-frames/frames.json"
check probes_frames_writes_the_same_frames $? "$(head -c 300 "$tmp/both.out")"
"$solve" probes "$tmp/double/result.h5" --job 7 --attempt 2 --out "$tmp/alone.json" --frames "$tmp/no/such/dir" > "$tmp/alone.out" 2>&1
rc=$?
[ "$rc" = 0 ] && [ -s "$tmp/alone.json" ] && grep -q "no frames written in '$tmp/no/such/dir'" "$tmp/alone.out"
check probes_stand_when_frames_cannot_be_written $? "exit $rc: $(head -c 300 "$tmp/alone.out")"

# bad input
mkdir -p "$tmp/bad"
printf 'not hdf5\n' > "$tmp/bad/result.h5"
"$solve" frames "$tmp/bad/result.h5" --out "$tmp/bad" > "$tmp/bad.out" 2>&1
rc=$?
[ "$rc" = 2 ] && [ ! -e "$tmp/bad/frames.bin" ] && [ ! -e "$tmp/bad/frames.json" ] && [ -z "$(ls -A "$tmp/bad" | grep -v '^result.h5$')" ]
check frames_of_non_result_exit_2_no_files $? "exit $rc: $(ls -A "$tmp/bad") $(head -c 300 "$tmp/bad.out")"
"$solve" frames "$tmp/double/result.h5" > "$tmp/noout.out" 2>&1
rc=$?
[ "$rc" = 2 ] && grep -q "missing --out DIR" "$tmp/noout.out"
check frames_without_out_is_usage_error $? "exit $rc: $(head -c 300 "$tmp/noout.out")"

# a slope: its index carries the report's run-out per frame
derive_case slope tests/cases/mc_slope_k1e-3_single_point.json 'c["time"]["end"] = 4 * c["time"]["dt"]; c["output"]["frame_interval"] = 2 * c["time"]["dt"]; c.pop("checkpoint", None)'
run_derived slope slope_run
mkdir -p "$tmp/slope-frames"
"$solve" frames "$tmp/slope/result.h5" --out "$tmp/slope-frames" > "$tmp/slope.out" 2>&1
python3 - "$tmp/slope-frames/frames.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
r = d["report"]
ok = r is not None and len(r["runout"]) == len(d["frames"]) == len(r["time"]) and r["runout"][0] == 0
sys.exit(0 if ok else 1)
PY
check frames_slope_index_has_runout $? "$(head -c 300 "$tmp/slope.out") $(head -c 300 "$tmp/slope-frames/frames.json")"
