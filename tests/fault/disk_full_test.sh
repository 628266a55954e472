#!/usr/bin/env bash
# disk_full_test.sh - the server on a file system that really fills up: its state directory on a
# small tmpfs (mount needs root or CAP_SYS_ADMIN; without them the test says so in an INFO line
# and checks nothing: io_error_test.sh injects ENOSPC without privileges). The disk is filled
# with a file while the server runs, under submissions and a worker's uploads:
#   - every submission is answered 201 (while room is left) or 507 insufficient_storage with a
#     JSON error and Retry-After; never a 500, a reset or a crash; uploads likewise;
#   - /healthz turns degraded;
#   - when the file is removed (space returns) the server recovers by itself: /healthz is ok and
#     submissions are acknowledged again;
# and after a clean stop, check_store (lib.sh): integrity_check, every acknowledged submission
# present once, every indexed file on disk.
#   bash tests/fault/disk_full_test.sh BUILD_DIR
set -u
build=${1:-build}
cd "$(dirname "$0")/../.."
. tests/service/lib.sh
. tests/fault/lib.sh
svc_init "$build"

mnt="$SVC_TMP/disk"
mkdir -p "$mnt"
if ! err=$(mount -t tmpfs -o size=48m,mode=0700 poro-disk-full "$mnt" 2>&1); then
	echo "INFO disk_full_test: no tmpfs can be mounted here ($err): the real full disk is not tried (io_error_test.sh injects ENOSPC)"
	exit 0
fi
# the servers stop before the tmpfs goes, and it goes before the temporary directory is removed
trap 'for p in "${SVC_PIDS[@]}"; do kill -TERM "$p" 2>/dev/null; wait "$p" 2>/dev/null; done; umount -l "$mnt"; svc_cleanup' EXIT

# svc_start puts the state in $SVC_TMP/NAME: make that the tmpfs
state="$SVC_TMP/full"
ln -s "$mnt" "$state"
svc_start full --lease-seconds 60 --min-free-mb 1
check server_starts_on_tmpfs $? "no server"
fault_client_init full
fault_claim 2000000

# Fill the disk, then submit until the database has no room left either (what the WAL had
# allocated may take a few more); each answer must be 201 or 507.
dd if=/dev/zero of="$mnt/filler" bs=1M > /dev/null 2>&1
others="" full=0
for i in $(seq 400); do
	got=$(submit_once "full-$i")
	case $got in
	201) ;;
	507) refusal_is insufficient_storage 507 || others="$others full-$i: 507 without the JSON error or Retry-After;"
	     full=$((full + 1)); [ "$full" -ge 3 ] && break ;;
	*) others="$others full-$i: $got $(head -c 200 "$SVC_BODY");" ;;
	esac
done
[ -z "$others" ]
check full_disk_answers_are_201_or_507 $? "$others"
[ "$full" -ge 3 ]
check full_disk_refuses_submissions_507 $? "$full refusals in 400 submissions"
echo "INFO disk_full_test: $(( $(wc -l < "$FAULT_RECORD") - 3 )) submissions acknowledged after the filler, then 507"
got=$(fault_upload)
refusal_is insufficient_storage 507
check full_disk_refuses_upload_507 $? "status $got: $(head -c 300 "$SVC_BODY")"
wait_for 20 health_is 503
check full_disk_health_degraded $? "$(curl -s "$SVC_URL/healthz")"
kill -0 "$SVC_PID"
check full_disk_server_alive $? "the server died"

rm -f "$mnt/filler"
wait_for 20 health_is 200
check space_returns_health_recovers_by_itself $? "$(curl -s "$SVC_URL/healthz")"
got=$(submit_once "after-1")
[ "$got" = 201 ]
check space_returns_submissions_acknowledged $? "status $got: $(head -c 300 "$SVC_BODY")"
got=$(fault_upload)
[ "$got" = 201 ]
check space_returns_upload_stored $? "status $got: $(head -c 300 "$SVC_BODY")"
svc_stop full
check server_stops_cleanly "$SVC_STATUS" "exit status $SVC_STATUS"
check_store "$mnt" "$FAULT_RECORD" disk_full
