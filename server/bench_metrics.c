/*
 * bench_metrics.c - a job's metrics.json as the server reads it for a benchmark run (bench.h).
 *
 * metrics.json is a file of the job like any other: uploaded by the worker (checked then to be
 * one JSON object, files.c), stored under STATE/files/<job>/<attempt>/, indexed with its size
 * and SHA-256. Before reading it the server checks the copy on disk against that row, as every
 * download does (files_serve.c), so a damaged copy is reported, never judged. It is small (a few
 * kB); more than BENCH_METRICS_MAX bytes is refused unread.
 */
#include "bench.h"
#include "store.h"

#include "digest.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define METRICS_NAME "metrics.json"

/* Reads path whole into a NUL-terminated buffer of at most max bytes; NULL with why. */
static char *read_whole(const char *path, long long want, char *why, size_t why_size)
{
	FILE *f = fopen(path, "rb");
	if (!f) {
		snprintf(why, why_size, "cannot open the stored metrics.json: %s", strerror(errno));
		return NULL;
	}
	char *text = malloc((size_t)want + 1);
	size_t got = text ? fread(text, 1, (size_t)want + 1, f) : 0;
	fclose(f);
	if (!text) {
		snprintf(why, why_size, "no memory to read metrics.json");
		return NULL;
	}
	if ((long long)got != want) {
		snprintf(why, why_size, "the stored metrics.json is damaged: it has %s%zu bytes on disk but %lld were "
			 "stored", (long long)got > want ? "more than " : "", got, want);
		free(text);
		return NULL;
	}
	text[got] = '\0';
	return text;
}

json_t *bench_job_metrics(struct server *srv, long long job, char *why, size_t why_size)
{
	int attempt;
	long long size;
	char sha[DIGEST_HEX_SIZE], got[DIGEST_HEX_SIZE], path[SERVER_PATH_MAX];
	struct api_error err = { 0 };
	if (store_file_find(srv->store, job, METRICS_NAME, -1, &attempt, &size, sha, &err) != API_OK) {
		if (err.code == API_NOT_FOUND)
			snprintf(why, why_size, "job %lld uploaded no metrics.json", job);
		else
			snprintf(why, why_size, "%s", err.message);
		return NULL;
	}
	if (size > BENCH_METRICS_MAX) {
		snprintf(why, why_size, "the metrics.json of job %lld has %lld bytes, more than the %d read", job, size,
			 BENCH_METRICS_MAX);
		return NULL;
	}
	snprintf(path, sizeof path, "%s/files/%lld/%d/%s", srv->cfg.state, job, attempt, METRICS_NAME);
	char *text = read_whole(path, size, why, why_size);
	if (!text)
		return NULL;
	digest_hex(text, (size_t)size, got);
	json_error_t jerr;
	json_t *doc = NULL;
	if (!digest_hex_equal(got, sha))
		snprintf(why, why_size, "the stored metrics.json of job %lld is damaged: its SHA-256 is %s, %s was stored",
			 job, got, sha);
	else if (!(doc = json_loads(text, JSON_REJECT_DUPLICATES, &jerr)) || !json_is_object(doc))
		snprintf(why, why_size, "the metrics.json of job %lld is not a JSON object: %s", job,
			 doc ? "another value" : jerr.text);
	free(text);
	if (doc && !json_is_object(doc)) {
		json_decref(doc);
		doc = NULL;
	}
	return doc;
}

void bench_fingerprint(const json_t *machine, char *out)
{
	out[0] = '\0';
	if (!json_is_object(machine))
		return;
	/* the fields that make two runs' timings comparable; not the host name */
	char *text = NULL;
	json_t *key = json_pack("[O?, O?, O?, O?, O?, O?]", json_object_get(machine, "cpu_model"),
				json_object_get(machine, "cores"), json_object_get(machine, "memory_mb"),
				json_object_get(machine, "kernel"), json_object_get(machine, "compiler"),
				json_object_get(machine, "blas"));
	if (key && (text = json_dumps(key, JSON_COMPACT))) {
		char hex[DIGEST_HEX_SIZE];
		digest_hex(text, strlen(text), hex);
		snprintf(out, BENCH_FINGERPRINT_HEX + 1, "%.*s", BENCH_FINGERPRINT_HEX, hex);
	}
	free(text);
	json_decref(key);
}
