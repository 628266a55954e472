#!/usr/bin/env bash
# power_loss_test.sh - an acknowledged submission, and an acknowledged upload, survive a power
# loss: the state directory is cut back to what had been fsynced when the server stopped, and a
# new server started on that.
#
# The server runs under tests/fault/fault_shim.c, which keeps the durable image of its state
# directory: each file's bytes as of its last fsync, each directory's entries as of its last
# fsync (docs/hardening.md "Power loss"). poro-load submits from 4 clients with Idempotency-Keys
# while a real worker runs the jobs (tiny_column.json: checkpoints, uploads, finishes). At a
# random moment the server is killed with SIGKILL; the image is then laid out as a fresh state
# directory (crash_image.py), a server started on it (SQLite recovers its WAL), and check_store
# (lib.sh) run on it after a clean stop: integrity, every acknowledged key present once as the job
# its client was told, one state per job, every indexed file on disk at its size and SHA-256, no
# stale result. A succeeded job's result.h5 must also download with its checksum.
#   bash tests/fault/power_loss_test.sh BUILD_DIR    (POWER_LOSS_CYCLES=N for more cycles; 3)
set -u
build=${1:-build}
cd "$(dirname "$0")/../.."
. tests/service/lib.sh
. tests/fault/lib.sh
svc_init "$build"
fault_init "$build" || exit 1
cycles=${POWER_LOSS_CYCLES:-3}
pids=()
trap 'for p in "${pids[@]}"; do kill -9 "$p" 2>/dev/null; done; svc_cleanup' EXIT
tiny_submission "$SVC_TMP/case.json"
RANDOM=20261207   # the kill moments are random, and the same on every run of the test

for cycle in $(seq "$cycles"); do
	state="$SVC_TMP/state-$cycle" img="$SVC_TMP/image-$cycle" after="$SVC_TMP/after-$cycle"
	mkdir -p "$state" "$img"
	port=$(free_port)
	shim=(env LD_PRELOAD="$FAULT_SHIM" PORO_CRASH_ROOT="$state" PORO_CRASH_IMAGE="$img" --)
	# the tokens are written through the shim too: they are part of what must survive
	user=$(env LD_PRELOAD="$FAULT_SHIM" PORO_CRASH_ROOT="$state" PORO_CRASH_IMAGE="$img" \
		"$build/poro-server" token create --state "$state" --user alice --role user)
	pool=$(env LD_PRELOAD="$FAULT_SHIM" PORO_CRASH_ROOT="$state" PORO_CRASH_IMAGE="$img" \
		"$build/poro-server" token create --state "$state" --user pool --role worker)
	svc_record_token "$user"; svc_record_token "$pool"
	(umask 077 && printf '%s\n' "$pool" > "$SVC_TMP/pool-$cycle.token")
	start_server_at "$state" "$port" "$SVC_TMP/server-$cycle.log" "${shim[@]}" --lease-seconds 5
	check "cycle${cycle}_server_starts_under_shim" $? "$(tail -3 "$SVC_TMP/server-$cycle.log")"
	server=$SERVER_PID
	pids+=("$server")
	"$build/poro-worker" --server "http://127.0.0.1:$port" --token-file "$SVC_TMP/pool-$cycle.token" --work "$SVC_TMP/work-$cycle" \
		--solver "$build/poro-solve" --slots 2 --threads 2 --name "w$cycle" > "$SVC_TMP/worker-$cycle.log" 2>&1 &
	worker=$!
	pids+=("$worker")
	"$build/poro-load" submit --server "http://127.0.0.1:$port" --token "$user" --case "$SVC_TMP/case.json" \
		--clients 4 --count 400 --key-prefix "c$cycle" --record "$SVC_TMP/record-$cycle.txt" --pause-ms 40 \
		> "$SVC_TMP/load-$cycle.log" 2>&1 &
	load=$!
	pids+=("$load")
	# the power goes after some submissions and some finished jobs: wait for the first of each,
	# then a random 0.5-3 s more
	wait_for 60 grep -q ' 201 ' "$SVC_TMP/record-$cycle.txt"
	wait_for 120 grep -q 'state change.*succeeded\|succeeded' "$SVC_TMP/worker-$cycle.log"
	sleep "$((RANDOM % 3)).$((RANDOM % 10))"
	kill -9 "$server"
	wait "$server" 2>/dev/null
	kill -9 "$load" "$worker" 2>/dev/null
	wait "$load" "$worker" 2>/dev/null
	acked=$(awk '$2 == 200 || $2 == 201' "$SVC_TMP/record-$cycle.txt" | wc -l)
	python3 tests/fault/crash_image.py "$img" "$after"
	check "cycle${cycle}_image_laid_out" $? "no image in $img"
	stored=$(find "$state/files" -type f ! -name '.*' | wc -l)
	kept=$(find "$after/files" -type f ! -name '.*' 2>/dev/null | wc -l)
	echo "INFO cycle $cycle: power lost after $acked acknowledged submissions; stored files: $stored before, $kept in the image"
	port2=$(free_port)
	start_server_at "$after" "$port2" "$SVC_TMP/after-$cycle.log" --lease-seconds 5
	check "cycle${cycle}_server_starts_after_power_loss" $? "$(tail -5 "$SVC_TMP/after-$cycle.log")"
	after_pid=$SERVER_PID
	# a succeeded job's result downloads whole, with its checksum
	SVC_URL="http://127.0.0.1:$port2"
	bad=""
	for id in $(sqlite3 -readonly "$after/poro.db" "SELECT id FROM jobs WHERE state = 'succeeded' LIMIT 20" 2>/dev/null); do
		code=$(svc_req GET "/v1/jobs/$id/files/result.h5" "$user")
		sum=$(sha256sum < "$SVC_BODY" | cut -d' ' -f1)
		[ "$code" = 200 ] && [ "$sum" = "$(svc_header X-Checksum-Sha256)" ] || bad="$bad job $id: $code $(head -c 200 "$SVC_BODY");"
	done
	[ -z "$bad" ]
	check "cycle${cycle}_results_download_after_power_loss" $? "$bad"
	kill -TERM "$after_pid"
	wait "$after_pid"
	check "cycle${cycle}_server_stops_cleanly" $? "exit status $?"
	check_store "$after" "$SVC_TMP/record-$cycle.txt" "cycle${cycle}"
	# the figures docs/hardening.md reports: acknowledged keys present as their job, and duplicates
	sqlite3 -readonly "$after/poro.db" "SELECT key || ' ' || job_id FROM idempotency" | sort > "$SVC_TMP/stored-$cycle.txt"
	present=$(awk '$2 == 200 || $2 == 201 {print $1 " " $3}' "$SVC_TMP/record-$cycle.txt" | sort -u |
		comm -12 - "$SVC_TMP/stored-$cycle.txt" | wc -l)
	echo "INFO cycle $cycle: after the restart $present of the acknowledged keys present as the job their client" \
		"was told; $(sqlite3 -readonly "$after/poro.db" "SELECT count(*) FROM jobs") jobs for" \
		"$(wc -l < "$SVC_TMP/stored-$cycle.txt") keys"
done
