/*
 * job.h - one claimed job from start to finish: the job directory WORK/job-<id>-<attempt>/, the
 * checkpoint download when the claim carries one, the solver child, the log chunks, heartbeats
 * with progress, checkpoint uploads, cancel and wall-time enforcement, the final uploads and the
 * finish call (docs/service.md §2, §3 "Workers"). A write refused as stale (409) or for a job
 * that is gone (404) means the lease is lost: the solver's group is killed at once, the directory
 * removed, and nothing more is sent. A file of the attempt that did not reach the server keeps the
 * directory (§3 "Success needs its files").
 */
#ifndef PORO_JOB_H
#define PORO_JOB_H

#include <jansson.h>

#include "http_client.h"

/* Runs the job of a claim answer ({"id", "attempt", "case", "exclusive", ...}) to its end with c,
 * which must not abort on drain. Returns when the job is finished or abandoned and its directory is
 * removed (or kept: --keep-work, or files the server does not hold): 1 when the job had its turn
 * to start (slot_try_start said yes; the caller then calls slot_finished), 0 when it never got one. */
int job_run(struct http_client *c, const json_t *claim);

#endif
