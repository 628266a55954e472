#!/usr/bin/env bash
# fuzz/run.sh FUZZ_BUILD BUILD SECONDS [TARGET...] - runs each libFuzzer target of fuzz/ for SECONDS
# (make fuzz; docs/hardening.md "Fuzzing"), then prints one line per target: executions, edges
# covered (cov), features (ft), corpus, crashes, CPU seconds.
#
# Corpora: FUZZ_BUILD/corpus/TARGET keeps what each run found, so a later run goes on from there;
# seeds are laid out afresh in FUZZ_BUILD/seeds/TARGET from the repository: tests/cases/*.json
# (case, json_scan), fuzz/http/*.http (http, request_head; the requests of the API tests), the
# submissions of every test case (http), and result.h5 and checkpoint.h5 files that BUILD's
# poro-solve writes for tests/fault/tiny_column.json (results, checkpoint).
# A crash, a hang (-timeout), a leak or a run over the memory limit leaves its input in
# FUZZ_BUILD/crashes/TARGET/ and makes the exit status 1, except the faults of Debian's libhdf5 on
# damaged files (results, checkpoint: listed as "libhdf5", see triage); reproduce one with
#     FUZZ_BUILD/fuzz/TARGET_fuzz FILE
# FUZZ_JOBS (default 1) targets run at once, each at nice 10: the machine may be shared.
set -u
fb=$1 build=$2 seconds=$3
shift 3
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(case json_scan request_head http results checkpoint)
cd "$(dirname "$0")/.."
fb_abs=$(cd "$fb" && pwd)
jobs=${FUZZ_JOBS:-1}

seeds() {
	local t=$1 d="$fb/seeds/$1"
	rm -rf "$d" && mkdir -p "$d" "$fb/corpus/$t" "$fb/crashes/$t"
	case $t in
	case | json_scan) cp tests/cases/*.json tests/fault/tiny_column.json "$d/" ;;
	request_head) cp fuzz/http/*.http "$d/" ;;
	http)
		cp fuzz/http/*.http "$d/"
		# every test case as a submission, as the API tests send them
		python3 - "$d" tests/cases/*.json tests/fault/tiny_column.json <<'PY'
import json, os, sys
for path in sys.argv[2:]:
    body = json.dumps({"case": json.load(open(path)), "priority": 1}, separators=(",", ":")).encode()
    head = ("POST /v1/jobs HTTP/1.1\r\nHost: 127.0.0.1\r\nAuthorization: Bearer @U@\r\n"
            "Content-Type: application/json\r\nContent-Length: %d\r\n\r\n" % len(body)).encode()
    name = os.path.join(sys.argv[1], "submit-" + os.path.basename(path)[:-5] + ".http")
    open(name, "wb").write(head + body)
PY
		;;
	results | checkpoint)
		local run="$fb/seeds/tiny-run"
		if [ ! -f "$run/result.h5" ]; then
			rm -rf "$run"
			"$build/poro-solve" run tests/fault/tiny_column.json --out "$run" > /dev/null ||
				{ echo "fuzz: $build/poro-solve cannot run tests/fault/tiny_column.json" >&2; return 1; }
		fi
		if [ "$t" = results ]; then
			# h5repack drops the unused space the writer reserves: a smaller file mutates faster
			h5repack "$run/result.h5" "$d/result.h5" 2> /dev/null || cp "$run/result.h5" "$d/"
			cp "$run/result.xdmf" "$d/../result.xdmf" 2> /dev/null
		else
			cp "$run/checkpoint.h5" "$d/"
		fi
		;;
	esac
}

# The case keys of the schema, for the case target's mutations.
python3 - schemas/case.schema.json > "$fb/case.dict" <<'PY'
import json, sys
keys = set()
def walk(v):
    if isinstance(v, dict):
        for k, x in v.get("properties", {}).items():
            keys.add(k)
        for x in v.values():
            walk(x)
        for e in v.get("enum", []) if isinstance(v.get("enum"), list) else []:
            if isinstance(e, str):
                keys.add(e)
    elif isinstance(v, list):
        for x in v:
            walk(x)
walk(json.load(open(sys.argv[1])))
for k in sorted(keys):
    print('"\\"%s\\""' % k.replace('\\', '\\\\').replace('"', '\\"'))
PY

options() {
	case $1 in
	case) echo "-dict=$fb/case.dict -max_len=16384" ;;
	json_scan) echo "-max_len=8192" ;;
	request_head) echo "-max_len=20000" ;;
	http) echo "-close_fd_mask=3 -max_len=8192 -timeout=60" ;;
	# Damaged HDF5 files crash or hang Debian's libhdf5 itself (docs/hardening.md): these two run
	# in fork mode, which goes on after a crash or a hang and keeps each input; triage() then says
	# whether the fault lies in libhdf5 or in PoroMPM's code.
	results) echo "-close_fd_mask=3 -rss_limit_mb=4096 -timeout=10 $FORK" ;;
	checkpoint) echo "-close_fd_mask=3 -timeout=10 $FORK" ;;
	esac
}

FORK="-fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1"

# triage TARGET FILE: "libhdf5" when the input's fault (crash, hang or leak) happens inside
# libhdf5: the first frame of the report that lies in libhdf5 or in a source file comes before any
# of PoroMPM's (the sanitizers' interceptors, such as malloc, have no source file); "not
# reproduced" when the input runs clean (fork mode records a child that something outside killed,
# with an empty input); else "poro" (a fault in PoroMPM's code, to be fixed).
triage() {
	local out status
	out=$(FUZZ_CASE="$PWD/tests/fault/tiny_column.json" ASAN_OPTIONS=fast_unwind_on_malloc=0 timeout 120 \
		"$fb/fuzz/${1}_fuzz" -timeout=10 -close_fd_mask=3 "$2" 2>&1)
	status=$?
	[ "$status" -eq 0 ] && { echo "not reproduced"; return; }
	out=$(grep -E '^ +#[0-9]+ 0x' <<< "$out" | grep -E 'libhdf5|\.c:[0-9]+' | grep -vE 'compiler-rt|sanitizer_common|/fuzzer/' | head -1)
	case $out in *libhdf5*) echo libhdf5 ;; *) echo poro ;; esac
}

run_target() {
	local t=$1 log="$fb/logs/$1.log" start end
	seeds "$t" || { echo "$t: no seeds" > "$fb/logs/$t.summary"; return; }
	# shellcheck disable=SC2046
	FUZZ_CASE="$PWD/tests/fault/tiny_column.json" /usr/bin/time -f '%U %S' -o "$fb/logs/$t.cpu" \
		nice -n 10 "$fb/fuzz/${t}_fuzz" $(options "$t") -max_total_time="$seconds" -print_final_stats=1 \
		-artifact_prefix="$fb_abs/crashes/$t/" "$fb/corpus/$t" "$fb/seeds/$t" > "$log" 2>&1
	local status=$?
	local done_line cpu crashes
	done_line=$(grep -E '^#[0-9]+[[:space:]]+DONE|^#[0-9]+: cov:' "$log" | tail -1)
	cpu=$(tail -1 "$fb/logs/$t.cpu" 2> /dev/null | awk '{ printf "%.0f", $1 + $2 }')
	crashes=$(find "$fb/crashes/$t" -type f | wc -l)
	local runs cov ft corp
	runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
	[ -n "$runs" ] || runs=$(sed -n 's/^#\([0-9]*\): cov:.*/\1/p' <<< "$done_line")
	cov=$(sed -n 's/.* cov: \([0-9]*\).*/\1/p' <<< "$done_line")
	ft=$(sed -n 's/.* ft: \([0-9]*\).*/\1/p' <<< "$done_line")
	corp=$(sed -n 's/.* corp: \([^ ]*\).*/\1/p' <<< "$done_line")
	printf '%-13s runs %-10s cov %-6s ft %-6s corpus %-14s crashes %-3s cpu_s %-6s exit %s\n' "$t" "${runs:-?}" \
		"${cov:-?}" "${ft:-?}" "${corp:-?}" "$crashes" "${cpu:-?}" "$status" > "$fb/logs/$t.summary"
}

mkdir -p "$fb/logs"
if [ "$(cat "$fb/jansson/link" 2> /dev/null)" = -ljansson ]; then
	echo "fuzz: INFO jansson is Debian's uninstrumented library: its parser is invisible to the fuzzers"
fi
running=0
for t in "${targets[@]}"; do
	[ -x "$fb/fuzz/${t}_fuzz" ] || { echo "fuzz: no target '$t'" >&2; exit 2; }
	echo "fuzz: $t for $seconds s (log $fb/logs/$t.log)"
	run_target "$t" &
	running=$((running + 1))
	if [ "$running" -ge "$jobs" ]; then wait -n; running=$((running - 1)); fi
done
wait
failed=0
for t in "${targets[@]}"; do
	cat "$fb/logs/$t.summary"
	for f in $(find "$fb/crashes/$t" -type f); do
		where=$(triage "$t" "$f")
		echo "  found ($where): $f"
		[ "$where" = poro ] && failed=1
	done
done
[ "$failed" -eq 0 ] && echo "fuzz: no crash, hang or leak in PoroMPM's code" || echo "fuzz: findings above; each input reproduces with FUZZ_BUILD/fuzz/TARGET_fuzz FILE"
exit "$failed"
