/*
 * jobs_delete.c - DELETE /v1/jobs/{id} (docs/service.md §3 "Users"): removes a finished job and
 * everything stored for it, so a user at the storage quota can free space.
 *
 * The database rows go first, in one write (store_job_delete); only then are the job's files
 * removed from disk, so a failure never leaves an index row pointing at a missing file. A crash
 * between the two leaves a directory without a job, which the next start-up sweep removes
 * (file_sweep.c). The answer says what was freed: the stored bytes counted against the quota and
 * the rows removed.
 */
#include "api.h"
#include "log.h"
#include "file_sweep.h"
#include "store.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>

void jobs_delete(struct request *r)
{
	struct job_freed f;
	struct api_error err = { 0 };
	if (store_job_delete(r->srv->store, &r->who, r->id, &f, &err) != API_OK) {
		reply_error(r, &err);
		return;
	}
	long long disk = 0;
	if (file_sweep_job(r->srv->cfg.state, r->id, &disk) != 0)
		log_say(LOG_PRIO_WARNING,
			"cannot remove all files of deleted job %lld: %s (the next start-up removes them)", r->id,
			strerror(errno));
	reply_json(r, 200, json_pack("{s:I, s:b, s:I, s:I, s:I, s:I, s:I}", "id", (json_int_t)r->id, "deleted", 1,
				     "freed_bytes", (json_int_t)f.bytes, "files", (json_int_t)f.files,
				     "log_chunks", (json_int_t)f.log_chunks, "events", (json_int_t)f.events,
				     "idempotency_keys", (json_int_t)f.idempotency_keys));
}
