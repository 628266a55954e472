#!/usr/bin/env bash
# Listing latency at 100,000 jobs (run by bench/run.sh), printed and never asserted. A real
# poro-server on 127.0.0.1 with its SQLite file in the build directory is seeded through its API
# by poro-load: a "bulk" user with all jobs but 10, a "small" user with 10, and a fifth of the
# jobs claimed and finished so that state filters have something to find. Then, from one client,
# LIST_REQUESTS GETs of each listing shape (p50, p99):
#   - the admin's first page (limit 100);
#   - the small user's jobs, 10 among 100,000;
#   - a state-filtered page (bulk user, state=succeeded, limit 100);
#   - a deep page (bulk user, after= an id near the oldest, limit 100);
# and 64 concurrent clients listing the small user's jobs. The server's listing cost counters
# (poro_job_list_*) are printed too.
#   bash bench/list.sh BUILD_DIR        (LIST_JOBS, LIST_REQUESTS, PORO_SERVER_BIN, SERVER_FLAGS to override)
set -u
build=${1:-build}
cd "$(dirname "$0")/.."
root=$PWD
JOBS=${LIST_JOBS:-100000}
REQUESTS=${LIST_REQUESTS:-200}
server_bin=${PORO_SERVER_BIN:-$build/poro-server}
tmp=$(mktemp -d -p "$root/$build")
server=""
trap '[ -n "$server" ] && kill -TERM $server 2>/dev/null; wait 2>/dev/null; rm -rf "$tmp"' EXIT

# one load-generator token stands for many users here: lift the per-token limit on requests in
# progress above its 64 clients (SERVER_FLAGS="" for a server from before that limit)
server_flags=${SERVER_FLAGS-"--max-requests-per-token 1024"}
# shellcheck disable=SC2086 # the flags are words
"$server_bin" --listen 127.0.0.1:0 --state "$tmp/state" --user-max-queued 100000000 $server_flags \
	> "$tmp/server.log" 2>&1 &
server=$!
for i in $(seq 100); do [ -s "$tmp/state/server.url" ] && break; sleep 0.1; done
url=$(cat "$tmp/state/server.url")
token() { "$server_bin" token create --state "$tmp/state" --user "$1" --role "$2" | tail -1; }
admin=$(token root admin)
small=$(token small user)
bulk=$(token bulk user)
pool=$(token pool worker)
python3 -c "import json; c = json.load(open('tests/cases/terzaghi.json')); c['time']['end'] = 0.01; json.dump(c, open('$tmp/case.json', 'w'))"

load() { "$build/poro-load" "$@" --server "$url"; }
t0=$(date +%s.%N)
load submit --token "$bulk" --case "$tmp/case.json" --clients 64 --count $((JOBS / 2)) --key-prefix a > /dev/null
load submit --token "$small" --case "$tmp/case.json" --clients 2 --count 10 --key-prefix s > /dev/null
load submit --token "$bulk" --case "$tmp/case.json" --clients 64 --count $((JOBS - JOBS / 2 - 10)) --key-prefix b > /dev/null
load claim --token "$pool" --clients 8 --count $((JOBS / 5)) > /dev/null
echo "seeded $JOBS jobs through the API in $(python3 -c "import time; print('%.0f' % (time.time() - $t0))") s ($((JOBS / 5)) claimed and finished)"

deep=$((JOBS / 10))
get() { # NAME TOKEN PATH CLIENTS COUNT
	echo "$1: $(load get --token "$2" --path "$3" --clients "$4" --count "$5" | sed 's/ per second; latency/ per second;/')"
}
get "admin, first page of 100" "$admin" "/v1/jobs?limit=100" 1 "$REQUESTS"
get "user with 10 jobs among $JOBS" "$small" "/v1/jobs" 1 "$REQUESTS"
get "state=succeeded, page of 100" "$bulk" "/v1/jobs?state=succeeded&limit=100" 1 "$REQUESTS"
get "deep page, after=$deep, 100" "$bulk" "/v1/jobs?after=$deep&limit=100" 1 "$REQUESTS"
get "64 concurrent clients, user with 10 jobs" "$small" "/v1/jobs" 64 $((64 * REQUESTS / 4))
curl -s -H "Authorization: Bearer $admin" "$url/metrics" | grep '^poro_job_list' | tr '\n' ' ' | sed 's/^/listing cost counters: /'
echo
# the dashboard's search and its jobs page, on the same 100,000 jobs (bench/web.sh)
WEB_URL=$url WEB_ADMIN=$admin WEB_USER=$bulk WEB_SMALL=small bash bench/web.sh "$build"
