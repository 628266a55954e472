/*
 * bench_finish.c - POST /v1/benchmarks/{id}/finish: the verdicts of a benchmark run once every
 * job of its batch has ended (bench.h; docs/benchmarks.md "Verdicts").
 *
 * Per case of the plan, its jobs' ends are sorted first, so that "failed", "did not run" and
 * "regressed" are never confused:
 *   did_not_run  the case was refused at submission (the plan says why), or a job was cancelled
 *                or lost (its attempts ran out on infrastructure failures): nothing was measured;
 *   failed       a job ran and failed (the solver's message is kept), or succeeded without
 *                reporting the figure (no metrics.json, a damaged one, no value);
 * and only then, with a sample from every job (the repeats), the figure is judged by its check:
 * a band, the rank test against the same machine's history (regression.h), or none (recorded).
 * The samples of one figure must come from one machine fingerprint; samples from several are
 * recorded and not compared. The run's state is "failed" when any figure failed or did not run,
 * else "regressed" when any regressed, else "passed"; its summary counts the figures per verdict.
 *
 * Finishing is idempotent: a run already finished is answered as stored. A run whose jobs have
 * not all ended is refused (409 not_finished, naming them).
 */
#include "bench.h"
#include "store.h"

#include "figures.h"
#include "mann_whitney.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define UNFINISHED_NAMED 10   /* jobs named in a not_finished answer */

/* What the jobs of one case came to. */
struct case_outcome {
	enum regression_status status;   /* REGRESSION_OK when every job succeeded with metrics */
	char detail[SERVER_MESSAGE_MAX];
	json_t *metrics;                 /* [jobs] their metrics.json, when status is OK */
	char case_sha256[65];
	const char *solver_version;      /* of the first job's metrics, borrowed */
};

static json_t *real_or_null(double x)
{
	return isfinite(x) ? json_real(x) : json_null();
}

static int terminal(const char *state)
{
	return !strcmp(state, "succeeded") || !strcmp(state, "failed") || !strcmp(state, "cancelled");
}

/* The jobs of every case that have not ended, as "12, 13, ..." into out; their number. */
static int unfinished(struct request *r, const json_t *cases, char *out, size_t size)
{
	static const struct principal reader = { .role = ROLE_ADMIN };
	const json_t *c, *id;
	size_t i, k;
	int n = 0;
	out[0] = '\0';
	json_array_foreach(cases, i, c) {
		json_array_foreach(json_object_get(c, "jobs"), k, id) {
			json_t *job = NULL;
			struct api_error err = { 0 };
			if (store_job_get(r->srv->store, &reader, json_integer_value(id), 0, &job, &err) != API_OK)
				continue;   /* deleted since: it has ended */
			if (!terminal(json_string_value(json_object_get(job, "state"))) && n++ < UNFINISHED_NAMED) {
				size_t used = strlen(out);
				snprintf(out + used, size - used, "%s%lld", used ? ", " : "", (long long)json_integer_value(id));
			}
			json_decref(job);
		}
	}
	return n;
}

/* Sorts the ends of one case's jobs (see the top of this file). */
static void case_outcome(struct request *r, const json_t *c, struct case_outcome *o)
{
	static const struct principal reader = { .role = ROLE_ADMIN };
	const json_t *jobs = json_object_get(c, "jobs"), *id;
	size_t k;
	memset(o, 0, sizeof *o);
	o->metrics = json_array();
	if (json_array_size(jobs) == 0) {
		o->status = REGRESSION_DID_NOT_RUN;
		snprintf(o->detail, sizeof o->detail, "not submitted: %.900s", json_string_value(json_object_get(c, "error")));
		return;
	}
	json_array_foreach(jobs, k, id) {
		long long jid = json_integer_value(id);
		json_t *job = NULL;
		struct api_error err = { 0 };
		if (store_job_get(r->srv->store, &reader, jid, 0, &job, &err) != API_OK) {
			o->status = REGRESSION_DID_NOT_RUN;
			snprintf(o->detail, sizeof o->detail, "job %lld: %.900s", jid, err.message);
			return;
		}
		const char *state = json_string_value(json_object_get(job, "state"));
		const char *message = json_string_value(json_object_get(job, "message"));
		if (k == 0)
			snprintf(o->case_sha256, sizeof o->case_sha256, "%s",
				 json_string_value(json_object_get(job, "case_sha256")));
		int lost = message && !strncmp(message, "lost:", 5);
		if (!strcmp(state, "cancelled") || lost) {
			o->status = REGRESSION_DID_NOT_RUN;
			snprintf(o->detail, sizeof o->detail, "job %lld %s%s%s", jid, lost ? "was" : "was cancelled",
				 lost ? " " : "", lost ? message : "");
		} else if (!strcmp(state, "failed") && o->status != REGRESSION_DID_NOT_RUN) {
			o->status = REGRESSION_FAILED;
			snprintf(o->detail, sizeof o->detail, "job %lld failed: %s", jid, message ? message : "(no message)");
		} else if (o->status == REGRESSION_OK) {
			char why[SERVER_MESSAGE_MAX];
			json_t *m = bench_job_metrics(r->srv, jid, why, sizeof why);
			if (!m) {
				o->status = REGRESSION_FAILED;
				snprintf(o->detail, sizeof o->detail, "%s", why);
			}
			json_array_append_new(o->metrics, m ? m : json_null());
		}
		json_decref(job);
	}
	if (json_array_size(o->metrics))
		o->solver_version = json_string_value(json_object_get(json_array_get(o->metrics, 0), "solver_version"));
}

/* The samples of kind from every job's metrics; -1 (with detail) when one has no value. */
static int samples_of(const struct case_outcome *o, const char *kind, double *samples, char *fingerprint,
		      char *detail, size_t detail_size)
{
	const json_t *m;
	size_t k;
	char fp[BENCH_FINGERPRINT_HEX + 1];
	int machines = 0;
	json_array_foreach(o->metrics, k, m) {
		const json_t *v = json_object_get(json_object_get(json_object_get(m, "figures"), kind), "value");
		if (!json_is_number(v)) {
			snprintf(detail, detail_size, "repeat %zu reported no value of %s%s", k + 1, kind,
				 json_object_get(json_object_get(m, "figures"), kind) ? " (undefined for this run)" : "");
			return -1;
		}
		samples[k] = json_number_value(v);
		bench_fingerprint(json_object_get(m, "machine"), fp);
		if (k == 0)
			strcpy(fingerprint, fp);
		else if (strcmp(fp, fingerprint))
			machines = 2;
	}
	return machines > 1 ? 1 : 0;
}

/* The history verdict of a timing figure, with its statistics. */
static void judge_history(struct request *r, const char *suite, const char *figure, const char *fingerprint,
			  const char *case_sha256, long long run, const struct regression_rule *rule,
			  const double *samples, int n, struct regression_verdict *v, json_t **stats)
{
	double *history = NULL;
	int m = 0, runs = 0;
	struct api_error err = { 0 };
	if (store_bench_history(r->srv->store, suite, figure, fingerprint, case_sha256, run, rule->history_runs,
				&history, &m, &runs, &err) != API_OK || regression_history(samples, n, history, m, rule, v)) {
		memset(v, 0, sizeof *v);
		v->status = REGRESSION_RECORDED;
		v->median = mw_median(samples, n);
		snprintf(v->detail, sizeof v->detail, "not compared: %.200s", err.message[0] ? err.message : "no memory");
	}
	free(history);
	*stats = json_pack("{s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:i, s:i, s:f, s:f}", "history_median",
			   real_or_null(v->history_median), "history_min", real_or_null(v->history_min), "history_max",
			   real_or_null(v->history_max), "ratio", real_or_null(v->ratio), "p_slower",
			   real_or_null(v->p_slower), "p_faster", real_or_null(v->p_faster), "p_exceed_slower",
			   real_or_null(v->p_exceed_slower), "p_exceed_faster", real_or_null(v->p_exceed_faster),
			   "history_samples", v->history_samples, "history_runs", runs, "alpha", rule->alpha,
			   "min_effect", rule->min_effect);
}

/* One figure row of a case (bench.h, store.h). */
static json_t *figure_row(struct request *r, const char *suite, long long run, const json_t *c,
			  const struct case_outcome *o, const json_t *f, const struct regression_rule *rule)
{
	const char *name = json_string_value(json_object_get(c, "name"));
	const char *kind = json_string_value(json_object_get(f, "kind"));
	const char *check = json_string_value(json_object_get(f, "check"));
	enum figure_kind k = (enum figure_kind)figure_parse(kind);
	char figure[BENCH_FIGURE_MAX], fingerprint[BENCH_FINGERPRINT_HEX + 1] = "";
	snprintf(figure, sizeof figure, "%s/%s", name, kind);
	size_t n = json_array_size(o->metrics);
	double *samples = calloc(n + 1, sizeof *samples);
	struct regression_verdict v = { .status = o->status, .median = NAN };
	json_t *stats = json_null();
	snprintf(v.detail, sizeof v.detail, "%.250s", o->detail);
	if (o->status == REGRESSION_OK) {
		int mixed = samples ? samples_of(o, kind, samples, fingerprint, v.detail, sizeof v.detail) : -1;
		if (mixed < 0) {
			v.status = REGRESSION_FAILED;
			if (!samples)
				snprintf(v.detail, sizeof v.detail, "no memory to judge the figure");
		} else if (mixed > 0) {
			v.status = REGRESSION_RECORDED;
			v.median = mw_median(samples, (int)n);
			snprintf(v.detail, sizeof v.detail, "its repeats ran on machines of different fingerprints: not "
				 "compared");
		} else if (!strcmp(check, "band")) {
			const json_t *band = json_object_get(f, "band");
			double lo = json_is_number(json_array_get(band, 0)) ? json_number_value(json_array_get(band, 0)) : NAN;
			double hi = json_is_number(json_array_get(band, 1)) ? json_number_value(json_array_get(band, 1)) : NAN;
			regression_band(samples, (int)n, lo, hi, &v);
		} else if (!strcmp(check, "history")) {
			judge_history(r, suite, figure, fingerprint, o->case_sha256, run, rule, samples, (int)n, &v, &stats);
		} else {
			v.status = REGRESSION_RECORDED;
			v.median = mw_median(samples, (int)n);
			snprintf(v.detail, sizeof v.detail, "recorded");
		}
	}
	json_t *list = json_array();
	for (size_t i = 0; v.status != REGRESSION_FAILED && v.status != REGRESSION_DID_NOT_RUN && i < n; i++)
		json_array_append_new(list, json_real(samples[i]));
	free(samples);
	return json_pack("{s:s, s:s, s:s, s:s, s:s, s:o, s:o, s:o, s:o, s:O, s:s, s:s, s:o}", "figure", figure,
			 "kind", kind, "class", figure_class_name(figure_class(k)), "check", check, "unit",
			 figure_unit(k), "case_sha256", o->case_sha256[0] ? json_string(o->case_sha256) : json_null(),
			 "machine", fingerprint[0] ? json_string(fingerprint) : json_null(), "samples", list, "median",
			 real_or_null(v.median), "band", json_object_get(f, "band") ? json_object_get(f, "band") : json_null(),
			 "status", regression_status_name(v.status), "detail", v.detail, "stats", stats);
}

/* The run's machine: that of its first timing figure measured, else of any job's metrics. */
static void run_machine(const json_t *figures, struct case_outcome *outcomes, size_t cases, json_t *result)
{
	const json_t *machine = NULL;
	for (size_t i = 0; i < cases && !machine; i++)
		if (json_array_size(outcomes[i].metrics))
			machine = json_object_get(json_array_get(outcomes[i].metrics, 0), "machine");
	const json_t *f;
	size_t k;
	json_array_foreach(figures, k, f) {
		const char *fp = json_string_value(json_object_get(f, "machine"));
		if (fp && !strcmp(json_string_value(json_object_get(f, "class")), "timing")) {
			json_object_set_new(result, "fingerprint", json_string(fp));
			break;
		}
	}
	char fp[BENCH_FINGERPRINT_HEX + 1];
	bench_fingerprint(machine, fp);
	if (!json_object_get(result, "fingerprint"))
		json_object_set_new(result, "fingerprint", fp[0] ? json_string(fp) : json_null());
	/* the machine whose fingerprint the run names */
	const char *want = json_string_value(json_object_get(result, "fingerprint"));
	for (size_t i = 0; i < cases && want; i++) {
		const json_t *m = json_array_get(outcomes[i].metrics, 0);
		bench_fingerprint(json_object_get(m, "machine"), fp);
		if (m && !strcmp(fp, want)) {
			machine = json_object_get(m, "machine");
			break;
		}
	}
	json_object_set(result, "machine", machine ? (json_t *)machine : json_null());
}

/* Every figure of the run judged: {"state", "solver_version", "machine", "fingerprint", "summary",
 * "figures"}. */
static json_t *judge(struct request *r, const json_t *run)
{
	const char *suite = json_string_value(json_object_get(run, "suite"));
	long long id = json_integer_value(json_object_get(run, "id"));
	const json_t *cases = json_object_get(run, "cases"), *c, *f;
	struct regression_rule rule;
	json_t *plan = json_pack("{s:O}", "settings", json_object_get(run, "settings"));
	bench_plan_rule(plan, &rule);
	json_decref(plan);
	size_t count = json_array_size(cases), i, k;
	struct case_outcome *outcomes = calloc(count + 1, sizeof *outcomes);
	json_t *figures = json_array(), *summary = json_object(), *result = json_object();
	const char *version = NULL;
	int failed = 0, regressed = 0;
	json_array_foreach(cases, i, c) {
		case_outcome(r, c, &outcomes[i]);
		if (!version)
			version = outcomes[i].solver_version;
		json_array_foreach(json_object_get(c, "figures"), k, f) {
			json_t *row = figure_row(r, suite, id, c, &outcomes[i], f, &rule);
			const char *status = json_string_value(json_object_get(row, "status"));
			failed |= !strcmp(status, "failed") || !strcmp(status, "did_not_run");
			regressed |= !strcmp(status, "regressed");
			json_object_set_new(summary, status, json_integer(json_integer_value(json_object_get(summary, status)) + 1));
			json_array_append_new(figures, row);
		}
	}
	json_object_set_new(result, "state", json_string(failed ? "failed" : regressed ? "regressed" : "passed"));
	json_object_set_new(result, "solver_version", version ? json_string(version) : json_null());
	json_object_set_new(result, "summary", summary);
	json_object_set_new(result, "figures", figures);
	run_machine(figures, outcomes, count, result);
	for (i = 0; i < count; i++)
		json_decref(outcomes[i].metrics);
	free(outcomes);
	return result;
}

void bench_finish(struct request *r)
{
	if (r->body_size) {
		json_t *body = api_body_object(r);
		static const char *const none[] = { NULL };
		int bad = !body || api_known_keys(r, body, none);
		json_decref(body);
		if (bad)
			return;
	}
	json_t *run = NULL;
	long long owner = 0;
	struct api_error err = { 0 };
	if (store_bench_get(r->srv->store, r->id, 1, &run, &owner, &err) != API_OK) {
		reply_error(r, &err);
		return;
	}
	if (strcmp(json_string_value(json_object_get(run, "state")), "running")) {
		reply_json(r, 200, run);   /* finished already: as stored */
		return;
	}
	if (owner != r->who.user_id && r->who.role != ROLE_ADMIN) {
		json_decref(run);
		reply_fail(r, API_FORBIDDEN, "", "benchmark run %lld belongs to another user: only they or an admin may "
			   "finish it", r->id);
		return;
	}
	char names[256];
	int open = unfinished(r, json_object_get(run, "cases"), names, sizeof names);
	if (open) {
		json_decref(run);
		reply_fail(r, API_NOT_FINISHED, "", "benchmark run %lld has %d job%s not ended yet (%s%s): finish it when "
			   "they have", r->id, open, open == 1 ? "" : "s", names, open > UNFINISHED_NAMED ? ", ..." : "");
		return;
	}
	json_t *result = judge(r, run);
	json_decref(run);
	int changed = 0;
	if (store_bench_finish(r->srv->store, r->id, result, &changed, &err) != API_OK ||
	    store_bench_get(r->srv->store, r->id, 1, &run, NULL, &err) != API_OK)
		reply_error(r, &err);
	else
		reply_json(r, 200, run);
	json_decref(result);
}
