#!/usr/bin/env bash
# memory_claim_test.sh - jobs that state the memory they need (memory_mb, docs/service.md §2
# "Memory"), over HTTP against real poro-server and poro-worker processes:
#   - memory_mb is checked at submission: not an integer, negative, or above 16777216 MB is 422
#     naming /memory_mb, and no job is stored; absent, it is 0 ("not stated"), shown in the job;
#   - a claim with max_memory_mb gets only jobs asking for at most that, or for nothing; a claim
#     without it (an older worker) gets any job; a bad max_memory_mb is 422 naming it;
#   - a poro-worker whose --memory-limit-mb is below a job's memory_mb leaves that job queued
#     while it takes a smaller one submitted after it, and a worker with a larger limit takes it;
#   - poro submit --memory-mb sends it and poro show prints it; a bad value is refused before any
#     request is made;
#   - poro-pilot.sbatch gives its worker the allocation's memory (--mem, or --mem-per-cpu times
#     the CPUs), and poro-slurm-provider refuses a --mem sbatch would not take;
#   - a database at schema version 5 (before memory_mb) upgrades in place, every job and event
#     kept, its jobs stating no memory.
#   bash tests/service/memory_claim_test.sh BUILD_DIR      (from the repository root)
set -u
build=${1:-build}
cd "$(dirname "$0")/../.."
. tests/service/lib.sh
svc_init "$build"
tmp=$SVC_TMP
workers=()
trap 'for p in "${workers[@]}"; do kill -9 "$p" 2>/dev/null; done; svc_cleanup' EXIT

python3 - tests/cases/terzaghi.json "$tmp" <<'PY'
import json, sys
c = json.load(open(sys.argv[1]))
c["time"]["end"] = 0.002
json.dump(c, open(sys.argv[2] + "/case.json", "w"))
for name, mb in (("fat", 4096), ("thin", 512), ("plain", None)):
    body = {"case": c}
    if mb is not None:
        body["memory_mb"] = mb
    json.dump(body, open(sys.argv[2] + "/" + name + ".json", "w"))
PY
# submit TOKEN NAME: the new job's id
submit() { svc_req POST /v1/jobs "$1" -H 'Content-Type: application/json' --data-binary "@$tmp/$2.json" > /dev/null; json '["id"]' < "$SVC_BODY"; }
# job_field TOKEN ID KEY
job_field() { svc_req GET "/v1/jobs/$2" "$1" > /dev/null && json "[\"$3\"]" < "$SVC_BODY"; }
# claimer TOKEN ID: the worker id of the claim that started the job's first attempt
claimer() {
	svc_req GET "/v1/jobs/$2" "$1" > /dev/null &&
		json '["events"]' < "$SVC_BODY" | python3 -c '
import json, sys
print(next((e["actor"] for e in json.load(sys.stdin) if e["to"] == "running"), ""))'
}
job_count() { sqlite3 "$1/poro.db" "SELECT count(*) FROM jobs"; }

# ---- submission: memory_mb checked, nothing stored when it is wrong ------------------------------
svc_start api
user=$(svc_token api alice user)
worker=$(svc_token api pool worker)
before=$(job_count "$SVC_STATE")
for bad in negative:-1 string:'"4G"' fraction:2048.5 boolean:true above_max:16777217 bytes_not_mb:17179869184; do
	printf '{"memory_mb": %s, "case": %s}' "${bad#*:}" "$(cat "$tmp/case.json")" > "$tmp/bad.json"
	code=$(svc_req POST /v1/jobs "$user" -H 'Content-Type: application/json' --data-binary "@$tmp/bad.json")
	field=$(json '["error"]["field"]' < "$SVC_BODY") message=$(json '["error"]["message"]' < "$SVC_BODY")
	check "memory_mb_${bad%%:*}_refused" "$([ "$code" = 422 ] && [ "$field" = /memory_mb ] &&
		[[ $message == *"'memory_mb' must be"* ]]; echo $?)" "answered $code on '$field': $message"
done
check refused_memory_stores_nothing "$([ "$(job_count "$SVC_STATE")" = "$before" ]; echo $?)" \
	"$before jobs before, $(job_count "$SVC_STATE") after"
fat=$(submit "$user" fat)
fat_mb=$(json '["memory_mb"]' < "$SVC_BODY")
thin=$(submit "$user" thin)
plain=$(submit "$user" plain)
plain_mb=$(json '["memory_mb"]' < "$SVC_BODY")
check job_shows_memory "$([ "$fat_mb" = 4096 ] && [ "$plain_mb" = 0 ] && [ "$(job_field "$user" "$thin" memory_mb)" = 512 ]; echo $?)" \
	"memory_mb of the 4096 MB job '$fat_mb', of the unstated one '$plain_mb'"

# ---- the claim: max_memory_mb ------------------------------------------------------------------------
claim() { # [MAX_MEMORY_MB]: the claimed job's id, or the status
	local code mem=${1:+, \"max_memory_mb\": $1}
	code=$(svc_req POST /v1/worker/claim "$worker" -d "{\"worker\": \"t:1\"$mem}")
	[ "$code" = 200 ] && json '["job"]["id"]' < "$SVC_BODY" || echo "$code"
}
got1=$(claim 1024)
got1_mb=$(json '["job"]["memory_mb"]' < "$SVC_BODY")
got2=$(claim 1024)
got3=$(claim 1024)
check claim_takes_only_jobs_within_its_memory "$([ "$got1" = "$thin" ] && [ "$got1_mb" = 512 ] && [ "$got2" = "$plain" ] &&
	[ "$got3" = 204 ]; echo $?)" "with 1024 MB: got '$got1' ($got1_mb MB), '$got2', '$got3'; jobs: 4096 MB $fat, 512 MB $thin, unstated $plain"
got4=$(claim)
check claim_without_memory_takes_any_job "$([ "$got4" = "$fat" ]; echo $?)" "a claim stating no memory got '$got4', not $fat"
for bad in zero:0 negative:-5 string:'"8G"'; do
	code=$(svc_req POST /v1/worker/claim "$worker" -d "{\"worker\": \"t:1\", \"max_memory_mb\": ${bad#*:}}")
	field=$(json '["error"]["field"]' < "$SVC_BODY")
	check "max_memory_mb_${bad%%:*}_refused" "$([ "$code" = 422 ] && [ "$field" = /max_memory_mb ]; echo $?)" "answered $code on '$field'"
done

# ---- the CLI ------------------------------------------------------------------------------------------
cli() { PORO_SERVER=$SVC_URL PORO_TOKEN=$user HOME=$tmp "$build/poro" "$@"; }
id=$(cli submit "$tmp/case.json" --memory-mb 3000 2> "$tmp/cli.err")
check poro_show_prints_memory "$(cli show "$id" | grep -q '^memory  *3000 MB$'; echo $?)" "job '$id': $(cli show "$id" 2>&1 | grep -i memory)"
check poro_show_unstated_memory "$(cli show "$plain" | grep -q '^memory  *not stated$'; echo $?)" "$(cli show "$plain" 2>&1 | grep -i memory)"
before=$(job_count "$SVC_STATE")
cli submit "$tmp/case.json" --memory-mb -1 > /dev/null 2> "$tmp/cli.err"
status=$?
check poro_submit_refuses_bad_memory "$([ "$status" = 2 ] && grep -q -- "--memory-mb" "$tmp/cli.err" &&
	[ "$(job_count "$SVC_STATE")" = "$before" ]; echo $?)" "exit $status: $(cat "$tmp/cli.err")"
svc_stop api

# ---- real workers: a small one leaves the big job, a big one takes it ------------------------------
svc_start run
user=$(svc_token run bob user)
(umask 077 && svc_token run pool worker > "$tmp/worker.token")
fat=$(submit "$user" fat)
thin=$(submit "$user" thin)
start_worker() { # NAME LIMIT_MB
	"$build/poro-worker" --server "$SVC_URL" --token-file "$tmp/worker.token" --work "$tmp/work-$1" --threads 1 \
		--name "$1" --memory-limit-mb "$2" > "$tmp/$1.log" 2>&1 &
	workers+=($!)
}
start_worker small:1 2048
claimed() { [ "$(job_field "$user" "$1" attempt)" -ge 1 ]; }
wait_for 60 claimed "$thin"
thin_by=$(claimer "$user" "$thin")
# the small worker took the younger job; once it polls again (the job waits for a claim in
# progress: "starting"), it has passed over the 4096 MB one at least once more
fat_waits() { [ "$(job_field "$user" "$fat" waiting | json '["reason"]')" = starting ]; }
wait_for 60 fat_waits
sleep 2   # a waiting claim looks again at least once a second
check small_worker_leaves_big_job "$([ "$thin_by" = small:1 ] && [ "$(job_field "$user" "$fat" state)" = queued ] &&
	[ "$(job_field "$user" "$fat" attempt)" = 0 ]; echo $?)" \
	"512 MB job claimed by '$thin_by'; 4096 MB job $(job_field "$user" "$fat" state), attempt $(job_field "$user" "$fat" attempt)"
grep -q "memory limit 2048 MB per solver" "$tmp/small:1.log"
check worker_states_its_limit $? "$(head -1 "$tmp/small:1.log")"
start_worker big:1 8192
wait_for 60 claimed "$fat"
fat_by=$(claimer "$user" "$fat")
check big_worker_takes_big_job "$([ "$fat_by" = big:1 ]; echo $?)" "4096 MB job first claimed by '$fat_by'"
for p in "${workers[@]}"; do kill -TERM "$p" 2>/dev/null; kill -TERM "$p" 2>/dev/null; wait "$p" 2>/dev/null; done
workers=()
svc_stop run

# ---- the Slurm pilot's memory and the provider's --mem -----------------------------------------------
mkdir -p "$tmp/bin"
printf '#!/bin/sh\necho 1:00:00\n' > "$tmp/bin/squeue"
printf '#!/bin/sh\necho "$@" > "%s"\n' "$tmp/pilot.args" > "$tmp/bin/worker"
chmod +x "$tmp/bin/squeue" "$tmp/bin/worker"
pilot_memory() { # SLURM variables...: the --memory-limit-mb the pilot script gives its worker
	rm -f "$tmp/pilot.args"
	env -i PATH="$tmp/bin:/usr/bin:/bin" SLURM_JOB_ID=7 PORO_SERVER=http://127.0.0.1:9 PORO_TOKEN_FILE=/dev/null \
		PORO_WORKER="$tmp/bin/worker" TMPDIR="$tmp" "$@" bash deploy/slurm/poro-pilot.sbatch 2>> "$tmp/pilot.err"
	sed -n 's/.*--memory-limit-mb \([0-9]*\).*/\1/p' "$tmp/pilot.args" 2>/dev/null
}
per_node=$(pilot_memory SLURM_MEM_PER_NODE=16384 SLURM_CPUS_PER_TASK=8)
per_cpu=$(pilot_memory SLURM_MEM_PER_CPU=2048 SLURM_CPUS_PER_TASK=4)
none=$(pilot_memory SLURM_CPUS_PER_TASK=4)
check pilot_passes_allocation_memory "$([ "$per_node" = 16384 ] && [ "$per_cpu" = 8192 ] && [ "$none" = 0 ]; echo $?)" \
	"--mem 16384: '$per_node', --mem-per-cpu 2048 x 4: '$per_cpu', none: '$none'; $(tail -2 "$tmp/pilot.err" 2>/dev/null)"
deploy/slurm/poro-slurm-provider --server http://127.0.0.1:9 --token-file /dev/null --mem 16GB > /dev/null 2> "$tmp/provider.err"
status=$?
check provider_refuses_bad_mem "$([ "$status" = 2 ] && grep -q "^poro-slurm-provider: --mem must be a size such as 16G" "$tmp/provider.err"; echo $?)" \
	"exit $status: $(cat "$tmp/provider.err")"

# ---- a database at schema version 5 upgrades in place ------------------------------------------------
svc_start old
user=$(svc_token old carol user)
worker=$(svc_token old pool worker)
running=$(submit "$user" plain)
queued=$(submit "$user" plain)
svc_req POST /v1/worker/claim "$worker" -d '{"worker": "t:1"}' > /dev/null   # the older job: $running
running_attempt=$(json '["job"]["attempt"]' < "$SVC_BODY")
svc_stop old
db=$tmp/old/poro.db
# version 5 is version 6 without migration 6's one column: undo it, as an older server left it
sqlite3 "$db" "ALTER TABLE jobs DROP COLUMN memory_mb; DELETE FROM schema_migrations WHERE version = 6;"
snapshot() { sqlite3 "$db" "SELECT id, state, attempt, case_sha256 FROM jobs ORDER BY id; SELECT count(*) FROM events;"; }
old_rows=$(snapshot)
old_version=$(sqlite3 "$db" "SELECT max(version) FROM schema_migrations")
svc_start old
new_version=$(sqlite3 "$db" "SELECT max(version) FROM schema_migrations")
check old_database_upgrades "$([ "$old_version" = 5 ] && [ "$new_version" = 6 ] && [ "$(snapshot)" = "$old_rows" ]; echo $?)" \
	"version $old_version -> $new_version; rows before: $old_rows; after: $(snapshot)"
check upgraded_jobs_state_no_memory "$([ "$(job_field "$user" "$queued" memory_mb)" = 0 ] &&
	[ "$(job_field "$user" "$running" state)" = running ] && [ "$(job_field "$user" "$running" attempt)" = "$running_attempt" ]; echo $?)" \
	"queued job: memory_mb '$(job_field "$user" "$queued" memory_mb)'; running job: $(job_field "$user" "$running" state)"
got=$(svc_req POST /v1/worker/claim "$worker" -d '{"worker": "t:2", "max_memory_mb": 256}' > /dev/null; json '["job"]["id"]' < "$SVC_BODY")
check upgraded_job_claimable_by_any_memory "$([ "$got" = "$queued" ]; echo $?)" "a 256 MB claim got '$got', not $queued"
new=$(submit "$user" fat)
check upgraded_database_takes_memory "$([ "$(job_field "$user" "$new" memory_mb)" = 4096 ]; echo $?)" "job '$new': $(head -c 300 "$SVC_BODY")"
svc_summary
