#!/usr/bin/env bash
# io_error_test.sh - the store and the artefacts under injected faults: a full disk (ENOSPC), an
# I/O error on write (EIO) and fsync failing (EIO), each on the database and on the files
# directory, injected into the running server by tests/fault/fault_shim.c (LD_PRELOAD; needs no
# privileges). For each fault:
#   - a submission, or a worker's upload, is refused with 507 insufficient_storage (full disk) or
#     503 unavailable (I/O error), a JSON error with a message and Retry-After, never a 500, a
#     reset or a crash;
#   - /healthz turns degraded;
#   - once the fault is lifted the server recovers by itself (no restart): /healthz is ok again,
#     the refused submission's key was not stored (it is created now, 201) and the refused upload
#     goes through;
# and at the end, after a clean stop, check_store (lib.sh): integrity_check, every acknowledged
# submission present once, every indexed file on disk, one state per job.
#   bash tests/fault/io_error_test.sh BUILD_DIR
set -u
build=${1:-build}
cd "$(dirname "$0")/../.."
. tests/service/lib.sh
. tests/fault/lib.sh
svc_init "$build"
fault_init "$build" || exit 1

fault_start main --lease-seconds 60 --min-free-mb 0
control=$FAULT_CONTROL

# fault RULE NAME CODE STATUS: a submission under RULE is refused as CODE/STATUS, health degrades,
# and the server recovers when the rule is lifted.
fault() {
	local rule=$1 name=$2 code=$3 status=$4 got
	echo "$rule" > "$control"
	got=$(submit_once "$name")
	refusal_is "$code" "$status"
	check "${name}_submission_refused_${status}" $? "status $got: $(head -c 300 "$SVC_BODY")"
	wait_for 20 health_is 503
	check "${name}_health_degraded" $? "$(curl -s "$SVC_URL/healthz")"
	kill -0 "$SVC_PID"
	check "${name}_server_alive" $? "the server died"
	: > "$control"
	wait_for 20 health_is 200
	check "${name}_health_recovers_by_itself" $? "$(curl -s "$SVC_URL/healthz")"
	got=$(submit_once "$name")
	[ "$got" = 201 ]
	check "${name}_refused_key_was_not_stored" $? "status $got after the fault: $(head -c 300 "$SVC_BODY")"
}
fault "write ENOSPC poro.db" db_disk_full insufficient_storage 507
fault "write EIO poro.db" db_write_error unavailable 503
fault "fsync EIO poro.db" db_fsync_error unavailable 503
fault "write EFBIG poro.db" db_file_too_large unavailable 503

# uploads: a worker claims a job and uploads its result under each fault of files/
fault_claim 300000
upload_fault() {
	local rule=$1 name=$2 code=$3 status=$4 got
	echo "$rule" > "$control"
	got=$(fault_upload)
	refusal_is "$code" "$status"
	check "${name}_upload_refused_${status}" $? "status $got: $(head -c 300 "$SVC_BODY")"
	: > "$control"
	got=$(fault_upload)
	[ "$got" = 201 ]
	check "${name}_upload_goes_through_after" $? "status $got: $(head -c 300 "$SVC_BODY")"
}
upload_fault "write ENOSPC files/" files_disk_full insufficient_storage 507
upload_fault "write EIO files/" files_write_error unavailable 503
upload_fault "fsync EIO files/" files_fsync_error unavailable 503
# the first fsync of the upload's directories passes, the file's own fails
upload_fault "fsync EIO result.h5" file_fsync_error unavailable 503
# the upload's directory fsync after the rename, in the writer's transaction
upload_fault "fsync EIO files/$FAULT_JOB/$FAULT_ATTEMPT\$" store_dir_fsync_error unavailable 503
ls -a "$SVC_TMP/main/files/$FAULT_JOB/$FAULT_ATTEMPT" | grep -q '^\.tmp-'
check refused_uploads_leave_no_temporary_file $(( ! $? )) "$(ls -a "$SVC_TMP/main/files/$FAULT_JOB/$FAULT_ATTEMPT")"

svc_stop main
check server_stops_cleanly "$SVC_STATUS" "exit status $SVC_STATUS"
check_store "$SVC_TMP/main" "$FAULT_RECORD" io_error
