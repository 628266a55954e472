/*
 * api.h - the route handlers (docs/service.md §3), grouped by caller: jobs_api.c (users),
 * worker_api.c and files.c (workers), logs.c (log reading and following), admin_api.c (operators),
 * and the JSON helpers they share (api_json.c). The route table that maps paths to these lives in
 * http.c.
 */
#ifndef PORO_API_H
#define PORO_API_H

#include "http.h"

/* users */
void jobs_submit(struct request *r);
void jobs_list(struct request *r);
void jobs_show(struct request *r);
void jobs_cancel(struct request *r);
void jobs_delete(struct request *r);
void jobs_probes(struct request *r);
void logs_get(struct request *r);
void files_get(struct request *r);

/* workers */
void worker_claim(struct request *r);
void worker_heartbeat(struct request *r);
void worker_log(struct request *r);
void worker_finish(struct request *r);
void worker_file_get(struct request *r);
void files_upload_begin(struct request *r);
int files_upload_data(struct request *r, const char *data, size_t size);
void files_upload_end(struct request *r);
void files_upload_abort(struct request *r);

/* An indexed stored file (store_file_find). */
struct stored_file {
	long long id;
	int attempt;
	const char *name;
	long long size;                   /* bytes, as indexed */
	const char *sha256;               /* as indexed */
};
/* Answers with the stored file, checked against its index row on the way (files_serve.c): its
 * size always, its SHA-256 for whole-file downloads; a damaged copy is 500 stored_file_damaged. */
void files_serve(struct request *r, const struct stored_file *f, const char *content_type);
/* Answers with the newest attempt's version of a JSON file a worker derived from result.h5
 * (probes.json, frames.json) of the job {id}, as files_serve; 404 naming what (e.g. "probes")
 * while no attempt has uploaded it. */
void files_serve_newest(struct request *r, const char *name, const char *what);

/* the dashboard (docs/web.md): static files (web.c), validation without a job (jobs_api.c), a
 * job's case and the admin view (web_api.c), the field viewer's frames (frames.c) */
void web_index(struct request *r);
void web_file(struct request *r);
/* WEB_ROOT when --web-root is not given: BINDIR/../share/poro/web or BINDIR/../web, the first
 * holding index.html, into out; "" when neither does. */
void web_root_default(char *out, size_t size);
void jobs_validate(struct request *r);
void web_job_case(struct request *r);
void web_admin_workers(struct request *r);
void frames_index(struct request *r);
void frames_get(struct request *r);

/* operators */
void admin_healthz(struct request *r);
void admin_metrics(struct request *r);
void admin_users_create(struct request *r);
void admin_tokens_create(struct request *r);
void admin_tokens_list(struct request *r);
void admin_tokens_revoke(struct request *r);

/* ---- request-body helpers (api_json.c) ---- */
/* The body as a JSON object; NULL after replying 400 invalid_json (with jansson's line and column),
 * or 503 when jansson runs out of memory. The body's syntax has been checked by http.c already. */
json_t *api_body_object(struct request *r);
/* Refuses keys of obj not in the NULL-terminated list: 0, or -1 after replying 422 naming the key. */
int api_known_keys(struct request *r, json_t *obj, const char *const *keys);
/* Optional integer member in [min, max] (default def when absent or null); -1 after replying 422. */
int api_int_member(struct request *r, json_t *obj, const char *key, long long min, long long max, long long def,
		   long long *out);
/* Optional string member of 1..max bytes without control characters (NULL when absent or null, or
 * when required is 0); -1 after replying 422. */
int api_string_member(struct request *r, json_t *obj, const char *key, size_t max, int required, const char **out);
/* A query parameter as an integer in [min, max], default def: 0, or -1 after replying 400. */
int api_query_int(struct request *r, const char *name, long long min, long long max, long long def, long long *out);
/* File names: ^[A-Za-z0-9][A-Za-z0-9._-]{0,127}$ and no "..". Decodes the raw path element into
 * out[129]; 0, or -1 after replying 400 invalid_file_name. */
int api_file_name(struct request *r, const char *raw, char out[129]);
/* 1 when a decoded name follows the rule of api_file_name (for names inside JSON bodies). */
int api_file_name_valid(const char *name);
/* The job {id} of the path exists and the caller may see it: 0, or -1 after replying (404 for
 * another user's job, as for a missing one). */
int api_job_visible(struct request *r);

#endif
