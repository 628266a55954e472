#!/usr/bin/env bash
# lib.sh - helpers for service tests: start a real poro-server on 127.0.0.1 with a port chosen by
# the kernel and a fresh temporary state directory, create tokens with `poro-server token create`,
# speak HTTP with curl, read JSON with python3, stop the server. Source it from a test script:
#
#     . tests/service/lib.sh
#     svc_init "$build"                  # temporary directory + cleanup trap
#     svc_start main --lease-seconds 30  # sets SVC_URL, SVC_STATE, SVC_PID (per instance name)
#     tok=$(svc_token main alice user)
#     code=$(svc_req GET /v1/jobs "$tok")  # body in $SVC_BODY, headers in $SVC_HEADERS
#     id=$(json '.["id"]' < "$SVC_BODY")
#     svc_stop main; echo "$SVC_STATUS"
#
# Several named instances may run at once; svc_use NAME makes one current. Everything started is
# stopped and the temporary directory removed when the script exits.
#
# For the token-leak check (tests/service/token_leak_check.sh), tests/run.sh sets two variables:
# with SVC_TOKENS_LOG set, every token svc_token creates (and every one a test passes to
# svc_record_token) is appended to that file; with SVC_KEEP_LOGS set, the logs a script leaves in
# its temporary directory (*.out, *.err, *.log: servers' stdout and stderr, workers' logs) are
# copied into that directory before the temporary directory is removed.

SVC_BUILD=build
SVC_TMP=""
declare -A SVC_PIDS SVC_URLS SVC_STATES

svc_cleanup() {
	local name
	for name in "${!SVC_PIDS[@]}"; do
		kill -TERM "${SVC_PIDS[$name]}" 2>/dev/null
	done
	for name in "${!SVC_PIDS[@]}"; do
		wait "${SVC_PIDS[$name]}" 2>/dev/null
	done
	[ -n "$SVC_TMP" ] && svc_keep_logs "$SVC_TMP" && rm -rf "$SVC_TMP"
}

# svc_keep_logs DIR: with SVC_KEEP_LOGS set, copies the *.out, *.err and *.log files of DIR (and
# of its subdirectories, one level down) into it, named SCRIPT-PATH with slashes as '-'. Always
# succeeds: a log that cannot be kept must not fail the test.
svc_keep_logs() {
	[ -n "${SVC_KEEP_LOGS:-}" ] || return 0
	local dir=$1 script f rel
	script=$(basename "$0" .sh)
	mkdir -p "$SVC_KEEP_LOGS" 2>/dev/null || return 0
	while IFS= read -r f; do
		rel=${f#"$dir"/}
		cp "$f" "$SVC_KEEP_LOGS/$script-${rel//\//-}" 2>/dev/null
	done < <(find "$dir" -maxdepth 2 -type f \( -name '*.out' -o -name '*.err' -o -name '*.log' \) 2>/dev/null)
	return 0
}

# svc_record_token TOKEN: notes a token a test created (by svc_token, or through POST /v1/tokens)
# in $SVC_TOKENS_LOG, when set, for the token-leak check.
svc_record_token() {
	[ -n "${SVC_TOKENS_LOG:-}" ] && [ -n "$1" ] && (umask 077 && printf '%s\n' "$1" >> "$SVC_TOKENS_LOG")
	return 0
}

# svc_init BUILD_DIR: a temporary directory for this script and the cleanup trap.
svc_init() {
	SVC_BUILD=${1:-build}
	SVC_TMP=$(mktemp -d)
	SVC_BODY="$SVC_TMP/body"
	SVC_HEADERS="$SVC_TMP/headers"
	trap svc_cleanup EXIT
}

# svc_start NAME [poro-server flags...]: starts an instance with state $SVC_TMP/NAME and waits for
# STATE/server.url. Returns non-zero (with the server's stderr) if it does not come up in 10 s.
svc_start() {
	local name=$1
	shift
	local state="$SVC_TMP/$name"
	mkdir -p "$state"
	rm -f "$state/server.url"
	# with SVC_ROUTES_LOG set (tests/run.sh does), every answered request is logged there for the
	# route coverage check (tests/service/route_coverage.sh)
	local log_args=()
	[ -n "${SVC_ROUTES_LOG:-}" ] && log_args=(--access-log "$SVC_ROUTES_LOG")
	# SVC_WRAP (an array, e.g. (prlimit --as=200000000)) runs the server under another command
	${SVC_WRAP[@]+"${SVC_WRAP[@]}"} "$SVC_BUILD/poro-server" --listen 127.0.0.1:0 --state "$state" "${log_args[@]}" "$@" \
		> "$SVC_TMP/$name.out" 2> "$SVC_TMP/$name.err" &
	SVC_PIDS[$name]=$!
	SVC_STATES[$name]=$state
	local i
	for i in $(seq 100); do
		if [ -s "$state/server.url" ]; then
			SVC_URLS[$name]=$(cat "$state/server.url")
			svc_use "$name"
			return 0
		fi
		kill -0 "${SVC_PIDS[$name]}" 2>/dev/null || break
		sleep 0.1
	done
	cat "$SVC_TMP/$name.err" >&2
	return 1
}

# svc_use NAME: makes an instance current (SVC_URL, SVC_STATE, SVC_PID).
svc_use() {
	SVC_URL=${SVC_URLS[$1]}
	SVC_STATE=${SVC_STATES[$1]}
	SVC_PID=${SVC_PIDS[$1]}
}

# svc_stop NAME: SIGTERM and wait; the exit status goes to SVC_STATUS. Call it directly, not in
# $(...): a subshell cannot wait for the server.
svc_stop() {
	local pid=${SVC_PIDS[$1]}
	kill -TERM "$pid" 2>/dev/null
	wait "$pid"
	SVC_STATUS=$?
	unset "SVC_PIDS[$1]"
}

# svc_token NAME USER ROLE: creates (if needed) the user and prints a new token (recorded, see above).
svc_token() {
	local token
	token=$("$SVC_BUILD/poro-server" token create --state "${SVC_STATES[$1]}" --user "$2" --role "$3") || return
	svc_record_token "$token"
	printf '%s\n' "$token"
}

# svc_req METHOD PATH TOKEN [curl arguments...]: one request to the current instance; prints the
# status code; the body goes to $SVC_BODY and the headers to $SVC_HEADERS. TOKEN "" sends none.
# The Authorization header reaches curl through a file (-H @FILE), not its command line, so the
# token is not in the process list while the request runs.
svc_req() {
	local method=$1 path=$2 token=$3
	shift 3
	local auth=() header="$SVC_TMP/.auth-$BASHPID"
	if [ -n "$token" ]; then
		(umask 077 && printf 'Authorization: Bearer %s\n' "$token" > "$header")
		auth=(-H "@$header")
	fi
	curl -s --path-as-is -X "$method" "${auth[@]}" -o "$SVC_BODY" -D "$SVC_HEADERS" \
		-w '%{http_code}' "$@" "$SVC_URL$path"
}

# json EXPR: evaluates EXPR (jq-like python suffix on d, e.g. '["job"]["id"]') on the JSON of
# stdin; strings print raw, everything else as JSON. Prints nothing and fails on bad input.
json() {
	python3 -c '
import json, sys
try:
    d = json.load(sys.stdin)
    v = eval("d" + sys.argv[1])
except Exception as e:
    sys.exit(1)
print(v if isinstance(v, str) else json.dumps(v, sort_keys=True))
' "$1"
}

# svc_header NAME: a response header of the last svc_req (case-insensitive), without CR.
svc_header() {
	grep -i "^$1:" "$SVC_HEADERS" | head -1 | cut -d' ' -f2- | tr -d '\r'
}

# check NAME CONDITION-STATUS WHY: prints "PASS NAME" when the status is 0, else "FAIL NAME: WHY".
# svc_summary prints the closing "N passed, N failed" of the checks made so far.
SVC_PASSED=0 SVC_FAILED=0
check() {
	if [ "$2" -eq 0 ]; then
		echo "PASS $1"; SVC_PASSED=$((SVC_PASSED + 1))
	else
		echo "FAIL $1: $3"; SVC_FAILED=$((SVC_FAILED + 1))
	fi
}
svc_summary() {
	echo "$SVC_PASSED passed, $SVC_FAILED failed"
}

# svc_asan BINARY: status 0 when BINARY was built with AddressSanitizer (make test-san), whose
# shadow memory reserves terabytes of address space: such a process cannot run under an address
# space limit (RLIMIT_AS), so checks that need one are left out, saying so.
svc_asan() {
	ldd "$1" 2>/dev/null | grep -q libasan
}

# wait_for SECONDS COMMAND...: runs COMMAND every 0.1 s until it succeeds (status 0) or SECONDS
# have passed (status 1). Waiting on the state itself, not a fixed sleep, keeps the tests quick on
# an idle machine and correct on a loaded one. What COMMAND prints is dropped: a poll's misses are
# expected and would only clutter the test's output.
wait_for() {
	local t=$1 i
	shift
	for i in $(seq $((t * 10))); do "$@" > /dev/null 2>&1 && return 0; sleep 0.1; done
	return 1
}
