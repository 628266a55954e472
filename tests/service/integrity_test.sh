#!/usr/bin/env bash
# integrity_test.sh - what the service does with damaged, missing and refused result files, with a
# real poro-server, poro-worker, poro-solve and poro on 127.0.0.1:
#   - a result.h5 with four changed bytes (the length of one string in HDF5's global heap, which
#     makes libhdf5 read far past it) uploaded with a worker token: GET /v1/jobs/{id}/probes leaves
#     the server alive and answering, before and after a restart (it used to parse result.h5 with
#     libhdf5 in its own process and crash, on every restart); poro-server links no libhdf5;
#   - `poro-solve probes` exits 2 on a file that is no result file and 4 on one it cannot open;
#   - probes come from a real worker: it runs `poro-solve probes` on each result.h5 it uploads and
#     uploads probes.json, which GET probes serves byte for byte; a worker whose solver leaves a
#     damaged result.h5 loses the probes (the extraction dies in its own process), not the job;
#   - an uploaded probes.json that is not JSON is refused 422 invalid_json_file naming where it fails;
#   - a finish "succeeded" without a stored result.h5, or with a declared checksum that is not the
#     stored one, is 409 artifact_missing and the job stays running;
#   - a result.h5 the server refuses (a --max-upload-bytes below its size) fails the job with a
#     message naming the file and the refusal; `poro submit --wait` exits non-zero and the worker
#     keeps the job directory with result.h5 in it;
#   - stored files damaged on disk: truncated (whole and ranged GET), same size with flipped bytes,
#     and a file above the size hashed before answering (65 MiB): each is an error at once (a JSON
#     500 stored_file_damaged naming the file), or for the large file a download that never
#     completes and then the JSON error; poro fetch prints the server's message and exits non-zero.
#   bash tests/service/integrity_test.sh BUILD_DIR      (from the repository root)
set -u
build=${1:-build}
cd "$(dirname "$0")/../.."
root=$(pwd)
case $build in /*) ;; *) build=$root/$build ;; esac   # workers and the wrapper below run elsewhere
. tests/service/lib.sh
svc_init "$build"
tmp=$SVC_TMP
workers=()
trap 'for w in "${workers[@]}"; do kill -TERM "$w" 2>/dev/null; wait "$w" 2>/dev/null; done; svc_cleanup' EXIT

# a short Terzaghi case: 200 steps, 3 probes, a result.h5 of about 0.9 MB
python3 - tests/cases/terzaghi.json "$tmp/case.json" "$tmp/body.json" <<'EOF'
import json, sys
c = json.load(open(sys.argv[1]))
c["time"]["end"] = 0.02
c["output"]["frame_interval"] = 0.01
json.dump(c, open(sys.argv[2], "w"))
json.dump({"case": c}, open(sys.argv[3], "w"))
EOF
probe_names=$(python3 -c 'import json,sys; print(" ".join(p["name"] for p in json.load(open(sys.argv[1]))["probes"]))' "$tmp/case.json")

# damage.py IN OUT: changes four bytes (the middle of the 8-byte length) of the first unit name
# ("Pa" or "m") in HDF5's global heap collection, so that a reader trusting the length reads far
# past it; exits 1 when the file has no such string
cat > "$tmp/damage.py" <<'EOF'
import struct, sys
b = bytearray(open(sys.argv[1], "rb").read())
pos = b.find(b"GCOL")
end = pos + struct.unpack_from("<Q", b, pos + 8)[0]
p, done = pos + 16, False
while pos >= 0 and p + 16 <= end and not done:
    index, _, _, size = struct.unpack_from("<HHIQ", b, p)
    if index == 0:
        break
    if bytes(b[p + 16:p + 16 + size]) in (b"Pa", b"m"):
        b[p + 10:p + 14] = b"\xff\xff\xff\x7f"
        done = True
    p += 16 + (size + 7) // 8 * 8
open(sys.argv[2], "wb").write(b)
sys.exit(0 if done else 1)
EOF
damage() { python3 "$tmp/damage.py" "$1" "$2"; }
submit() { # TOKEN -> job id of a new job of the short case
	svc_req POST /v1/jobs "$1" -H 'Content-Type: application/json' --data-binary "@$tmp/body.json" > /dev/null
	json '["id"]' < "$SVC_BODY"
}
claim() { # WORKER_TOKEN -> "id attempt" of the claimed job
	svc_req POST /v1/worker/claim "$1" -d '{"worker": "curl:1", "host": "curl", "wait_seconds": 5}' > /dev/null
	echo "$(json '["job"]["id"]' < "$SVC_BODY") $(json '["job"]["attempt"]' < "$SVC_BODY")"
}
put() { # WORKER_TOKEN JOB ATTEMPT NAME FILE [SHA256]: prints the status
	local sha=${6:-$(sha256sum "$5" | cut -d' ' -f1)}
	svc_req PUT "/v1/worker/jobs/$2/files/$4?attempt=$3" "$1" -H "X-Checksum-Sha256: $sha" --data-binary "@$5"
}
field() { svc_req GET "/v1/jobs/$1" "$alice" > /dev/null && json "[\"$2\"]" < "$SVC_BODY"; }
ended() { case $(field "$1" state) in succeeded|failed|cancelled) return 0 ;; esac; return 1; }
alive() { # the current server process runs and answers /healthz ok and a listing
	kill -0 "$SVC_PID" 2>/dev/null && [ "$(svc_req GET /healthz "")" = 200 ] &&
		[ "$(json '["status"]' < "$SVC_BODY")" = ok ] && [ "$(svc_req GET /v1/jobs "$alice")" = 200 ]
}
error_is() { # STATUS WANT_STATUS WANT_CODE
	[ "$1" = "$2" ] && [ "$(json '["error"]["code"]' < "$SVC_BODY")" = "$3" ]
}
start_worker() { # NAME SOLVER [flags...]: a worker of the current server, its log in $tmp/NAME.log
	local name=$1 solver=$2
	shift 2
	"$build/poro-worker" --server "$SVC_URL" --token "$pool" --work "$tmp/work-$name" --solver "$solver" \
		--name "$name" "$@" > "$tmp/$name.log" 2>&1 &
	workers+=($!)
}
stop_workers() {
	for w in "${workers[@]}"; do kill -TERM "$w" 2>/dev/null; wait "$w" 2>/dev/null; done
	workers=()
}

# ---- poro-server has no HDF5 in it ---------------------------------------------------------------
n=$(ldd "$build/poro-server" | grep -c hdf5)
check server_links_no_hdf5 "$([ "$n" -eq 0 ]; echo $?)" "ldd shows $n libhdf5 lines: $(ldd "$build/poro-server" | grep hdf5)"

# ---- a damaged result.h5 uploaded by a worker token ----------------------------------------------
svc_start main --lease-seconds 300 || { echo "FAIL start_main: server did not start"; exit 1; }
alice=$(svc_token main alice user)
pool=$(svc_token main pool worker)
"$build/poro-solve" run "$tmp/case.json" --out "$tmp/local" > /dev/null 2>&1
damage "$tmp/local/result.h5" "$tmp/damaged.h5"
check damaged_copy_made $? "no unit name found in the global heap of $tmp/local/result.h5"
# (in a subshell, whose shell says "Segmentation fault" to /dev/null rather than to the test's output;
# a sanitizer build reports the bad read in libhdf5 and exits 1 instead)
rc=$( { "$build/poro-solve" probes "$tmp/damaged.h5" --job 1 --attempt 1 > /dev/null 2> "$tmp/damaged.err"; echo $?; } 2> /dev/null)
echo "INFO poro-solve probes on the damaged result.h5 exits $rc (128 + signal when libhdf5 crashes)"
[ "$rc" -gt 128 ] || { [ "$rc" -ne 0 ] && grep -q "ERROR: AddressSanitizer" "$tmp/damaged.err"; }
check damaged_result_crashes_an_hdf5_reader $? "poro-solve probes exited $rc, wanted death by a signal"

"$build/poro-solve" probes "$tmp/case.json" --job 1 --attempt 1 --out "$tmp/no.json" 2> "$tmp/no.err"
rc=$?
[ "$rc" = 2 ] && [ ! -e "$tmp/no.json" ] && grep -q "is not a result file" "$tmp/no.err"
check probes_command_refuses_non_result_2 $? "exit $rc, stderr: $(head -2 "$tmp/no.err")"
"$build/poro-solve" probes "$tmp/missing.h5" --job 1 --attempt 1 > /dev/null 2> "$tmp/no.err"
rc=$?
[ "$rc" = 4 ] && grep -q "cannot open '$tmp/missing.h5'" "$tmp/no.err"
check probes_command_missing_file_4 $? "exit $rc, stderr: $(head -2 "$tmp/no.err")"

j1=$(submit "$alice")
read -r cid catt <<< "$(claim "$pool")"
[ "$cid" = "$j1" ] && [ "$(put "$pool" "$cid" "$catt" result.h5 "$tmp/damaged.h5")" = 201 ]
check damaged_result_uploaded $? "claim '$cid' of job '$j1', upload: $(head -c 200 "$SVC_BODY")"
code=$(svc_req GET "/v1/jobs/$j1/probes" "$alice" --max-time 10)
error_is "$code" 404 not_found && grep -q "no probes" "$SVC_BODY"
check probes_without_probes_json_404 $? "status $code: $(head -c 300 "$SVC_BODY")"
alive
check probes_of_damaged_result_server_alive $? "GET probes answered $code; server pid $SVC_PID: $(tail -2 "$tmp/main.err")"

# probes.json is checked as JSON while it streams in
printf '{"job": %s, "attempt": 1, "probes": {"p": {"unit": "Pa", "time": [0, 1], "value": [2.5,, 3]}}}' "$j1" > "$tmp/bad.json"
column=$(python3 -c 'import sys; print(open(sys.argv[1]).read().index(",,") + 2)' "$tmp/bad.json")
code=$(put "$pool" "$cid" "$catt" probes.json "$tmp/bad.json")
error_is "$code" 422 invalid_json_file && grep -q "at line 1 column $column" "$SVC_BODY"
check probes_json_not_json_refused_422 $? "status $code: $(head -c 300 "$SVC_BODY")"
[ ! -e "$SVC_STATE/files/$j1/$catt/probes.json" ] && [ "$(svc_req GET "/v1/jobs/$j1/probes" "$alice")" = 404 ]
check refused_probes_json_not_stored $? "stored: $(ls "$SVC_STATE/files/$j1/$catt")"
printf '[1, 2]' > "$tmp/array.json"
code=$(put "$pool" "$cid" "$catt" probes.json "$tmp/array.json")
error_is "$code" 422 invalid_json_file
check probes_json_not_an_object_refused_422 $? "status $code: $(head -c 300 "$SVC_BODY")"
"$build/poro-solve" probes "$tmp/local/result.h5" --job "$j1" --attempt "$catt" --out "$tmp/local-probes.json"
code=$(put "$pool" "$cid" "$catt" probes.json "$tmp/local-probes.json")
check probes_json_valid_stored_201 "$([ "$code" = 201 ]; echo $?)" "status $code: $(head -c 300 "$SVC_BODY")"
code=$(svc_req GET "/v1/jobs/$j1/probes" "$alice")
[ "$code" = 200 ] && cmp -s "$SVC_BODY" "$tmp/local-probes.json" && svc_header Content-Type | grep -q '^application/json' &&
	[ "$(svc_header X-Checksum-Sha256)" = "$(sha256sum "$tmp/local-probes.json" | cut -d' ' -f1)" ]
check probes_served_as_stored $? "status $code, headers: $(tr -d '\r' < "$SVC_HEADERS" | tr '\n' ' ')"

svc_stop main
svc_start main --lease-seconds 300 || { echo "FAIL restart_main: server did not start"; exit 1; }
code=$(svc_req GET "/v1/jobs/$j1/probes" "$alice" --max-time 10)
[ "$code" = 200 ] && alive
check probes_after_restart_server_alive $? "GET probes answered $code; server: $(tail -2 "$tmp/main.err")"
svc_stop main

# each part below runs on a server of its own, so that it shows its own failure on a server that
# fails another part
svc_start files --lease-seconds 300 || { echo "FAIL start_files: server did not start"; exit 1; }
alice=$(svc_token files alice user)
pool=$(svc_token files pool worker)

# ---- a success needs its result.h5 stored as declared --------------------------------------------
j2=$(submit "$alice")
read -r did datt <<< "$(claim "$pool")"
finish() { # JOB ATTEMPT ARTIFACTS-JSON
	svc_req POST "/v1/worker/jobs/$1/finish" "$pool" -d "{\"attempt\": $2, \"outcome\": \"succeeded\", \"exit_code\": 0, \"artifacts\": $3}"
}
code=$(finish "$did" "$datt" '[]')
error_is "$code" 409 artifact_missing && grep -q "result.h5" "$SVC_BODY" && [ "$(field "$j2" state)" = running ]
check finish_without_result_409 $? "status $code: $(head -c 300 "$SVC_BODY"); job $(field "$j2" state)"
xsha=$(sha256sum "$tmp/local/result.xdmf" | cut -d' ' -f1)
xsize=$(stat -c %s "$tmp/local/result.xdmf")
code=$(finish "$did" "$datt" "[{\"name\": \"result.h5\", \"size\": $xsize, \"sha256\": \"$xsha\"}]")
error_is "$code" 409 artifact_missing && grep -q "never stored" "$SVC_BODY"
check finish_declaring_unstored_result_409 $? "status $code: $(head -c 300 "$SVC_BODY")"
put "$pool" "$did" "$datt" result.h5 "$tmp/local/result.h5" > /dev/null
rsha=$(sha256sum "$tmp/local/result.h5" | cut -d' ' -f1)
rsize=$(stat -c %s "$tmp/local/result.h5")
code=$(finish "$did" "$datt" "[{\"name\": \"result.h5\", \"size\": $rsize, \"sha256\": \"$xsha\"}]")
error_is "$code" 409 artifact_missing && [ "$(json '["error"]["field"]' < "$SVC_BODY")" = /artifacts/0 ] &&
	[ "$(field "$j2" state)" = running ]
check finish_with_wrong_checksum_409 $? "status $code: $(head -c 300 "$SVC_BODY"); job $(field "$j2" state)"
code=$(finish "$did" "$datt" "[{\"name\": \"result.h5\", \"size\": $rsize, \"sha256\": \"$rsha\"}]")
[ "$code" = 200 ] && [ "$(field "$j2" state)" = succeeded ]
check finish_with_stored_result_200 $? "status $code: $(head -c 300 "$SVC_BODY")"

# ---- a real worker: probes.json for each result, served by GET probes ------------------------------
start_worker w1 "$build/poro-solve"
j3=$(submit "$alice")
wait_for 60 ended "$j3"
[ "$(field "$j3" state)" = succeeded ]
check worker_job_succeeds $? "state $(field "$j3" state): $(field "$j3" message)"
svc_req GET "/v1/jobs/$j3/files/result.h5" "$alice" > /dev/null
cp "$SVC_BODY" "$tmp/j3-result.h5"
code=$(svc_req GET "/v1/jobs/$j3/probes" "$alice")
cp "$SVC_BODY" "$tmp/j3-probes.json"
"$build/poro-solve" probes "$tmp/j3-result.h5" --job "$j3" --attempt 1 --out "$tmp/j3-local.json"
[ "$code" = 200 ] && cmp -s "$tmp/j3-probes.json" "$tmp/j3-local.json"
check worker_probes_served $? "status $code: $(head -c 200 "$tmp/j3-probes.json")"
python3 - "$tmp/j3-probes.json" "$j3" "$probe_names" <<'EOF'
import json, sys
try:
    d = json.load(open(sys.argv[1]))
    names = list(d["probes"])
    ok = d["job"] == int(sys.argv[2]) and d["attempt"] == 1 and names == sys.argv[3].split()
    ok = ok and all(len(p["time"]) == len(p["value"]) > 1 for p in d["probes"].values())
    base = d["probes"]["pore_pressure_base"]
    ok = ok and base["unit"] == "Pa" and abs(base["time"][-1] - 0.02) < 1e-9
    why = "job %r attempt %r names %r" % (d.get("job"), d.get("attempt"), names)
except Exception as e:
    ok, why = False, "not the probes document: %r" % e
print("PASS worker_probes_are_the_case_series" if ok else "FAIL worker_probes_are_the_case_series: " + why)
EOF
[ ! -e "$tmp/work-w1/job-$j3-1" ]
check worker_removes_stored_job_dir $? "$tmp/work-w1/job-$j3-1 left behind"

stop_workers

# ---- stored files damaged on disk ------------------------------------------------------------------
stored=$SVC_STATE/files/$j3/1
size=$(stat -c %s "$stored/result.h5")
truncate -s 4096 "$stored/result.h5"
t0=$(date +%s.%N)
code=$(svc_req GET "/v1/jobs/$j3/files/result.h5" "$alice" --max-time 10)
echo "INFO GET of a truncated stored file answered $code after $(python3 -c "print('%.2f' % ($(date +%s.%N) - $t0))") s"
error_is "$code" 500 stored_file_damaged && grep -q "'result.h5' of job $j3" "$SVC_BODY" &&
	grep -q "4096 bytes on disk but $size" "$SVC_BODY"
check truncated_file_error_at_once $? "status $code: $(head -c 300 "$SVC_BODY")"
code=$(svc_req GET "/v1/jobs/$j3/files/result.h5" "$alice" --max-time 10 -H 'Range: bytes=0-99')
error_is "$code" 500 stored_file_damaged
check truncated_file_ranged_error $? "status $code: $(head -c 300 "$SVC_BODY")"
grep -q "damaged stored file: job $j3 attempt 1 'result.h5': it has 4096 bytes" "$tmp/files.err" &&
	[ "$(grep -c "job $j3 attempt 1 'result.h5'" "$tmp/files.err")" -eq 1 ]
check server_logs_damaged_file_once $? "stderr: $(grep damaged "$tmp/files.err")"
(cd "$tmp" && PORO_SERVER=$SVC_URL PORO_TOKEN=$alice timeout 30 "$build/poro" fetch "$j3" --out fetched > fetch.out 2>&1)
rc=$?
[ "$rc" -ne 0 ] && [ "$rc" -ne 124 ] && grep -q "damaged.*(stored_file_damaged)" "$tmp/fetch.out" && ! grep -q "cannot reach" "$tmp/fetch.out"
check fetch_prints_damage $? "exit $rc: $(cat "$tmp/fetch.out")"
printf 'XXXX' | dd of="$stored/result.xdmf" bs=1 seek=200 conv=notrunc 2> /dev/null
code=$(svc_req GET "/v1/jobs/$j3/files/result.xdmf" "$alice" --max-time 10)
error_is "$code" 500 stored_file_damaged && grep -q "SHA-256" "$SVC_BODY"
check flipped_bytes_error_at_once $? "status $code: $(head -c 300 "$SVC_BODY")"

# a file above the size hashed before answering is hashed while it is sent
j5=$(submit "$alice")
read -r bid batt <<< "$(claim "$pool")"
head -c $((65 << 20)) /dev/urandom > "$tmp/big.h5"
put "$pool" "$bid" "$batt" result.h5 "$tmp/big.h5" > /dev/null
code=$(svc_req GET "/v1/jobs/$j5/files/result.h5" "$alice" --max-time 60)
[ "$code" = 200 ] && cmp -s "$SVC_BODY" "$tmp/big.h5"
check large_file_streamed_whole $? "status $code, $(stat -c %s "$SVC_BODY") bytes"
printf 'XXXX' | dd of="$SVC_STATE/files/$j5/$batt/result.h5" bs=1 seek=$((40 << 20)) conv=notrunc 2> /dev/null
curl -s -o "$tmp/big.got" -H "Authorization: Bearer $alice" --max-time 60 "$SVC_URL/v1/jobs/$j5/files/result.h5"
rc=$?
got=$(stat -c %s "$tmp/big.got")
echo "INFO download of a damaged 65 MiB file: curl exit $rc after $got of $((65 << 20)) bytes"
[ "$rc" -ne 0 ] && [ "$rc" -ne 28 ] && [ "$got" -lt $((65 << 20)) ]
check large_damaged_file_never_completes $? "curl exit $rc, $got bytes"
code=$(svc_req GET "/v1/jobs/$j5/files/result.h5" "$alice" --max-time 10)
error_is "$code" 500 stored_file_damaged && alive
check large_damaged_file_then_error $? "status $code: $(head -c 300 "$SVC_BODY")"
rm -f "$tmp/big.h5" "$tmp/big.got" "$SVC_BODY"
# a fresh server has not seen the damage: poro fetch's download is broken off, and asked again
svc_stop files
svc_start files --lease-seconds 300 || { echo "FAIL restart_files: server did not start"; exit 1; }
(cd "$tmp" && PORO_SERVER=$SVC_URL PORO_TOKEN=$alice timeout 60 "$build/poro" fetch "$j5" --out fetched5 > fetch5.out 2>&1)
rc=$?
[ "$rc" -ne 0 ] && [ "$rc" -ne 124 ] && grep -q "damaged.*(stored_file_damaged)" "$tmp/fetch5.out" &&
	! grep -q "cannot reach" "$tmp/fetch5.out" && [ ! -e "$tmp/fetched5/result.h5" ]
check fetch_prints_damage_of_large_file $? "exit $rc: $(cat "$tmp/fetch5.out")"
rm -rf "$tmp/fetched5"
svc_stop files

# ---- a solver that leaves a damaged result.h5: the extraction dies, the job does not ----------------
svc_start dmg || { echo "FAIL start_dmg: server did not start"; exit 1; }
alice=$(svc_token dmg alice user)
pool=$(svc_token dmg pool worker)
cat > "$tmp/damaging-solver" <<EOF
#!/usr/bin/env bash
# poro-solve, but a run's result.h5 gets four bytes changed before it is uploaded
[ "\$1" = run ] || exec "$build/poro-solve" "\$@"
"$build/poro-solve" "\$@"
rc=\$?
if [ "\$1" = run ] && [ \$rc -eq 0 ]; then
	cp out/result.h5 out/clean.h5 && python3 "$tmp/damage.py" out/clean.h5 out/result.h5 && rm out/clean.h5
fi
exit \$rc
EOF
chmod +x "$tmp/damaging-solver"
start_worker w2 "$tmp/damaging-solver"
j4=$(submit "$alice")
wait_for 60 ended "$j4"
state=$(field "$j4" state) message=$(field "$j4" message)
[ "$state" = succeeded ] && echo "$message" | grep -Eq "no probes.json: poro-solve probes (was killed by signal|exited with status)"
check damaged_result_costs_only_probes $? "state $state, message: $message"
code=$(svc_req GET "/v1/jobs/$j4/probes" "$alice")
error_is "$code" 404 not_found && alive
check damaged_worker_result_server_alive $? "GET probes $code; $(tail -2 "$tmp/dmg.err")"
grep -q "job $j4 attempt 1: no probes.json" "$tmp/w2.log"
check worker_says_probes_failed $? "w2 log: $(tail -3 "$tmp/w2.log")"
stop_workers

svc_stop dmg

# ---- a result.h5 the server refuses fails the job, and the worker keeps it -------------------------
svc_start small --max-upload-bytes 20000 || { echo "FAIL start_small: server did not start"; exit 1; }
alice=$(svc_token small alice user)
pool=$(svc_token small pool worker)
start_worker w3 "$build/poro-solve"
PORO_SERVER=$SVC_URL PORO_TOKEN=$alice timeout 120 "$build/poro" submit "$tmp/case.json" --wait > "$tmp/wait.out" 2> "$tmp/wait.err"
rc=$?
j6=$(cat "$tmp/wait.out")
[ "$rc" -ne 0 ] && [ "$rc" -ne 124 ]
check refused_result_submit_wait_fails $? "exit $rc: $(tail -2 "$tmp/wait.err")"
state=$(field "$j6" state) message=$(field "$j6" message)
[ "$state" = failed ] && echo "$message" | grep -q "result.h5 (.*) was refused by the server: .*(body_too_large)"
check refused_result_fails_job $? "state $state, message: $message"
[ -s "$tmp/work-w3/job-$j6-1/out/result.h5" ] && echo "$message" | grep -q "kept in $tmp/work-w3/job-$j6-1 on host"
check refused_result_kept_by_worker $? "$(ls "$tmp/work-w3/job-$j6-1/out" 2>&1); message: $message"
[ "$(field "$j6" attempt)" = 1 ]
check refused_result_not_retried $? "attempt $(field "$j6" attempt)"
(cd "$tmp" && PORO_SERVER=$SVC_URL PORO_TOKEN=$alice timeout 30 "$build/poro" fetch "$j6" --out fetched6 > fetch6.out 2>&1)
rc=$?
[ "$rc" -ne 0 ] && [ ! -e "$tmp/fetched6/result.h5" ]
check refused_result_fetch_fails $? "exit $rc: $(cat "$tmp/fetch6.out")"
stop_workers
