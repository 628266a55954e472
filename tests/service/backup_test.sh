#!/usr/bin/env bash
# backup_test.sh - online backup and restore of the server's database (docs/operations.md):
#   - poro-load submits from 8 clients while `poro-server backup` runs; the copy passes SQLite's
#     integrity_check (the sqlite3 shell's, not the server's own code), holds every submission
#     acknowledged before the backup began, and the load saw no error meanwhile;
#   - a backup never overwrites a file, and a missing database is named;
#   - restore refuses while the server runs, refuses a damaged backup (leaving poro.db as it was),
#     and restores: a server started on the restored state answers every job of the copy, knows
#     no job submitted after it, and accepts the tokens it held.
#   bash tests/service/backup_test.sh BUILD_DIR      (from the repository root)
set -u
build=${1:-build}
cd "$(dirname "$0")/../.."
. tests/service/lib.sh
svc_init "$build"
tmp=$SVC_TMP
LOAD_COUNT=3000
LOAD_CLIENTS=8

python3 - tests/cases/terzaghi.json "$tmp/case.json" <<'EOF2'
import json, sys
c = json.load(open(sys.argv[1]))
c["time"]["end"] = 0.01
json.dump(c, open(sys.argv[2], "w"))
json.dump({"case": c}, open(sys.argv[2].replace("case.json", "request.json"), "w"))
EOF2
svc_start main
token=$(svc_token main alice user)
acked() { awk '$2 == 201 { print $3 }' "$tmp/record.txt" 2>/dev/null; }

"$build/poro-load" submit --server "$SVC_URL" --token "$token" --case "$tmp/case.json" --clients "$LOAD_CLIENTS" \
	--count "$LOAD_COUNT" --key-prefix backup --record "$tmp/record.txt" --pause-ms 5 > "$tmp/load.out" 2>&1 &
load_pid=$!
enough_acked() { [ "$(acked | wc -l)" -ge 300 ]; }
wait_for 60 enough_acked
acked > "$tmp/before.txt"     # acknowledged before the backup began
"$build/poro-server" backup --state "$SVC_STATE" --out "$tmp/copy.db" > "$tmp/backup.out" 2> "$tmp/backup.err"
status=$?
acked > "$tmp/after.txt"
load_running=$(kill -0 "$load_pid" 2>/dev/null && echo 1 || echo 0)
wait "$load_pid"
echo "INFO backup: $(cat "$tmp/backup.out" "$tmp/backup.err"); $(wc -l < "$tmp/before.txt") acknowledged before it, $(wc -l < "$tmp/after.txt") when it ended; load: $(cat "$tmp/load.out")"
check backup_succeeds_under_load "$status" "exit $status: $(cat "$tmp/backup.err")"
check load_ran_through_the_backup "$([ "$load_running" = 1 ] && [ "$(wc -l < "$tmp/after.txt")" -gt "$(wc -l < "$tmp/before.txt")" ]; echo $?)" \
	"the load was not submitting while the backup ran (running: $load_running)"
check load_saw_no_error "$(grep -q ' 0 errors' "$tmp/load.out"; echo $?)" "$(cat "$tmp/load.out")"
integrity=$(sqlite3 "file:$tmp/copy.db?mode=ro" 'PRAGMA integrity_check' 2>&1)
check copy_passes_integrity_check "$([ "$integrity" = ok ]; echo $?)" "integrity_check said: $integrity"
check copy_is_one_file "$([ ! -e "$tmp/copy.db-wal" ] && [ "$(sqlite3 "$tmp/copy.db" 'PRAGMA journal_mode')" = delete ]; echo $?)" \
	"the copy needs a -wal or is not in rollback-journal mode"
sqlite3 "file:$tmp/copy.db?mode=ro" 'SELECT id FROM jobs' | sort -n > "$tmp/copy_ids.txt"
missing=$(sort -n "$tmp/before.txt" | comm -23 - "$tmp/copy_ids.txt" | wc -l)
check copy_holds_every_acknowledged_submission "$([ "$missing" -eq 0 ] && [ -s "$tmp/before.txt" ]; echo $?)" \
	"$missing of $(wc -l < "$tmp/before.txt") jobs acknowledged before the backup are missing from it"
copy_max=$(tail -1 "$tmp/copy_ids.txt")
copy_count=$(wc -l < "$tmp/copy_ids.txt")

# ---- refusals of backup -----------------------------------------------------------------------
before_size=$(stat -c %s "$tmp/copy.db")
"$build/poro-server" backup --state "$SVC_STATE" --out "$tmp/copy.db" > /dev/null 2> "$tmp/again.err"
status=$?
check backup_never_overwrites "$([ "$status" = 1 ] && grep -q "exists" "$tmp/again.err" && [ "$(stat -c %s "$tmp/copy.db")" = "$before_size" ]; echo $?)" \
	"exit $status: $(cat "$tmp/again.err")"
"$build/poro-server" backup --state "$tmp/nowhere" --out "$tmp/other.db" > /dev/null 2> "$tmp/none.err"
status=$?
check backup_names_a_missing_database "$([ "$status" = 1 ] && grep -q "no database at '$tmp/nowhere/poro.db'" "$tmp/none.err" && [ ! -e "$tmp/other.db" ]; echo $?)" \
	"exit $status: $(cat "$tmp/none.err")"
"$build/poro-server" backup --state "$SVC_STATE" > /dev/null 2> "$tmp/usage.err"
status=$?
check backup_without_out_is_usage "$([ "$status" = 2 ] && grep -q "needs --out" "$tmp/usage.err"; echo $?)" "exit $status: $(cat "$tmp/usage.err")"

# ---- restore ----------------------------------------------------------------------------------
"$build/poro-server" restore --state "$SVC_STATE" --from "$tmp/copy.db" > /dev/null 2> "$tmp/busy.err"
status=$?
check restore_refused_while_server_runs "$([ "$status" = 1 ] && grep -q "in use by poro-server pid $SVC_PID" "$tmp/busy.err"; echo $?)" \
	"exit $status: $(cat "$tmp/busy.err")"
svc_stop main
last_id=$(sort -n "$tmp/after.txt" | tail -1)
sqlite3 "$SVC_STATE/poro.db" 'SELECT count(*) FROM jobs' > "$tmp/live_count.txt"
head -c 65536 "$tmp/copy.db" > "$tmp/damaged.db"
head -c 65536 /dev/urandom | dd of="$tmp/damaged.db" bs=4096 seek=4 conv=notrunc status=none
sum_before=$(sha256sum < "$SVC_STATE/poro.db")
"$build/poro-server" restore --state "$SVC_STATE" --from "$tmp/damaged.db" > /dev/null 2> "$tmp/damaged.err"
status=$?
check restore_refuses_a_damaged_backup "$([ "$status" = 1 ] && grep -q "restore failed" "$tmp/damaged.err" && [ "$(sha256sum < "$SVC_STATE/poro.db")" = "$sum_before" ]; echo $?)" \
	"exit $status: $(cat "$tmp/damaged.err")"
"$build/poro-server" restore --state "$SVC_STATE" --from "$tmp/copy.db" > "$tmp/restore.out" 2> "$tmp/restore.err"
status=$?
echo "INFO restore: $(cat "$tmp/restore.out" "$tmp/restore.err")"
check restore_succeeds "$status" "exit $status: $(cat "$tmp/restore.err")"
svc_start main
answered=0
for id in $(head -1 "$tmp/before.txt") $(sort -n "$tmp/before.txt" | tail -1) "$copy_max"; do
	[ "$(svc_req GET "/v1/jobs/$id" "$token")" = 200 ] && answered=$((answered + 1))
done
check restored_server_answers_the_copys_jobs_with_its_tokens "$([ "$answered" = 3 ]; echo $?)" "$answered of 3 jobs answered 200"
code=$(svc_req GET "/v1/jobs/$last_id" "$token")
check restored_server_is_the_copy "$([ "$last_id" -gt "$copy_max" ] && [ "$code" = 404 ]; echo $?)" \
	"job $last_id (submitted after the copy's last, $copy_max) answered $code"
svc_req GET "/v1/jobs?limit=1" "$token" > /dev/null
count=$(sqlite3 "file:$SVC_STATE/poro.db?mode=ro" 'SELECT count(*) FROM jobs')
check restored_store_holds_the_copys_jobs "$([ "$count" = "$copy_count" ]; echo $?)" "$count jobs after restore, $copy_count in the copy (the live store had $(cat "$tmp/live_count.txt"))"
code=$(svc_req POST /v1/jobs "$token" -H 'Content-Type: application/json' --data-binary "@$tmp/request.json")
new_id=$(json '["id"]' < "$SVC_BODY")
check restored_server_takes_submissions "$([ "$code" = 201 ] && [ "$new_id" -gt "$copy_max" ]; echo $?)" "answered $code, id '$new_id'"
svc_stop main

svc_summary
