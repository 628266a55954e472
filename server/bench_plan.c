/*
 * bench_plan.c - the check of a benchmark run's plan, the body of POST /v1/benchmarks (bench.h,
 * schemas/openapi.yaml BenchmarkCreate). Every value is checked before anything is stored, and a
 * bad one is answered 422 invalid_request with its JSON pointer ("/cases/2/figures/0/band") and
 * what it must be. The kinds of figures, their units and classes are the solver's (figures.h),
 * which poro-server links for case validation anyway.
 */
#include "bench.h"
#include "jobs_submit.h"
#include "store.h"

#include "figures.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static const struct regression_rule RULE_DEFAULT = REGRESSION_RULE_DEFAULT;
#define HISTORY_RUNS_MAX 1000
#define COMMIT_MAX 128
#define HOST_MAX 128

/* Replies 422 on field (printf-formatted pointer) with message; returns -1. */
static int refuse(struct request *r, const char *field, const char *message)
{
	reply_fail(r, API_INVALID_REQUEST, field, "%s: %s", field, message);
	return -1;
}

/* Refuses keys of obj not in allowed; the pointer of obj is base. */
static int known_keys(struct request *r, const json_t *obj, const char *base, const char *const *allowed)
{
	const char *key = bench_unknown_key(obj, allowed);
	char field[SERVER_FIELD_MAX];
	snprintf(field, sizeof field, "%s/%.64s", base, key ? key : "");
	return key ? refuse(r, field, "unknown key") : 0;
}

/* A number member in [lo, hi] (default def when absent); -1 after replying. */
static int number_in(struct request *r, const json_t *obj, const char *base, const char *key, double lo, double hi,
		     double def, double *out)
{
	const json_t *v = json_object_get(obj, key);
	char field[SERVER_FIELD_MAX], why[128];
	*out = def;
	if (!v || json_is_null(v))
		return 0;
	snprintf(field, sizeof field, "%s/%s", base, key);
	snprintf(why, sizeof why, "must be a number from %g to %g", lo, hi);
	if (!json_is_number(v) || !(json_number_value(v) >= lo && json_number_value(v) <= hi))
		return refuse(r, field, why);
	*out = json_number_value(v);
	return 0;
}

/* The "settings" object: alpha, min_effect, history_runs, with their defaults filled in. */
static json_t *check_settings(struct request *r, const json_t *body)
{
	static const char *const keys[] = { "alpha", "min_effect", "history_runs", NULL };
	const json_t *s = json_object_get(body, "settings");
	double alpha, effect, runs;
	if (s && !json_is_null(s) && !json_is_object(s)) {
		refuse(r, "/settings", "must be an object");
		return NULL;
	}
	if ((s && json_is_object(s) && known_keys(r, s, "/settings", keys)) ||
	    number_in(r, s, "/settings", "alpha", 1e-9, 0.5, RULE_DEFAULT.alpha, &alpha) ||
	    number_in(r, s, "/settings", "min_effect", 0, 10, RULE_DEFAULT.min_effect, &effect) ||
	    number_in(r, s, "/settings", "history_runs", 1, HISTORY_RUNS_MAX, RULE_DEFAULT.history_runs, &runs))
		return NULL;
	if (runs != floor(runs)) {
		refuse(r, "/settings/history_runs", "must be a whole number");
		return NULL;
	}
	return json_pack("{s:f, s:f, s:i}", "alpha", alpha, "min_effect", effect, "history_runs", (int)runs);
}

void bench_plan_rule(const json_t *plan, struct regression_rule *rule)
{
	const json_t *s = json_object_get(plan, "settings");
	*rule = RULE_DEFAULT;
	if (json_is_number(json_object_get(s, "alpha")))
		rule->alpha = json_number_value(json_object_get(s, "alpha"));
	if (json_is_number(json_object_get(s, "min_effect")))
		rule->min_effect = json_number_value(json_object_get(s, "min_effect"));
	if (json_is_integer(json_object_get(s, "history_runs")))
		rule->history_runs = (int)json_integer_value(json_object_get(s, "history_runs"));
}

/* A band [min, max], either end null (open); -1 after replying. */
static int check_band(struct request *r, const json_t *band, const char *field)
{
	const json_t *lo = json_array_get(band, 0), *hi = json_array_get(band, 1);
	int ok = json_is_array(band) && json_array_size(band) == 2 && (json_is_null(lo) || json_is_number(lo)) &&
		 (json_is_null(hi) || json_is_number(hi)) && !(json_is_null(lo) && json_is_null(hi));
	if (!ok)
		return refuse(r, field, "must be [min, max]: two numbers, or one and null for an open end");
	if (json_is_number(lo) && json_is_number(hi) && json_number_value(lo) > json_number_value(hi))
		return refuse(r, field, "min must not exceed max");
	return 0;
}

/* One figure {"kind", "check", "band"} of case i; -1 after replying. */
static int check_figure(struct request *r, const json_t *f, const char *base)
{
	static const char *const keys[] = { "kind", "check", "band", NULL };
	char field[SERVER_FIELD_MAX];
	if (!json_is_object(f))
		return refuse(r, base, "must be an object {\"kind\", \"check\", \"band\"}");
	if (known_keys(r, f, base, keys))
		return -1;
	const char *kind = json_string_value(json_object_get(f, "kind"));
	const char *check = json_string_value(json_object_get(f, "check"));
	snprintf(field, sizeof field, "%.200s/kind", base);
	if (!kind || figure_parse(kind) < 0)
		return refuse(r, field, "must name a figure the solver reports (docs/benchmarks.md: terzaghi_rms, "
			      "cpu_us_per_point_step, ...)");
	snprintf(field, sizeof field, "%.200s/check", base);
	if (!check || (strcmp(check, "band") && strcmp(check, "history") && strcmp(check, "none")))
		return refuse(r, field, "must be \"band\", \"history\" or \"none\"");
	if (!strcmp(check, "history") && figure_class((enum figure_kind)figure_parse(kind)) != FIGURE_TIMING)
		return refuse(r, field, "\"history\" is for timing figures; judge an accuracy or count figure by a band");
	const json_t *band = json_object_get(f, "band");
	snprintf(field, sizeof field, "%.200s/band", base);
	if (!strcmp(check, "band"))
		return check_band(r, band, field);
	if (band && !json_is_null(band))
		return refuse(r, field, "only a figure checked against a band has one");
	return 0;
}

/* The jobs of case i: ids of jobs the caller sees, carrying the run's label. */
static int check_jobs(struct request *r, const json_t *jobs, const char *base, const char *label)
{
	char field[SERVER_FIELD_MAX], why[SERVER_MESSAGE_MAX];
	if (!json_is_array(jobs) || json_array_size(jobs) > BENCH_JOBS_MAX) {
		snprintf(why, sizeof why, "must be an array of at most %d job ids", BENCH_JOBS_MAX);
		return refuse(r, base, why);
	}
	size_t k;
	const json_t *id;
	json_array_foreach(jobs, k, id) {
		snprintf(field, sizeof field, "%.200s/%zu", base, k);
		if (!json_is_integer(id) || json_integer_value(id) < 1)
			return refuse(r, field, "must be a job id");
		json_t *job = NULL;
		struct api_error err = { 0 };
		if (store_job_get(r->srv->store, &r->who, json_integer_value(id), 0, &job, &err) != API_OK) {
			if (err.code != API_NOT_FOUND) {
				reply_error(r, &err);
				return -1;
			}
			snprintf(why, sizeof why, "no job %lld", (long long)json_integer_value(id));
			return refuse(r, field, why);
		}
		const char *batch = json_string_value(json_object_get(job, "batch"));
		int ok = batch && !strcmp(batch, label);
		snprintf(why, sizeof why, "job %lld carries the batch label '%s', not the run's '%s'",
			 (long long)json_integer_value(id), batch ? batch : "(none)", label);
		json_decref(job);
		if (!ok)
			return refuse(r, field, why);
	}
	return 0;
}

/* Case i: {"name", "jobs", "error", "figures"}; names unique (seen holds them). */
static int check_case(struct request *r, const json_t *c, size_t i, const char *label, json_t *seen)
{
	static const char *const keys[] = { "name", "jobs", "error", "figures", NULL };
	char base[64], field[SERVER_FIELD_MAX], why[128];
	snprintf(base, sizeof base, "/cases/%zu", i);
	if (!json_is_object(c))
		return refuse(r, base, "must be an object {\"name\", \"jobs\", \"figures\"}");
	if (known_keys(r, c, base, keys))
		return -1;
	const char *name = json_string_value(json_object_get(c, "name"));
	snprintf(field, sizeof field, "%s/name", base);
	snprintf(why, sizeof why, "must be 1 to %d characters of A-Z a-z 0-9 _ . -", BENCH_NAME_MAX);
	if (!bench_name_valid(name))
		return refuse(r, field, why);
	if (json_object_get(seen, name))
		return refuse(r, field, "names another case already");
	json_object_set_new(seen, name, json_true());
	const json_t *jobs = json_object_get(c, "jobs"), *error = json_object_get(c, "error");
	snprintf(field, sizeof field, "%s/jobs", base);
	if (check_jobs(r, jobs, field, label))
		return -1;
	snprintf(field, sizeof field, "%s/error", base);
	if (error && !json_is_null(error) &&
	    (!json_is_string(error) || !json_string_length(error) || json_string_length(error) > BENCH_ERROR_MAX))
		return refuse(r, field, "must be a string of 1 to 1024 bytes: why the case has no jobs");
	if (json_array_size(jobs) == 0 && !json_is_string(error))
		return refuse(r, field, "a case without jobs must say why (it was refused at submission)");
	const json_t *figures = json_object_get(c, "figures"), *f;
	snprintf(field, sizeof field, "%s/figures", base);
	if (!json_is_array(figures) || json_array_size(figures) < 1 || json_array_size(figures) > BENCH_FIGURES_MAX)
		return refuse(r, field, "must be an array of 1 to 32 figures");
	json_t *kinds = json_object();
	size_t k;
	int rc = 0;
	json_array_foreach(figures, k, f) {
		snprintf(field, sizeof field, "%s/figures/%zu", base, k);
		if ((rc = check_figure(r, f, field)))
			break;
		const char *kind = json_string_value(json_object_get(f, "kind"));
		if (json_object_get(kinds, kind)) {
			rc = refuse(r, field, "names a figure the case lists already");
			break;
		}
		json_object_set_new(kinds, kind, json_true());
	}
	json_decref(kinds);
	return rc;
}

int bench_plan_check(struct request *r, json_t *body, json_t **plan)
{
	static const char *const keys[] = { "suite", "label", "commit", "host", "settings", "cases", NULL };
	*plan = NULL;
	const char *suite = json_string_value(json_object_get(body, "suite"));
	const char *label = json_string_value(json_object_get(body, "label"));
	const char *commit, *host;
	char why[128];
	if (known_keys(r, body, "", keys))
		return -1;
	snprintf(why, sizeof why, "must be 1 to %d characters of A-Z a-z 0-9 _ . -", BENCH_NAME_MAX);
	if (!bench_name_valid(suite))
		return refuse(r, "/suite", why);
	if (!label || !bench_label_valid(label))
		return refuse(r, "/label", "must be the batch label of the run's jobs: 1 to 128 characters of "
			      "A-Z a-z 0-9 . _ : -");
	if (api_string_member(r, body, "commit", COMMIT_MAX, 1, &commit) ||
	    api_string_member(r, body, "host", HOST_MAX, 0, &host))
		return -1;
	json_t *settings = check_settings(r, body);
	if (!settings)
		return -1;
	const json_t *cases = json_object_get(body, "cases"), *c;
	if (!json_is_array(cases) || json_array_size(cases) < 1 || json_array_size(cases) > BENCH_CASES_MAX) {
		json_decref(settings);
		snprintf(why, sizeof why, "must be an array of 1 to %d cases", BENCH_CASES_MAX);
		return refuse(r, "/cases", why);
	}
	json_t *seen = json_object();
	size_t i;
	int rc = 0;
	json_array_foreach(cases, i, c) {
		if ((rc = check_case(r, c, i, label, seen)))
			break;
	}
	json_decref(seen);
	if (rc) {
		json_decref(settings);
		return -1;
	}
	*plan = json_pack("{s:o, s:O}", "settings", settings, "cases", cases);
	return 0;
}
