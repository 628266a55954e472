#!/usr/bin/env bash
# checkpoint_test.sh - a run of the real build/poro-solve killed with SIGKILL after a checkpoint and
# resumed with --resume, as a lost worker's job is (docs/service.md §2 "Checkpoints and resume").
#
# The case is tests/cases/terzaghi.json shortened to 1000 steps, drained on top, with a frame every
# 0.01 s and a checkpoint every 0.02 s of simulated time. The killed run's checkpoint.h5 and
# result.h5 are copied into a fresh directory, as a new worker downloads them, and the run resumes
# there. Oracle: an uninterrupted run of the same case. The resumed run must exit 0; its frames
# must fall at the uninterrupted run's times, those up to the checkpoint still readable; its last
# frame must match to a relative 1e-10 (normwise per field; the first pressure solve after a resume
# factorises afresh, spd_solve.h); every probe series must have exactly the uninterrupted run's
# sample times (so no duplicate and no gap at the resume point) and values within 1e-10.
# Datasets are read with h5dump. Prints "PASS name" / "FAIL name: why". Runs in about 6 s.
#   bash tests/cli/checkpoint_test.sh BUILD_DIR      (from the repository root)
set -u
build=${1:-build}
cd "$(dirname "$0")/../.."
solve="$build/poro-solve"
tmp=$(mktemp -d)
running=""
trap '[ -n "$running" ] && kill -9 "$running" 2>/dev/null; rm -rf "$tmp"' EXIT

check() { # name, condition exit status ($?-style: 0 = holds), why
	if [ "$2" -eq 0 ]; then echo "PASS $1"; else echo "FAIL $1: $3"; fi
}

python3 - tests/cases/terzaghi.json "$tmp/case.json" <<'EOF'
import json, sys
c = json.load(open(sys.argv[1]))
c["time"]["end"] = 0.1
c["output"]["frame_interval"] = 0.01
c["checkpoint"] = {"interval": 0.02}
c["boundaries"]["top"] = {"drainage": "drained"}
json.dump(c, open(sys.argv[2], "w"), indent=1)
EOF

# ---- the oracle: an uninterrupted run ---------------------------------------------------------------

"$solve" run "$tmp/case.json" --out "$tmp/ref" > "$tmp/ref.out" 2> "$tmp/ref.err"
rc=$?
check uninterrupted_run_exits_0 "$rc" "exit $rc: $(head -c 300 "$tmp/ref.err")"
grep -q "^checkpoint step=[0-9]* time=" "$tmp/ref.out"
check run_prints_checkpoint_lines $? "no checkpoint line in: $(head -c 300 "$tmp/ref.out")"

# ---- killed with SIGKILL after its first checkpoint line ---------------------------------------------

"$solve" run "$tmp/case.json" --out "$tmp/killed" > "$tmp/killed.out" 2> "$tmp/killed.err" &
running=$!
for _ in $(seq 400); do
	grep -q "^checkpoint " "$tmp/killed.out" && break
	kill -0 "$running" 2>/dev/null || break
	sleep 0.01
done
kill -9 "$running" 2>/dev/null
wait "$running" 2>/dev/null
rc=$?
running=""
check killed_after_a_checkpoint $(( rc != 137 )) \
	"exit $rc (137 = killed; 0 = finished before the kill), stdout: $(tail -c 300 "$tmp/killed.out")"
[ -f "$tmp/killed/checkpoint.h5" ] && [ ! -e "$tmp/killed/checkpoint.h5.tmp" ]
check checkpoint_file_complete $? "$(ls "$tmp/killed")"

# ---- resumed in a fresh directory from the two files a worker keeps ---------------------------------

mkdir -p "$tmp/resumed"
cp "$tmp/killed/checkpoint.h5" "$tmp/killed/result.h5" "$tmp/resumed/"
"$solve" run "$tmp/case.json" --out "$tmp/resumed" --resume "$tmp/resumed/checkpoint.h5" \
	> "$tmp/resumed.out" 2> "$tmp/resumed.err"
rc=$?
check resumed_run_exits_0 "$rc" "exit $rc: $(head -c 300 "$tmp/resumed.err")"
resumed_step=$(sed -n 's/^resumed from .* at step \([0-9]*\),.*/\1/p' "$tmp/resumed.out")
first_step=$(sed -n 's/^step \([0-9]*\)\/.*/\1/p' "$tmp/resumed.out" | head -1)
[ -n "$resumed_step" ] && [ "$resumed_step" -gt 0 ] && [ -n "$first_step" ] && [ "$first_step" -ge "$resumed_step" ]
check resumed_progress_continues_from_checkpoint $? "resumed at '$resumed_step', first progress step '$first_step'"

# ---- a checkpoint of another case is refused, naming the difference --------------------------------

python3 - "$tmp/case.json" "$tmp/other.json" <<'EOF'
import json, sys
c = json.load(open(sys.argv[1]))
c["materials"][0]["youngs_modulus"] = 1.1e7
json.dump(c, open(sys.argv[2], "w"))
EOF
"$solve" run "$tmp/other.json" --out "$tmp/other" --resume "$tmp/killed/checkpoint.h5" > /dev/null 2> "$tmp/other.err"
rc=$?
grep -q "/materials/0/youngs_modulus" "$tmp/other.err"
check other_case_checkpoint_exits_2_naming_difference $(( rc != 2 || $? != 0 )) \
	"exit $rc: $(head -c 300 "$tmp/other.err")"
"$solve" run "$tmp/case.json" --out "$tmp/x" --checkpoint-wall nonsense > /dev/null 2>&1
rc=$?
check checkpoint_wall_must_be_seconds $(( rc != 2 )) "exit $rc"

# ---- the resumed result against the uninterrupted one -----------------------------------------------

python3 - "$tmp/ref" "$tmp/resumed" "$resumed_step" <<'EOF'
import re, subprocess, sys
ref, res, resumed_step = sys.argv[1], sys.argv[2], int(sys.argv[3] or 0)
TOL = 1e-10

def report(name, ok, why):
    print(("PASS %s" % name) if ok else ("FAIL %s: %s" % (name, why)))

def values(d, path):
    """A dataset's values, read with h5dump in full precision; None when unreadable."""
    p = subprocess.run(["h5dump", "-d", path, "-y", "-w", "0", "-m", "%.17g", d + "/result.h5"],
                       capture_output=True, text=True)
    if p.returncode != 0 or "DATA {" not in p.stdout:
        return None
    body = p.stdout.split("DATA {", 1)[1].split("}", 1)[0]   # attributes follow the data
    return [float(x) for x in body.replace(",", " ").split()]

def frame_times(d):
    xdmf = open(d + "/result.xdmf").read()   # the soil series' times: one per frame
    return [float(t) for t in re.findall(r'<Grid Name="soil" GridType="Uniform">\s*<Time Value="([^"]*)"', xdmf)]

def frame_groups(d):
    p = subprocess.run(["h5ls", d + "/result.h5/frames"], capture_output=True, text=True)
    return [line.split()[0] for line in p.stdout.splitlines() if line.strip()]

def rel(a, b):
    if a is None or b is None or len(a) != len(b) or not b:
        return float("inf")
    scale = max(max(abs(x) for x in b), 1e-300)
    return max(abs(x - y) for x, y in zip(a, b)) / scale

t_ref, t_res = frame_times(ref), frame_times(res)
groups = frame_groups(res)
report("resumed_frames_at_uninterrupted_times", t_ref == t_res and len(groups) == len(t_res),
       "times %s vs %s, %d groups" % (t_res, t_ref, len(groups)))
# the index of frames is cut back with the frames and continued: it lists what the groups hold
i_ref, i_res = values(ref, "/frame_times"), values(res, "/frame_times")
s_ref, s_res = values(ref, "/frame_steps"), values(res, "/frame_steps")
report("resumed_frame_index_as_uninterrupted", i_ref is not None and i_ref == i_res and s_ref == s_res and
       len(i_res) == len(groups), "times %s vs %s, steps %s vs %s" % (i_res, i_ref, s_res, s_ref))

t_ckpt = resumed_step * 1e-4
worst = 0.0
kept = [g for g, t in zip(groups, t_res) if t <= t_ckpt + 0.5e-4]
for g in kept:
    for field in ("soil/x", "soil/stress", "water/pore_pressure"):
        worst = max(worst, rel(values(res, "/frames/%s/%s" % (g, field)), values(ref, "/frames/%s/%s" % (g, field))))
report("frames_before_checkpoint_readable", len(kept) >= 2 and worst <= TOL,
       "%d frames up to t = %g, largest relative difference %.3g" % (len(kept), t_ckpt, worst))

last = groups[-1] if groups else "none"
worst, where = 0.0, ""
for field in ("soil/x", "soil/v", "soil/stress", "soil/porosity", "water/x", "water/v", "water/pore_pressure"):
    d = rel(values(res, "/frames/%s/%s" % (last, field)), values(ref, "/frames/%s/%s" % (last, field)))
    if d > worst or where == "":
        worst, where = d, field
print("INFO final frame of the resumed run: largest relative difference %.3g (%s)" % (worst, where))
report("final_frame_matches_uninterrupted", worst <= TOL, "%.3g in %s" % (worst, where))

for probe in ("pore_pressure_base", "pore_pressure_mid", "settlement_top"):
    tr, ts = values(ref, "/probes/%s/time" % probe), values(res, "/probes/%s/time" % probe)
    vr, vs = values(ref, "/probes/%s/value" % probe), values(res, "/probes/%s/value" % probe)
    increasing = ts is not None and all(b > a for a, b in zip(ts, ts[1:]))
    report("probe_%s_same_samples_no_gap_no_duplicate" % probe,
           ts is not None and ts == tr and increasing and rel(vs, vr) <= TOL,
           "%s samples vs %s, increasing %s, values differ by %.3g" %
           (len(ts) if ts else None, len(tr) if tr else None, increasing, rel(vs, vr)))
EOF
