/*
 * jobs_api.c - the users' job routes (docs/service.md §3 "Users"): submit, list, show, cancel,
 * probes (the probes.json a worker extracted from result.h5, served as stored).
 *
 * A submission is checked completely before anything is stored: the request keys and ranges
 * (422 naming the key; threads also against --max-job-threads; memory_mb 0..JOB_MEMORY_MB_MAX,
 * 0 being "not stated"), then the case with the solver's own loader, case_load_json(), on the
 * tree already parsed from the body, so one tree is built, not two. Its "JSON-pointer: message" lines (at most CASE_PROBLEMS_MAX, then a count of the rest)
 * become problems [{"field": "/case<pointer>", "message"}] (422 invalid_case, whose message gives
 * the total). The case is stored in canonical form (json_dumps with JSON_COMPACT |
 * JSON_SORT_KEYS: the loader's c->json), and case_sha256 is the SHA-256 of that text. The
 * idempotency comparison uses the SHA-256 of the whole request in the same canonical form, so key
 * order and white space do not make two identical requests differ. A valid case's warnings (values
 * the loader allows but that are most likely not what was meant, case.h) are answered with the
 * job, as "warnings" [{"field", "message"}] beside the 201 or 200, so that a user who submits over
 * HTTP learns what `poro-solve validate` would have printed; they are not stored.
 */
#define _DEFAULT_SOURCE /* timegm */
#include "api.h"
#include "store.h"

#include "case.h"
#include "digest.h"
#include "jobs_submit.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define PRIORITY_MIN -100
#define PRIORITY_MAX 100
#define THREADS_MAX 256
#define WALL_TIME_MAX 2592000LL           /* s, 30 days */
#define WALL_TIME_DEFAULT JOB_WALL_TIME_DEFAULT /* s, server.h */
#define IDEMPOTENCY_KEY_MAX 200
#define LIST_LIMIT_MAX 1000
#define LIST_LIMIT_DEFAULT 100
#define ID_MAX 999999999999999999LL

/* Turns the loader's "pointer: message" lines (its problems, or a valid case's warnings) into
 * [{"field": "/case<pointer>", "message"}]; the loader's last line "... and N more problems" is not
 * a problem of its own (the total is case_problem_count's). */
static json_t *case_problems(const char *message)
{
	json_t *problems = json_array();
	const char *line = message;
	while (problems && line && *line) {
		const char *end = strchr(line, '\n');
		size_t n = end ? (size_t)(end - line) : strlen(line);
		if (strncmp(line, CASE_PROBLEMS_MORE, strlen(CASE_PROBLEMS_MORE)) == 0)
			break;
		const char *sep = memchr(line, ':', n);
		char field[SERVER_FIELD_MAX] = "/case";
		const char *text = line;
		size_t text_n = n;
		if (sep && line[0] == '/') {
			size_t pn = (size_t)(sep - line);
			if (!(pn == 1 && line[0] == '/'))  /* "/" is the whole case */
				snprintf(field, sizeof field, "/case%.*s", (int)pn, line);
			text = sep + 1;
			text_n = n - pn - 1;
			while (text_n && *text == ' ') {
				text++;
				text_n--;
			}
		}
		if (n)
			json_array_append_new(problems, json_pack("{s:s, s:s%}", "field", field, "message", text, text_n));
		line = end ? end + 1 : NULL;
	}
	return problems;
}

/* Validates the case; 0 with the loaded case in *loaded (its json is the canonical text), or -1
 * after replying 422 with the problems. */
static int check_case(struct request *r, const json_t *case_spec, struct case_spec **loaded)
{
	struct poro_error *perr = calloc(1, sizeof *perr);
	if (!perr) {
		reply_fail(r, API_UNAVAILABLE, "", "no memory to check the case: retry later");
		return -1;
	}
	enum poro_status st = jobs_case_load(case_spec, loaded, perr);   /* by the loader its schema names */
	if (st == PORO_OK) {
		free(perr);
		return 0;
	}
	if (st != PORO_EINVAL) {      /* out of memory: the case may be fine, so try again later */
		reply_fail(r, st == PORO_ENOMEM ? API_UNAVAILABLE : API_INTERNAL, "/case", "cannot check the case: %s",
			   perr->message);
		free(perr);
		return -1;
	}
	struct api_error err = { 0 };
	api_fail(&err, API_INVALID_CASE, "/case", "case is invalid");
	err.problems = case_problems(perr->message);
	size_t listed = json_array_size(err.problems);
	long total = case_problem_count(perr->message);
	if (listed > 0) {
		json_t *first = json_array_get(err.problems, 0);
		char shown[64] = "";
		if ((long)listed < total)
			snprintf(shown, sizeof shown, " (the first %zu listed)", listed);
		snprintf(err.field, sizeof err.field, "%s", json_string_value(json_object_get(first, "field")));
		snprintf(err.message, sizeof err.message, "case is invalid: %ld problem%s%s, first: %s", total,
			 total > 1 ? "s" : "", shown, json_string_value(json_object_get(first, "message")));
	}
	free(perr);
	reply_error(r, &err);
	return -1;
}

/* A job may ask for at most this server's --max-job-threads: 0, or -1 after replying 422. */
static int check_threads(struct request *r, long long threads)
{
	int limit = r->srv->cfg.max_job_threads;
	if (threads <= limit)
		return 0;
	reply_fail(r, API_INVALID_REQUEST, "/threads",
		   "'threads' must be at most %d, this server's limit (--max-job-threads), got %lld", limit, threads);
	return -1;
}

static int idempotency_key(struct request *r, const char **key)
{
	*key = http_header(r, "Idempotency-Key");
	if (!*key)
		return 0;
	size_t n = strlen(*key);
	int ok = n >= 1 && n <= IDEMPOTENCY_KEY_MAX;
	for (size_t i = 0; ok && i < n; i++)
		ok = (*key)[i] > 0x20 && (*key)[i] < 0x7f;
	if (!ok) {
		reply_fail(r, API_INVALID_HEADER, "Idempotency-Key",
			   "Idempotency-Key must be 1..%d visible ASCII characters", IDEMPOTENCY_KEY_MAX);
		return -1;
	}
	return 0;
}

/* What a checked submission stores: its canonical case and request digests, without the trees
 * they came from. */
struct submission {
	char *canonical;                 /* the case in canonical form, owned */
	char *name;                      /* owned, or NULL */
	char *title;                     /* the case's title, owned, or NULL */
	json_t *warnings;                /* the case's warnings as [{field, message}], owned */
	const char *key;                 /* the Idempotency-Key header, or NULL */
	char *batch;                     /* owned, or NULL (jobs_batch.c) */
	int exclusive;
	long long priority, threads, wall, memory_mb;
	char case_sha[DIGEST_HEX_SIZE], body_sha[DIGEST_HEX_SIZE];
};

static void submission_release(struct submission *s)
{
	free(s->canonical);
	free(s->name);
	free(s->title);
	free(s->batch);
	json_decref(s->warnings);
}

/* The costly part of a submission: parses the body, checks the request and validates the case,
 * then frees both trees (and the body's text), keeping only what the store needs. 0, or -1 after
 * replying. */
static int submission_check(struct request *r, struct submission *s)
{
	static const char *const keys[] = { "case", "priority", "threads", "wall_time_seconds", "memory_mb", "name",
					    "batch", "exclusive", NULL };
	json_t *body = api_body_object(r);
	if (!body)
		return -1;
	const char *name;
	char *whole = NULL;
	struct case_spec *loaded = NULL;
	int rc = -1;
	json_t *case_spec = json_object_get(body, "case");
	if (api_known_keys(r, body, keys) || idempotency_key(r, &s->key))
		goto done;
	if (!json_is_object(case_spec)) {
		reply_fail(r, API_INVALID_REQUEST, "/case", case_spec ? "'case' must be an object" : "missing required key 'case'");
		goto done;
	}
	if (api_int_member(r, body, "priority", PRIORITY_MIN, PRIORITY_MAX, 0, &s->priority) ||
	    api_int_member(r, body, "threads", 1, THREADS_MAX, 1, &s->threads) || check_threads(r, s->threads) ||
	    api_int_member(r, body, "wall_time_seconds", 1, WALL_TIME_MAX, WALL_TIME_DEFAULT, &s->wall) ||
	    api_int_member(r, body, "memory_mb", 0, JOB_MEMORY_MB_MAX, 0, &s->memory_mb) ||
	    api_string_member(r, body, "name", SERVER_NAME_MAX, 0, &name) ||
	    jobs_batch_members(r, body, &s->batch, &s->exclusive) || check_case(r, case_spec, &loaded))
		goto done;
	whole = json_dumps(body, JSON_COMPACT | JSON_SORT_KEYS);
	s->name = name ? strdup(name) : NULL;
	s->warnings = case_problems(loaded->warnings);
	s->title = loaded->title[0] ? strdup(loaded->title) : NULL;
	if (!whole || (name && !s->name) || !s->warnings || (loaded->title[0] && !s->title)) {
		reply_fail(r, API_UNAVAILABLE, "", "no memory to store the case: retry later");
		goto done;
	}
	s->canonical = loaded->json; /* taken from the loaded case, which is freed below */
	loaded->json = NULL;
	digest_hex(s->canonical, strlen(s->canonical), s->case_sha);
	digest_hex(whole, strlen(whole), s->body_sha);
	rc = 0;
done:
	case_destroy(&loaded);
	free(whole);
	json_decref(body);
	free(r->body); /* the text is not needed any more either: free it before the durable write */
	r->body = NULL;
	r->body_size = 0;
	return rc;
}

/* Parsing and validation take their turn among the submissions being checked
 * (http_submission_enter); the durable write, which waits on an fsync, does not, so group commit
 * still gathers every submission in flight into one transaction. */
void jobs_submit(struct request *r)
{
	struct submission s = { 0 };
	if (http_submission_enter(r) != 0)
		return;
	int checked = submission_check(r, &s) == 0;
	http_submission_leave(r);
	if (!checked) {
		submission_release(&s);
		return;
	}
	struct job_submit in = { .who = &r->who, .idempotency_key = s.key, .body_sha256 = s.body_sha,
				 .case_json = s.canonical, .case_sha256 = s.case_sha, .name = s.name, .case_title = s.title,
				 .priority = (int)s.priority, .threads = (int)s.threads,
				 .wall_time_seconds = (int)s.wall, .memory_mb = s.memory_mb, .batch = s.batch,
				 .exclusive = s.exclusive };
	json_t *job = NULL;
	int created = 0;
	struct api_error err = { 0 };
	if (store_job_submit(r->srv->store, &in, &job, &created, &err) != API_OK) {
		reply_error(r, &err);
	} else {
		char location[64];
		snprintf(location, sizeof location, "/v1/jobs/%lld",
			 (long long)json_integer_value(json_object_get(job, "id")));
		reply_header(r, "Location", location);
		json_object_set_new(job, "warnings", s.warnings);   /* the answer's, not stored */
		s.warnings = NULL;
		reply_json(r, created ? 201 : 200, job);
	}
	submission_release(&s);
}

/* POST /v1/cases/validate: the checks of a submission, nothing stored (docs/web.md, "Submit"). The
 * body is what POST /v1/jobs takes, so its problems name the same fields (/case/...); a valid one
 * answers 200 with the case's title, the SHA-256 its job would get and the case's warnings. */
void jobs_validate(struct request *r)
{
	struct submission s = { 0 };
	if (http_submission_enter(r) != 0)
		return;
	int checked = submission_check(r, &s) == 0;
	http_submission_leave(r);
	if (checked) {
		reply_json(r, 200, json_pack("{s:b, s:s, s:o, s:O}", "valid", 1, "case_sha256", s.case_sha, "title",
					     s.title ? json_string(s.title) : json_null(), "warnings", s.warnings));
	}
	submission_release(&s);
}

static int parse_states(struct request *r, unsigned *mask)
{
	char text[256];
	int have = http_query(r, "state", text, sizeof text);
	*mask = 0;
	if (have == 0)
		return 0;
	char *save = NULL;
	for (char *tok = have > 0 ? strtok_r(text, ",", &save) : NULL; tok; tok = strtok_r(NULL, ",", &save)) {
		enum job_state st;
		if (job_state_parse(tok, &st) != 0) {
			have = -1;
			break;
		}
		*mask |= 1u << st;
	}
	if (have < 0 || *mask == 0) {
		reply_fail(r, API_INVALID_PARAMETER, "state",
			   "query parameter 'state' must be a comma-separated list of queued, running, succeeded, "
			   "failed, cancelled");
		return -1;
	}
	return 0;
}

/* A text filter of the search: 1 when given (into out), 0 when absent or empty, -1 after replying. */
static int search_text(struct request *r, const char *name, char *out, size_t size)
{
	int have = http_query(r, name, out, size);
	if (have < 0) {
		reply_fail(r, API_INVALID_PARAMETER, name, "query parameter '%s' is too long or badly encoded", name);
		return -1;
	}
	return have && out[0];
}

/* A time of the search, RFC 3339 ("2026-12-07T10:30:00Z", seconds and fraction optional) or a
 * date ("2026-12-07": its start, or with end_of_day its last millisecond), UTC: ms into *ms (0
 * when absent), or -1 after replying 400. */
static int search_time(struct request *r, const char *name, int end_of_day, long long *ms)
{
	char text[64];
	*ms = 0;
	int have = http_query(r, name, text, sizeof text);
	if (have == 0 || (have > 0 && !text[0]))
		return 0;
	struct tm tm = { 0 };
	int frac = 0, n = 0, used = 0;
	double seconds = 0;
	int ok = have > 0 && sscanf(text, "%4d-%2d-%2d%n", &tm.tm_year, &tm.tm_mon, &tm.tm_mday, &n) == 3 && n == 10;
	if (ok && text[10]) {
		ok = (text[10] == 'T' || text[10] == ' ') &&
		     sscanf(text + 11, "%2d:%2d%n", &tm.tm_hour, &tm.tm_min, &used) == 2;
		const char *rest = text + 11 + used;
		if (ok && *rest == ':') {
			ok = sscanf(rest + 1, "%lf%n", &seconds, &frac) == 1 && seconds >= 0 && seconds < 61;
			rest += 1 + frac;
		}
		ok = ok && (!strcmp(rest, "Z") || !*rest);
	}
	tm.tm_year -= 1900;
	tm.tm_mon -= 1;
	ok = ok && tm.tm_mon >= 0 && tm.tm_mon < 12 && tm.tm_mday >= 1 && tm.tm_mday <= 31 && tm.tm_hour < 24 &&
	     tm.tm_min < 60 && tm.tm_year >= 70;
	if (!ok) {
		reply_fail(r, API_INVALID_PARAMETER, name,
			   "query parameter '%s' must be a UTC date (2026-12-07) or time (2026-12-07T10:30:00Z)", name);
		return -1;
	}
	*ms = (long long)timegm(&tm) * 1000 + (long long)(seconds * 1000);
	if (end_of_day && !text[10])
		*ms += 86400000LL - 1;
	return 0;
}

/* The dashboard's filters (docs/web.md, "Jobs"): 1 with q filled when any is given, 0 when none
 * is (the plain listing), -1 after replying 400. */
static int search_query(struct request *r, struct job_search *q, char user[SERVER_NAME_MAX + 1],
			char name[SERVER_NAME_MAX + 1], char title[SERVER_NAME_MAX * 2])
{
	char order[16];
	int have_order = http_query(r, "order", order, sizeof order);
	if (have_order < 0 || (have_order > 0 && strcmp(order, "newest") && strcmp(order, "oldest"))) {
		reply_fail(r, API_INVALID_PARAMETER, "order", "query parameter 'order' must be newest or oldest");
		return -1;
	}
	int u = search_text(r, "user", user, SERVER_NAME_MAX + 1);
	int n = u < 0 ? -1 : search_text(r, "name", name, SERVER_NAME_MAX + 1);
	int t = n < 0 ? -1 : search_text(r, "title", title, SERVER_NAME_MAX * 2);
	if (t < 0 || search_time(r, "created_after", 0, &q->created_from) ||
	    search_time(r, "created_before", 1, &q->created_to))
		return -1;
	q->user = u ? user : NULL;
	q->name = n ? name : NULL;
	q->title = t ? title : NULL;
	q->oldest_first = have_order > 0 && !strcmp(order, "oldest");
	return u || n || t || q->created_from || q->created_to || q->oldest_first;
}

void jobs_list(struct request *r)
{
	unsigned states;
	long long limit, after;
	struct job_search q = { 0 };
	char user[SERVER_NAME_MAX + 1], name[SERVER_NAME_MAX + 1], title[SERVER_NAME_MAX * 2];
	if (parse_states(r, &states) || api_query_int(r, "limit", 1, LIST_LIMIT_MAX, LIST_LIMIT_DEFAULT, &limit) ||
	    api_query_int(r, "after", 1, ID_MAX, 0, &after))
		return;
	int search = search_query(r, &q, user, name, title);
	if (search < 0)
		return;
	json_t *page = NULL;
	struct api_error err = { 0 };
	q.states = states;
	q.limit = (int)limit;
	q.after = after;
	enum api_code rc = search ? store_job_search(r->srv->store, &r->who, &q, &page, &err)
				  : store_job_list(r->srv->store, &r->who, states, (int)limit, after, &page, &err);
	if (rc != API_OK) {
		reply_error(r, &err);
		return;
	}
	reply_json(r, 200, page);
}

void jobs_show(struct request *r)
{
	json_t *job = NULL;
	struct api_error err = { 0 };
	if (store_job_get(r->srv->store, &r->who, r->id, 1, &job, &err) != API_OK) {
		reply_error(r, &err);
		return;
	}
	reply_json(r, 200, job);
}

void jobs_cancel(struct request *r)
{
	if (r->body_size) {
		json_t *body = api_body_object(r);
		static const char *const none[] = { NULL };
		int bad = !body || api_known_keys(r, body, none);
		json_decref(body);
		if (bad)
			return;
	}
	json_t *job = NULL;
	struct api_error err = { 0 };
	if (store_job_cancel(r->srv->store, &r->who, r->id, &job, &err) != API_OK) {
		reply_error(r, &err);
		return;
	}
	reply_json(r, 200, job);
}

/* The probe series of the job's newest attempt that has them, for plots: the probes.json the worker
 * extracted from result.h5 with `poro-solve probes` (in its own process: the server never parses a
 * result file) and uploaded, checked as JSON at upload, sent as stored and checked like any stored
 * file. A job without probes.json yet is 404 saying so. */
void jobs_probes(struct request *r)
{
	files_serve_newest(r, "probes.json", "probes");
}
