#!/usr/bin/env bash
# paraview_test.sh - result.xdmf read by ParaView's own XDMF readers (Debian's python3-paraview:
# "XDMF Reader" and "Xdmf3 Reader T"), on short runs of the Terzaghi column, double and single point
# (tests/cases/terzaghi.json, terzaghi_single_point.json: dt 1e-4 s, frames every 3 steps, whose
# times 3e-4, 6e-4, 9e-4 s are each a hair above their decimal values in binary).
#
# Oracles: result.h5 itself (h5dump): the point count of every set at every frame, and the frame
# index /frame_times, /frame_steps. Checked, per reader:
#   - one block per point set at every frame, in the same place, with the same name at every frame
#     ("soil", "water": XDMF Reader; Xdmf3 Reader T leaves collection blocks unnamed, so the check
#     there is that the name does not change; single point's one set reads as a lone dataset);
#   - each block's point count is that frame's in result.h5;
#   - the readers' times are the frames' decimal times (3e-4, not 3.0000000000000003e-4, which
#     a user asking for t = 3e-4 did not get), equal to /frame_times to 1e-15 relative;
#   - double point: the soil block has no pore_pressure (the water points carry it), the water
#     block has; single point: the soil block has it.
# Prints "PASS name" / "FAIL name: why". Runs in about 15 s.
#   bash tests/cli/paraview_test.sh BUILD_DIR      (from the repository root)
set -u
cd "$(dirname "$0")/../.."
. tests/cli/lib.sh
cli_setup "${1:-build}"

PV_PYTHON=/usr/bin/python3   # Debian's, where python3-paraview installs
SHORT='c["time"]["end"] = 0.0009; c["output"]["frame_interval"] = 0.0003'
derive_case double tests/cases/terzaghi.json "$SHORT"
derive_case single tests/cases/terzaghi_single_point.json "$SHORT"
for kind in double single; do
	run_derived "$kind" "terzaghi_${kind}_point_run"
	"$PV_PYTHON" tests/cli/xdmf_read.py "$tmp/$kind/result.xdmf" > "$tmp/$kind.read.json" 2> "$tmp/$kind.read.err"
	rc=$?
	check "paraview_reads_${kind}_point_result" $rc "exit $rc: $(tail -c 400 "$tmp/$kind.read.err")"
	for f in frame_times frame_steps; do
		h5dump -d "/$f" -y -w 0 -m %.17g -o "$tmp/$kind.$f.txt" "$tmp/$kind/result.h5" > /dev/null 2>&1
	done
	: > "$tmp/$kind.counts.txt"
	for frame in 000000 000001 000002 000003; do
		for set in soil water; do
			n=$(h5ls "$tmp/$kind/result.h5/frames/$frame/$set/x" 2>/dev/null | sed -n 's/.*{\([0-9]*\), 2}.*/\1/p')
			echo "$frame $set ${n:--1}" >> "$tmp/$kind.counts.txt"
		done
	done
done

"$PV_PYTHON" - "$tmp" <<'PY'
import json, sys
tmp = sys.argv[1]

def check(name, ok, why):
    print(("PASS %s" % name) if ok else ("FAIL %s: %s" % (name, why)))

def numbers(path):
    return [float(v) for v in open(path).read().replace(",", " ").split()]

for kind in ("double", "single"):
    try:
        read = json.load(open("%s/%s.read.json" % (tmp, kind)))
    except (OSError, ValueError) as e:
        check("%s_point_readers_output" % kind, False, str(e))
        continue
    times, steps = numbers("%s/%s.frame_times.txt" % (tmp, kind)), numbers("%s/%s.frame_steps.txt" % (tmp, kind))
    counts = {}
    for line in open("%s/%s.counts.txt" % (tmp, kind)):
        frame, s, n = line.split()
        if int(n) >= 0:
            counts.setdefault(int(frame), {})[s] = int(n)
    sets = ["soil", "water"] if kind == "double" else ["soil"]
    check("%s_point_frame_index" % kind, steps == [0, 3, 6, 9] and len(times) == 4,
          "steps %s times %s" % (steps, times))
    for reader, frames in sorted(read.items()):
        label = "%s_point_%s" % (kind, reader)
        check(label + "_lists_every_frame", len(frames) == len(times), "%d frames, /frame_times has %d" % (len(frames), len(times)))
        decimal = [float("%.15g" % t) for t in times]
        check(label + "_times_are_the_frames_decimal_times",
              [f["time"] for f in frames] == decimal and all(abs(a - b) <= 1e-15 * max(b, 1e-300) for a, b in zip(decimal, times)),
              "reader %s, /frame_times %r" % ([f["time"] for f in frames], times))
        first = [b["name"] for b in frames[0]["blocks"]] if frames else []
        names_ok = all([b["name"] for b in f["blocks"]] == first for f in frames)
        if reader == "xdmf2" and kind == "double":
            names_ok = names_ok and first == sets   # a single set is read as a lone, unnamed dataset
        check(label + "_block_names_the_same_at_every_frame", names_ok,
              "names per frame: %s" % [[b["name"] for b in f["blocks"]] for f in frames])
        count_ok = all(len(f["blocks"]) == len(sets) and
                       all(b["points"] == counts[k][s] for b, s in zip(f["blocks"], sets)) for k, f in enumerate(frames))
        check(label + "_point_counts_match_result_h5", count_ok,
              "reader %s, result.h5 %s" % ([[b["points"] for b in f["blocks"]] for f in frames], counts))
        arrays = frames[0]["blocks"] if frames else []
        if kind == "double":
            ok = len(arrays) == 2 and "pore_pressure" not in arrays[0]["arrays"] and "pore_pressure" in arrays[1]["arrays"]
        else:
            ok = len(arrays) == 1 and "pore_pressure" in arrays[0]["arrays"]
        check(label + "_pore_pressure_on_the_points_that_carry_it", ok, "arrays %s" % [a["arrays"] for a in arrays])
PY
