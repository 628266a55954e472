#!/usr/bin/env bash
# soak.sh BUILD_DIR JOBS - the service under random kills (make soak: 10,000 jobs; make test runs
# tests/fault/soak_test.sh, a few hundred). docs/hardening.md "Soak".
#
# A real poro-server and two real poro-workers (two slots each) run JOBS short jobs
# (tests/fault/tiny_column.json: five steps, two checkpoints, uploads, a finish) that poro-load
# submits from 4 clients with Idempotency-Keys, resending a submission that got no answer or a
# 5xx with the same key (a client relying on the key). Every 1-4 s (random, bash's RANDOM with a
# fixed seed) one of the three is killed with SIGKILL, the server one time in three, and started
# again (the server on the same port and state directory). Every few kills, and at the end,
# soak_check.py checks the live database: no job in two states, no two live attempts, no stale
# result, every acknowledged key one job, a reason for every failure; jobs that ended and were
# checked are then deleted (through the API), so that the disk holds only the jobs in flight.
# When every job has ended: the final check (every job succeeded exactly once or failed with a
# reason), integrity_check after a clean stop, and one INFO line of figures.
# Bounded: SOAK_SECONDS (default 120 + JOBS) after which the soak fails, saying where it was.
# Progress: a line per check round in SOAK_PROGRESS, when set.
set -u
build=${1:-build}
jobs=${2:-10000}
limit=${SOAK_SECONDS:-$((120 + jobs))}
cd "$(dirname "$0")/../.."
. tests/service/lib.sh
. tests/fault/lib.sh
svc_init "$build"
state="$SVC_TMP/state"
ledger="$SVC_TMP/ledger.json"
record="$SVC_TMP/record.txt"
mkdir -p "$state"
: > "$record"
port=$(free_port)
url="http://127.0.0.1:$port"
RANDOM=4711
server_flags=(--lease-seconds 3 --max-attempts 20 --max-backoff-seconds 1 --user-max-queued 100000
	      --user-max-stored-bytes 0)
declare -A worker_pid
load_pid=""
stop_all() {
	[ -n "$load_pid" ] && kill -9 "$load_pid" 2>/dev/null
	for w in "${!worker_pid[@]}"; do kill -9 "${worker_pid[$w]}" 2>/dev/null; done
	[ -n "${SERVER_PID:-}" ] && kill -9 "$SERVER_PID" 2>/dev/null
	wait 2>/dev/null
}
trap 'stop_all; svc_cleanup' EXIT

start_server_at "$state" "$port" "$SVC_TMP/server.log" "${server_flags[@]}"
check soak_server_starts $? "$(tail -3 "$SVC_TMP/server.log")"
user=$("$build/poro-server" token create --state "$state" --user soak --role user)
pool=$("$build/poro-server" token create --state "$state" --user pool --role worker)
svc_record_token "$user"; svc_record_token "$pool"
(umask 077 && printf '%s\n' "$pool" > "$SVC_TMP/pool.token")
starts=0
start_worker() { # NAME
	starts=$((starts + 1))
	"$build/poro-worker" --server "$url" --token-file "$SVC_TMP/pool.token" --work "$SVC_TMP/work-$1-$starts" --solver "$build/poro-solve" \
		--slots 2 --threads 2 --name "$1" >> "$SVC_TMP/$1.log" 2>&1 &
	worker_pid[$1]=$!
}
start_worker w1
start_worker w2
tiny_submission "$SVC_TMP/case.json"
"$build/poro-load" submit --server "$url" --token "$user" --case "$SVC_TMP/case.json" --clients 4 --count "$jobs" \
	--key-prefix soak --record "$record" --retry-seconds "$limit" > "$SVC_TMP/load.log" 2>&1 &
load_pid=$!

started=$(date +%s)
kills_server=0 kills_worker=0 rounds=0 problems=0 deleted=0
# check_round: soak_check.py on the live database, then deletion of what it cleared
check_round() {
	local ids id
	rounds=$((rounds + 1))
	if ! ids=$(python3 tests/fault/soak_check.py "$state" "$record" "$ledger" 2> "$SVC_TMP/check.err"); then
		problems=$((problems + 1))
		echo "INFO soak: check round $rounds: $(head -3 "$SVC_TMP/check.err")"
		return 1
	fi
	for id in $ids; do
		SVC_URL=$url svc_req DELETE "/v1/jobs/$id" "$user" > /dev/null && deleted=$((deleted + 1))
	done
	[ -n "${SOAK_PROGRESS:-}" ] && echo "$(( $(date +%s) - started )) s: round $rounds, $deleted of $jobs jobs ended," \
		"checked and deleted; $kills_server server and $kills_worker worker kills" >> "$SOAK_PROGRESS"
	return 0
}
ended() { # every key acknowledged and every job ended and checked
	[ "$(python3 -c 'import json,sys; print(len(json.load(open(sys.argv[1]))))' "$ledger" 2>/dev/null)" = "$jobs" ]
}

while :; do
	sleep "$((1 + RANDOM % 3)).$((RANDOM % 10))"
	if [ $((RANDOM % 3)) -eq 0 ]; then
		kill -9 "$SERVER_PID" 2>/dev/null
		wait "$SERVER_PID" 2>/dev/null
		kills_server=$((kills_server + 1))
		start_server_at "$state" "$port" "$SVC_TMP/server.log" "${server_flags[@]}" ||
			{ check soak_server_restarts 1 "$(tail -5 "$SVC_TMP/server.log")"; break; }
	else
		w=w$((1 + RANDOM % 2))
		kill -9 "${worker_pid[$w]}" 2>/dev/null
		wait "${worker_pid[$w]}" 2>/dev/null
		kills_worker=$((kills_worker + 1))
		start_worker "$w"
	fi
	if [ $(( (kills_server + kills_worker) % 4 )) -eq 0 ]; then
		check_round
		ended && break
	fi
	if [ $(( $(date +%s) - started )) -gt "$limit" ]; then
		check soak_ends_within_limit 1 "$limit s passed: $(python3 -c 'import json,sys; print(len(json.load(open(sys.argv[1]))))' "$ledger" 2>/dev/null) of $jobs jobs ended; $(tail -2 "$SVC_TMP/load.log")"
		break
	fi
done
elapsed=$(( $(date +%s) - started ))
# the last round, on a server left alone, then the final accounting
check_round
wait "$load_pid" 2>/dev/null
load_pid=""
kill -TERM "$SERVER_PID"
wait "$SERVER_PID"
check soak_server_stops_cleanly $? "$(tail -3 "$SVC_TMP/server.log")"
summary=$(python3 tests/fault/soak_check.py "$state" "$record" "$ledger" --final 2> "$SVC_TMP/check.err")
check soak_every_job_ended_once_or_failed_with_a_reason $? "$(head -5 "$SVC_TMP/check.err")"
[ "$problems" -eq 0 ]
check soak_invariants_held_in_every_round $? "$problems of $rounds rounds found problems (first ones printed above)"
acked=$(awk '$2 == 200 || $2 == 201 { print $1 }' "$record" | sort -u | wc -l)
[ "$acked" = "$jobs" ]
check soak_every_submission_acknowledged $? "$acked of $jobs keys acknowledged"
out=$(sqlite3 -readonly "$state/poro.db" 'PRAGMA integrity_check;' 2>&1)
[ "$out" = ok ]
check soak_integrity_check $? "$out"
echo "INFO soak: $summary; $kills_server server kills and $kills_worker worker kills in $elapsed s; $rounds check rounds, $deleted jobs deleted after their check; $(grep -c '' "$record") submission tries for $jobs keys"
