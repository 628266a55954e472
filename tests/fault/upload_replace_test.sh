#!/usr/bin/env bash
# upload_replace_test.sh - a new version of a stored file whose upload fails after it reached the
# disk (server/file_replace.c). It broke so: the directory fsync after the rename, or the
# COMMIT's WAL fsync, failed; the index row was rolled back but the new bytes had replaced the
# old ones, and the file was served as damaged. Under each fault (tests/fault/fault_shim.c) the
# upload is refused (503), and then the job's file listing, the bytes served with their
# X-Checksum-Sha256 and the file on disk all have the SHA-256 of the last acknowledged version,
# with nothing left beside it; the retried upload goes through. A first version refused the same
# way leaves no file. A replacement cut short by a crash (the state it leaves is made by hand:
# the old version kept, the new one in place, the old row) is put back by the start-up sweep.
# At the end check_store (lib.sh): integrity_check, every indexed file at its size and SHA-256.
#   bash tests/fault/upload_replace_test.sh BUILD_DIR
set -u
build=${1:-build}
cd "$(dirname "$0")/../.."
. tests/service/lib.sh
. tests/fault/lib.sh
svc_init "$build"
fault_init "$build" || exit 1
fault_start main --lease-seconds 120 --min-free-mb 0
fault_claim 300000
dir=$SVC_TMP/main/files/$FAULT_JOB/$FAULT_ATTEMPT

# agrees SHA: listing, download (body and header) and disk all hold result.h5 with SHA; nothing
# but the stored files in its directory.
agrees() {
	local listed served header disk
	svc_req GET "/v1/jobs/$FAULT_JOB" "$FAULT_USER" > /dev/null
	listed=$(python3 -c 'import json, sys
print(*[f["sha256"] for f in json.load(sys.stdin)["files"] if f["name"] == "result.h5"])' < "$SVC_BODY")
	svc_req GET "/v1/jobs/$FAULT_JOB/files/result.h5" "$FAULT_USER" > /dev/null
	served=$(sha256sum < "$SVC_BODY" | cut -d' ' -f1)
	header=$(svc_header X-Checksum-Sha256)
	disk=$(sha256sum < "$dir/result.h5" | cut -d' ' -f1)
	echo "listed $listed, served $served, header $header, disk $disk; in the directory: $(ls -A "$dir" | tr '\n' ' ')"
	[ "$listed" = "$1" ] && [ "$served" = "$1" ] && [ "$header" = "$1" ] && [ "$disk" = "$1" ] &&
		[ -z "$(ls -A "$dir" | grep '^\.')" ]
}

got=$(fault_upload)
check first_version_stored "$([ "$got" = 201 ]; echo $?)" "status $got: $(head -c 300 "$SVC_BODY")"

# replace NAME RULE: a new version uploaded under RULE is refused, the last one stays; the retry works.
replace() {
	local name=$1 rule=$2 kept=$FAULT_SUM got why
	fault_version $((200000 + RANDOM))
	echo "$rule" > "$FAULT_CONTROL"
	got=$(fault_upload)
	: > "$FAULT_CONTROL"
	refusal_is unavailable 503
	check "${name}_refused_503" $? "status $got: $(head -c 300 "$SVC_BODY")"
	why=$(agrees "$kept")
	check "${name}_index_and_disk_keep_the_old_version" $? "$why"
	got=$(fault_upload)
	why=$(agrees "$FAULT_SUM")
	check "${name}_retry_replaces_it" "$([ "$got" = 201 ]; echo $?)" "status $got; $why"
}
replace directory_fsync_failed "fsync EIO files/$FAULT_JOB/$FAULT_ATTEMPT\$"
replace commit_failed "fsync EIO poro.db-wal"

echo "fsync EIO files/$FAULT_JOB/$FAULT_ATTEMPT\$" > "$FAULT_CONTROL"
got=$(fault_upload checkpoint.h5)
: > "$FAULT_CONTROL"
code=$(svc_req GET "/v1/jobs/$FAULT_JOB/files/checkpoint.h5" "$FAULT_USER")
[ "$got" = 503 ] && [ "$code" = 404 ] && [ ! -e "$dir/checkpoint.h5" ]
check refused_first_version_leaves_no_file $? "upload $got, download $code; $(ls -A "$dir" | tr '\n' ' ')"

# what a crash between the directory fsync and the COMMIT leaves; and a kept version of a row
# that has moved on (its new version committed, the crash came before the kept one was removed)
svc_stop main
cp "$dir/result.h5" "$dir/.old-$FAULT_SUM-result.h5"
head -c 123457 /dev/urandom > "$dir/result.h5"
cp "$dir/result.h5" "$dir/.old-$(sha256sum < "$dir/result.h5" | cut -d' ' -f1)-result.h5"
svc_start main --lease-seconds 120 --min-free-mb 0
check server_restarts $? "no server"
why=$(agrees "$FAULT_SUM")
check crashed_replacement_put_back_at_start $? "$why"

svc_stop main
check server_stops_cleanly "$SVC_STATUS" "exit status $SVC_STATUS"
check_store "$SVC_TMP/main" "$FAULT_RECORD" upload_replace
