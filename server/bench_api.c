/*
 * bench_api.c - the benchmark routes (docs/service.md §3 "Benchmarks", bench.h): create a run
 * from its plan, list runs, show one (while it runs, with its jobs' states, so a client follows the
 * whole batch with one request), and a figure's series. Finishing a run is bench_finish.c.
 *
 * Every user may read every run and series (they describe the solver, not a user's work); a run
 * is finished by its creator or an admin.
 */
#include "bench.h"
#include "store.h"

#include "figures.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define LIST_LIMIT_MAX 1000
#define LIST_LIMIT_DEFAULT 50
#define SERIES_LIMIT_MAX 1000
#define SERIES_LIMIT_DEFAULT 100
#define ID_MAX 999999999999999999LL

void bench_create(struct request *r)
{
	json_t *body = api_body_object(r), *plan = NULL, *run = NULL;
	if (!body)
		return;
	if (bench_plan_check(r, body, &plan) == 0) {
		struct api_error err = { 0 };
		if (store_bench_create(r->srv->store, &r->who, json_string_value(json_object_get(body, "suite")),
				       json_string_value(json_object_get(body, "label")),
				       json_string_value(json_object_get(body, "commit")),
				       json_string_value(json_object_get(body, "host")), plan, &run, &err) != API_OK) {
			reply_error(r, &err);
		} else {
			char location[64];
			snprintf(location, sizeof location, "/v1/benchmarks/%lld",
				 (long long)json_integer_value(json_object_get(run, "id")));
			reply_header(r, "Location", location);
			reply_json(r, 201, run);
		}
	}
	json_decref(plan);
	json_decref(body);
}

/* A name-like query parameter (suite, figure, machine) into out: 1 present, 0 absent, -1 after
 * replying 400. allowed lists the characters besides letters and digits. */
static int query_name(struct request *r, const char *name, char *out, size_t size, const char *allowed)
{
	int have = http_query(r, name, out, size);
	int ok = have >= 0 && (have == 0 || out[0]);
	for (size_t i = 0; ok && have > 0 && out[i]; i++) {
		char c = out[i];
		ok = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || strchr(allowed, c);
	}
	if (!ok) {
		reply_fail(r, API_INVALID_PARAMETER, name, "query parameter '%s' must be 1 to %zu characters of A-Z a-z "
			   "0-9 %s", name, size - 1, allowed);
		return -1;
	}
	return have;
}

void bench_list(struct request *r)
{
	char suite[BENCH_NAME_MAX + 1];
	long long limit, after;
	int have = query_name(r, "suite", suite, sizeof suite, "_.-");
	if (have < 0 || api_query_int(r, "limit", 1, LIST_LIMIT_MAX, LIST_LIMIT_DEFAULT, &limit) ||
	    api_query_int(r, "after", 1, ID_MAX, 0, &after))
		return;
	json_t *page = NULL;
	struct api_error err = { 0 };
	if (store_bench_list(r->srv->store, have ? suite : NULL, (int)limit, after, &page, &err) != API_OK)
		reply_error(r, &err);
	else
		reply_json(r, 200, page);
}

/* While a run is running: "jobs", each {"id", "case", "state", "fraction"}, and "progress"
 * {"jobs", "ended", "fraction"}: the mean of its jobs' fractions, an ended job counting 1. */
static void add_jobs(struct request *r, json_t *run)
{
	json_t *jobs = json_array(), *c, *id;
	size_t i, k;
	int count = 0, ended = 0;
	double sum = 0;
	json_array_foreach(json_object_get(run, "cases"), i, c) {
		json_array_foreach(json_object_get(c, "jobs"), k, id) {
			static const struct principal reader = { .role = ROLE_ADMIN };
			json_t *job = NULL;
			struct api_error err = { 0 };
			const char *state = "missing";
			double fraction = 0;
			if (store_job_get(r->srv->store, &reader, json_integer_value(id), 0, &job, &err) == API_OK) {
				state = json_string_value(json_object_get(job, "state"));
				fraction = json_number_value(json_object_get(json_object_get(job, "progress"), "fraction"));
			}
			int done = !strcmp(state, "succeeded") || !strcmp(state, "failed") ||
				   !strcmp(state, "cancelled") || !strcmp(state, "missing");
			json_array_append_new(jobs, json_pack("{s:O, s:O, s:s, s:f}", "id", id, "case",
							      json_object_get(c, "name"), "state", state, "fraction",
							      done ? 1.0 : fraction));
			count++;
			ended += done;
			sum += done ? 1.0 : fraction;
			json_decref(job);
		}
	}
	json_object_set_new(run, "jobs", jobs);
	json_object_set_new(run, "progress", json_pack("{s:i, s:i, s:f}", "jobs", count, "ended", ended, "fraction",
						       count ? sum / count : 1.0));
}

void bench_show(struct request *r)
{
	json_t *run = NULL;
	struct api_error err = { 0 };
	if (store_bench_get(r->srv->store, r->id, 1, &run, NULL, &err) != API_OK) {
		reply_error(r, &err);
		return;
	}
	if (!strcmp(json_string_value(json_object_get(run, "state")), "running"))
		add_jobs(r, run);
	reply_json(r, 200, run);
}

void bench_series(struct request *r)
{
	char suite[BENCH_NAME_MAX + 1], figure[BENCH_FIGURE_MAX], machine[BENCH_FINGERPRINT_HEX + 1];
	long long limit;
	int have_suite = query_name(r, "suite", suite, sizeof suite, "_.-"), have_figure = -1, have_machine = -1;
	if (have_suite >= 0)
		have_figure = query_name(r, "figure", figure, sizeof figure, "_.-/");
	if (have_figure >= 0)
		have_machine = query_name(r, "machine", machine, sizeof machine, "");
	if (have_machine < 0 || api_query_int(r, "limit", 1, SERIES_LIMIT_MAX, SERIES_LIMIT_DEFAULT, &limit))
		return;
	if (!have_suite || !have_figure) {
		reply_fail(r, API_INVALID_PARAMETER, have_suite ? "figure" : "suite", "query parameter '%s' is required",
			   have_suite ? "figure" : "suite");
		return;
	}
	const char *slash = strchr(figure, '/');
	int kind = slash ? figure_parse(slash + 1) : -1;
	if (kind < 0) {
		reply_fail(r, API_INVALID_PARAMETER, "figure", "query parameter 'figure' must be CASE/KIND with KIND a "
			   "figure the solver reports, got '%s'", figure);
		return;
	}
	if (figure_class((enum figure_kind)kind) == FIGURE_TIMING && !have_machine) {
		reply_fail(r, API_INVALID_PARAMETER, "machine", "'%s' is a timing figure: its series is of one machine "
			   "(query parameter 'machine', a run's fingerprint), since timings of two machines are not "
			   "comparable", figure);
		return;
	}
	json_t *points = NULL;
	struct api_error err = { 0 };
	if (store_bench_series(r->srv->store, suite, figure, have_machine ? machine : NULL, (int)limit, &points, &err)
	    != API_OK) {
		reply_error(r, &err);
		return;
	}
	reply_json(r, 200, json_pack("{s:s, s:s, s:o, s:s, s:s, s:o}", "suite", suite, "figure", figure, "machine",
				     have_machine ? json_string(machine) : json_null(), "class",
				     figure_class_name(figure_class((enum figure_kind)kind)), "unit",
				     figure_unit((enum figure_kind)kind), "points", points));
}
