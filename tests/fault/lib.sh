#!/usr/bin/env bash
# lib.sh - helpers of the fault, power-loss and soak tests (tests/fault/, docs/hardening.md), on top
# of tests/service/lib.sh: the LD_PRELOAD shim (fault_shim.c), starting servers and workers on
# a given state directory, and the checks every one of these tests makes of a state directory
# after the fact. Source it after tests/service/lib.sh and svc_init.

FAULT_SHIM=""
# A sanitized server refuses a preloaded library ahead of its runtime unless told not to check.
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}verify_asan_link_order=0"

# fault_init BUILD: finds the shim (make build-all builds it); fails when it is missing.
fault_init() {
	FAULT_SHIM="$PWD/$1/tests/fault/fault_shim.so"
	[ -f "$FAULT_SHIM" ] || { echo "FAIL fault_shim_built: no $FAULT_SHIM (make build-all)"; return 1; }
}

# free_port: a port nothing listens on now (the kernel's pick), for servers restarted on the same URL.
free_port() {
	python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'
}

# start_server_at STATE PORT LOG [env NAME=VALUE... --] [server flags...]: starts poro-server and
# waits until /healthz answers; its pid in SERVER_PID. Retries a start that exits at once (the
# port not free yet after a kill). Returns 1 if it never answers.
start_server_at() {
	local state=$1 port=$2 log=$3 envs=() try i
	shift 3
	if [ "${1:-}" = env ]; then
		shift
		while [ "$1" != -- ]; do envs+=("$1"); shift; done
		shift
	fi
	local extra=()
	[ -n "${SVC_ROUTES_LOG:-}" ] && extra=(--access-log "$SVC_ROUTES_LOG")
	for try in $(seq 30); do
		env "${envs[@]}" "$SVC_BUILD/poro-server" --listen "127.0.0.1:$port" --state "$state" "${extra[@]}" "$@" \
			>> "$log" 2>&1 &
		SERVER_PID=$!
		for i in $(seq 200); do
			curl -s -o /dev/null "http://127.0.0.1:$port/healthz" && return 0
			kill -0 "$SERVER_PID" 2>/dev/null || break
			sleep 0.05
		done
		kill -9 "$SERVER_PID" 2>/dev/null
		wait "$SERVER_PID" 2>/dev/null
		sleep 0.2
	done
	return 1
}

# tiny_submission OUT: the submission body of tests/fault/tiny_column.json (five steps, two
# checkpoints, three frames), what these tests' jobs run.
tiny_submission() {
	python3 -c 'import json, sys; json.dump(json.load(open("tests/fault/tiny_column.json")), open(sys.argv[1], "w"))' "$1"
}

# check_store STATE RECORD NAME: the state directory of a stopped server against what its
# clients were told (poro-load's --record lines "key status job_id"):
#   - PRAGMA integrity_check is ok;
#   - every key acknowledged (200 or 201) is present exactly once, as the job id the client got;
#   - no job is in two states: its state is the to_state of its last event, it has one
#     creation event, and each event starts from the state the one before it left;
#   - every indexed file is on disk at its indexed size and SHA-256, in files/JOB/ATTEMPT/;
#   - no stale result: a succeeded job's files of its final attempt include result.h5, and no
#     file or log chunk belongs to an attempt after the job's last.
# Prints one PASS or FAIL line per property, named NAME_...
check_store() {
	local state=$1 record=$2 name=$3 out
	out=$(sqlite3 -readonly "$state/poro.db" "PRAGMA integrity_check;" 2>&1)
	[ "$out" = ok ]
	check "${name}_integrity_check" $? "$out"
	python3 - "$state" "$record" "$name" <<'PY'
import hashlib, os, sqlite3, sys
state, record, name = sys.argv[1:4]
db = sqlite3.connect("file:%s/poro.db?mode=ro" % state, uri=True)
def report(prop, problems):
    if problems:
        print("FAIL %s_%s: %d problems, first: %s" % (name, prop, len(problems), "; ".join(problems[:3])))
    else:
        print("PASS %s_%s" % (name, prop))
acked = {}
if record and os.path.exists(record):
    for line in open(record):
        parts = line.split()
        if len(parts) == 3 and parts[1] in ("200", "201") and parts[2] != "-":
            acked.setdefault(parts[0], set()).add(int(parts[2]))
keys = {}
for key, job in db.execute("SELECT key, job_id FROM idempotency"):
    keys.setdefault(key, []).append(job)
problems = []
for key, ids in acked.items():
    if len(ids) != 1:
        problems.append("key %s acknowledged as jobs %s" % (key, sorted(ids)))
    elif keys.get(key) != list(ids):
        problems.append("key %s acknowledged as job %d, stored as %s" % (key, min(ids), keys.get(key)))
jobs = {j: (s, a) for j, s, a in db.execute("SELECT id, state, attempt FROM jobs")}
for key, ids in acked.items():
    for j in ids:
        if j not in jobs:
            problems.append("acknowledged job %d (key %s) is missing" % (j, key))
report("acknowledged_present_once", problems)
problems = []
events = {}
for job, frm, to, attempt in db.execute("SELECT job_id, from_state, to_state, attempt FROM events ORDER BY id"):
    events.setdefault(job, []).append((frm, to, attempt))
for j, (st, attempt) in jobs.items():
    ev = events.get(j, [])
    if not ev or ev[0][0] is not None or ev[0][1] != "queued":
        problems.append("job %d does not start with one creation event" % j)
        continue
    if sum(1 for e in ev if e[0] is None) != 1:
        problems.append("job %d has %d creation events" % (j, sum(1 for e in ev if e[0] is None)))
    for prev, cur in zip(ev, ev[1:]):
        if cur[0] != prev[1]:
            problems.append("job %d: event %s->%s after one that left it %s" % (j, cur[0], cur[1], prev[1]))
        if prev[1] in ("succeeded", "failed", "cancelled"):
            problems.append("job %d: an event after its end (%s)" % (j, prev[1]))
    if ev[-1][1] != st:
        problems.append("job %d is %s but its last event left it %s" % (j, st, ev[-1][1]))
report("one_state_per_job", problems)
problems = []
for j, attempt, fname, size, sha in db.execute("SELECT job_id, attempt, name, size, sha256 FROM files"):
    path = os.path.join(state, "files", str(j), str(attempt), fname)
    if not os.path.isfile(path):
        problems.append("job %d attempt %d '%s' is indexed but not on disk" % (j, attempt, fname))
    elif os.path.getsize(path) != size:
        problems.append("job %d attempt %d '%s' has %d bytes, %d indexed" % (j, attempt, fname, os.path.getsize(path), size))
    elif hashlib.sha256(open(path, "rb").read()).hexdigest() != sha:
        problems.append("job %d attempt %d '%s' differs from its indexed SHA-256" % (j, attempt, fname))
report("indexed_files_on_disk", problems)
problems = []
for j, (st, attempt) in jobs.items():
    if st == "succeeded":
        n = db.execute("SELECT count(*) FROM files WHERE job_id = ? AND attempt = ? AND name = 'result.h5'", (j, attempt)).fetchone()[0]
        if n != 1:
            problems.append("succeeded job %d has no result.h5 of its attempt %d" % (j, attempt))
for j, attempt in db.execute("SELECT f.job_id, f.attempt FROM files f JOIN jobs j ON j.id = f.job_id WHERE f.attempt > j.attempt"):
    problems.append("job %d has a file of attempt %d, after its last" % (j, attempt))
for j, attempt in db.execute("SELECT l.job_id, l.attempt FROM log_chunks l JOIN jobs j ON j.id = l.job_id WHERE l.attempt > j.attempt"):
    problems.append("job %d has a log chunk of attempt %d, after its last" % (j, attempt))
report("no_stale_result", problems)
PY
}

# submit_once KEY: one submission of $FAULT_CASE (a submission body) with Idempotency-Key KEY to
# $SVC_URL as $FAULT_USER; prints the status, the body in $SVC_BODY. A 200 or 201 is appended to
# $FAULT_RECORD as poro-load records it ("key status job_id"), for check_store.
submit_once() {
	local code id
	code=$(svc_req POST /v1/jobs "$FAULT_USER" -H "Idempotency-Key: $1" -H 'Content-Type: application/json' \
		--data-binary "@$FAULT_CASE")
	if [ "$code" = 200 ] || [ "$code" = 201 ]; then
		id=$(json '["id"]' < "$SVC_BODY")
		echo "$1 $code $id" >> "$FAULT_RECORD"
	fi
	echo "$code"
}

# health_is STATUS: /healthz of $SVC_URL answers STATUS (200 or 503).
health_is() {
	[ "$(curl -s -o /dev/null -w '%{http_code}' "$SVC_URL/healthz")" = "$1" ]
}

# refusal_is CODE STATUS: the last answer ($SVC_BODY, $SVC_HEADERS) is the JSON error CODE with
# HTTP status STATUS, a message and a Retry-After header.
refusal_is() {
	[ "$(json '["error"]["code"]' < "$SVC_BODY")" = "$1" ] && [ -n "$(json '["error"]["message"]' < "$SVC_BODY")" ] &&
		[ -n "$(svc_header Retry-After)" ] && grep -q "^HTTP/1.1 $2 " "$SVC_HEADERS"
}

# fault_start NAME [server flags...]: starts instance NAME under the shim with the rule file
# FAULT_CONTROL (empty: no fault; write a rule into it to inject one), then fault_client_init.
fault_start() {
	local name=$1
	shift
	FAULT_CONTROL="$SVC_TMP/faults"
	: > "$FAULT_CONTROL"
	mkdir -p "$SVC_TMP/$name"
	SVC_WRAP=(env LD_PRELOAD="$FAULT_SHIM" PORO_FAULT_ROOT="$SVC_TMP/$name" PORO_FAULT_CONTROL="$FAULT_CONTROL")
	svc_start "$name" "$@"
	check server_starts_under_shim $? "no server"
	SVC_WRAP=()
	fault_client_init "$name"
}

# fault_client_init NAME: tokens of a user (FAULT_USER) and a worker (FAULT_POOL) on instance
# NAME, the submission body FAULT_CASE (tiny_column.json), an empty FAULT_RECORD, and three
# acknowledged submissions before any fault.
fault_client_init() {
	FAULT_USER=$(svc_token "$1" alice user)
	FAULT_POOL=$(svc_token "$1" pool worker)
	FAULT_CASE="$SVC_TMP/submission.json"
	FAULT_RECORD="$SVC_TMP/record.txt"
	: > "$FAULT_RECORD"
	python3 -c 'import json, sys; json.dump({"case": json.load(open(sys.argv[1]))}, open(sys.argv[2], "w"))' \
		tests/fault/tiny_column.json "$FAULT_CASE"
	local i
	for i in 1 2 3; do submit_once "before-$i" > /dev/null; done
	check submissions_before_faults_acknowledged "$([ "$(wc -l < "$FAULT_RECORD")" = 3 ]; echo $?)" "$(cat "$FAULT_RECORD")"
}

# fault_claim BYTES: the worker claims a job (FAULT_JOB, FAULT_ATTEMPT) and makes a random
# result.h5 of BYTES to upload with fault_upload.
fault_claim() {
	local code
	code=$(svc_req POST /v1/worker/claim "$FAULT_POOL" -H 'Content-Type: application/json' \
		--data '{"worker": "w:1", "host": "w", "threads": 1, "wait_seconds": 5}')
	FAULT_JOB=$(json '["job"]["id"]' < "$SVC_BODY")
	FAULT_ATTEMPT=$(json '["job"]["attempt"]' < "$SVC_BODY")
	check worker_claims "$([ "$code" = 200 ] && [ -n "$FAULT_JOB" ]; echo $?)" "status $code"
	fault_version "$1"
}

# fault_version BYTES: a new random result.h5 of BYTES for fault_upload (its SHA-256 in FAULT_SUM).
fault_version() {
	head -c "$1" /dev/urandom > "$SVC_TMP/result.h5"
	FAULT_SUM=$(sha256sum < "$SVC_TMP/result.h5" | cut -d' ' -f1)
}

# fault_upload [NAME]: uploads that result.h5 for the claimed attempt as NAME (default result.h5);
# prints the status.
fault_upload() {
	svc_req PUT "/v1/worker/jobs/$FAULT_JOB/files/${1:-result.h5}?attempt=$FAULT_ATTEMPT" "$FAULT_POOL" \
		-H "X-Checksum-Sha256: $FAULT_SUM" --data-binary "@$SVC_TMP/result.h5"
}
