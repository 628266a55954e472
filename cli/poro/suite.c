/*
 * suite.c - a benchmark suite file (schemas/suite.schema.json, docs/benchmarks.md "The suite")
 * read, checked and expanded into what `poro nightly run` submits (nightly.h).
 *
 * A suite names cases (case files, relative to the suite file), each with a JSON merge patch
 * (RFC 7386) that makes it as small as a nightly wants, the repeats of its jobs, and the figures
 * to judge: {"band": [min, max]} for an accuracy figure, {"history": true} for a timing figure
 * compared with the same machine's recent runs, {} to record one. The figure kinds are the
 * solver's own table (solver/verify/figures.h, linked into poro); a figure not every run reports
 * is asked for in the case's "metrics" object, which is added to the submitted case here. Every
 * problem is printed with its JSON pointer, and nothing is submitted while there is one.
 */
#define _GNU_SOURCE
#include "cli.h"
#include "nightly.h"

#include <errno.h>
#include <libgen.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "bench_names.h"
#include "figures.h"

#define SUITE_CASES_MAX 500
#define SUITE_FIGURES_MAX 32
#define SUITE_THREADS_MAX 256
#define SUITE_WALL_MAX 2592000

/* The loader's state: the file for messages and the problems found so far. */
struct reader {
	const char *file;
	int problems;
};

static void problem(struct reader *rd, const char *pointer, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static void problem(struct reader *rd, const char *pointer, const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	fprintf(stderr, "poro: %s: %s: ", rd->file, pointer[0] ? pointer : "/");
	vfprintf(stderr, fmt, ap);
	fputc('\n', stderr);
	va_end(ap);
	rd->problems++;
}

static void unknown_keys(struct reader *rd, const json_t *obj, const char *base, const char *const *allowed)
{
	const char *key = bench_unknown_key(obj, allowed);
	char p[512];
	snprintf(p, sizeof p, "%.300s/%.100s", base, key ? key : "");
	if (key)
		problem(rd, p, "unknown key");
}

/* An optional integer member in [lo, hi]; *out keeps def when absent. */
static void int_member(struct reader *rd, const json_t *obj, const char *base, const char *key, long long lo,
		       long long hi, long long def, long long *out)
{
	const json_t *v = json_object_get(obj, key);
	*out = def;
	if (!v)
		return;
	char p[512];
	snprintf(p, sizeof p, "%s/%s", base, key);
	if (!json_is_integer(v) || json_integer_value(v) < lo || json_integer_value(v) > hi)
		problem(rd, p, "must be a whole number from %lld to %lld", lo, hi);
	else
		*out = json_integer_value(v);
}

/* RFC 7386: patch merged into target (a new reference, target's reference is taken). */
static json_t *merge_patch(json_t *target, const json_t *patch)
{
	if (!json_is_object(patch)) {
		json_decref(target);
		return json_deep_copy(patch);
	}
	if (!json_is_object(target)) {
		json_decref(target);
		target = json_object();
	}
	const char *key;
	json_t *v;
	json_object_foreach((json_t *)patch, key, v) {
		if (json_is_null(v)) {
			json_object_del(target, key);
			continue;
		}
		json_t *old = json_object_get(target, key);
		json_object_set_new(target, key, merge_patch(old ? json_incref(old) : NULL, v));
	}
	return target;
}

static void check_settings(struct reader *rd, const json_t *s)
{
	static const char *const keys[] = { "alpha", "min_effect", "history_runs", NULL };
	if (!s)
		return;
	if (!json_is_object(s)) {
		problem(rd, "/settings", "must be an object {\"alpha\", \"min_effect\", \"history_runs\"}");
		return;
	}
	unknown_keys(rd, s, "/settings", keys);
	const json_t *a = json_object_get(s, "alpha"), *e = json_object_get(s, "min_effect");
	if (a && !(json_is_number(a) && json_number_value(a) > 0 && json_number_value(a) <= 0.5))
		problem(rd, "/settings/alpha", "must be a number in (0, 0.5]");
	if (e && !(json_is_number(e) && json_number_value(e) >= 0 && json_number_value(e) <= 10))
		problem(rd, "/settings/min_effect", "must be a number from 0 to 10 (a fraction of the median)");
	long long runs;
	int_member(rd, s, "/settings", "history_runs", 1, 1000, 10, &runs);
}

/* One figure {"band"} | {"history": true} | {} of a case into the plan's list. */
static void read_figure(struct reader *rd, struct suite_case *c, const char *kind, const json_t *spec, const char *base,
			int element, int *wants_history)
{
	static const char *const keys[] = { "band", "history", "description", NULL };
	char p[512];
	snprintf(p, sizeof p, "%.300s/%.100s", base, kind);
	int k = figure_parse(kind);
	if (k < 0) {
		problem(rd, p,
			"unknown figure: the solver reports wall_seconds, cpu_seconds, us_per_point_step, "
			"cpu_us_per_point_step, median_cpu_us_per_point_step, reference_kernel_us, relative_step_cost, "
			"steps, max_displacement, terzaghi_rms, "
			"xie_leo_settlement, runout, peak_q, newton_iterations, mohr_coulomb_peak_error (docs/benchmarks.md)");
		return;
	}
	if (!(figure_where((enum figure_kind)k) & (element ? FIGURE_ELEMENT : FIGURE_SIM))) {
		problem(rd, p, "is a figure of %s, and the case is %s", element ? "simulation runs" : "element tests",
			element ? "an element test" : "a simulation");
		return;
	}
	if (!json_is_object(spec)) {
		problem(rd, p, "must be an object: {\"band\": [min, max]}, {\"history\": true} or {}");
		return;
	}
	unknown_keys(rd, spec, p, keys);
	const json_t *band = json_object_get(spec, "band"), *history = json_object_get(spec, "history");
	const char *check = band ? "band" : json_is_true(history) ? "history" : "none";
	if (history && !json_is_boolean(history))
		problem(rd, p, "\"history\" must be true or false");
	if (band && json_is_true(history))
		problem(rd, p, "a figure is judged by a band or against history, not both");
	if (band) {
		const json_t *lo = json_array_get(band, 0), *hi = json_array_get(band, 1);
		int ok = json_is_array(band) && json_array_size(band) == 2 && (json_is_null(lo) || json_is_number(lo)) &&
			 (json_is_null(hi) || json_is_number(hi)) && !(json_is_null(lo) && json_is_null(hi)) &&
			 !(json_is_number(lo) && json_is_number(hi) && json_number_value(lo) > json_number_value(hi));
		if (!ok)
			problem(rd, p, "\"band\" must be [min, max] with min <= max, or one of them null for an open end");
	}
	if (!strcmp(check, "history") && figure_class((enum figure_kind)k) != FIGURE_TIMING)
		problem(rd, p, "only timing figures are judged against history; give an accuracy or count figure a band");
	*wants_history |= !strcmp(check, "history");
	json_array_append_new(c->figures, json_pack("{s:s, s:s, s:O?}", "kind", kind, "check", check, "band", band));
	if (!(figure_where((enum figure_kind)k) & (element ? FIGURE_ELEMENT_ALWAYS : FIGURE_SIM_ALWAYS))) {
		/* the case must ask for it */
		json_t *metrics = json_object_get(c->spec, "metrics");
		if (!json_is_object(metrics))
			json_object_set_new(c->spec, "metrics", metrics = json_object());
		json_object_set_new(metrics, kind, json_true());
	}
}

/* The case file, relative to the suite's directory, with the patch merged. */
static json_t *read_case_file(struct reader *rd, const struct suite *s, const char *file, const json_t *patch,
			      const char *base)
{
	char path[8300], p[512];
	snprintf(path, sizeof path, "%s%s%s", file[0] == '/' ? "" : s->dir, file[0] == '/' ? "" : "/", file);
	snprintf(p, sizeof p, "%s/case", base);
	json_error_t jerr;
	json_t *spec = json_load_file(path, 0, &jerr);
	if (!spec) {
		problem(rd, p, "cannot read the case '%s': %s", path, jerr.text);
		return NULL;
	}
	if (!json_is_object(spec)) {
		problem(rd, p, "the case '%s' is not a JSON object", path);
		json_decref(spec);
		return NULL;
	}
	if (patch && !json_is_object(patch)) {
		snprintf(p, sizeof p, "%s/patch", base);
		problem(rd, p, "must be an object: a JSON merge patch (RFC 7386) of the case");
		return spec;
	}
	return patch ? merge_patch(spec, patch) : spec;
}

static void read_case(struct reader *rd, struct suite *s, const json_t *c, size_t i, json_t *seen)
{
	static const char *const keys[] = { "name", "case", "patch", "repeats", "exclusive", "threads",
					    "wall_time_seconds", "figures", "description", NULL };
	struct suite_case *sc = &s->cases[s->count];
	char base[64], p[512];
	snprintf(base, sizeof base, "/cases/%zu", i);
	if (!json_is_object(c)) {
		problem(rd, base, "must be an object {\"name\", \"case\", \"figures\", ...}");
		return;
	}
	unknown_keys(rd, c, base, keys);
	const char *name = json_string_value(json_object_get(c, "name"));
	const char *file = json_string_value(json_object_get(c, "case"));
	snprintf(p, sizeof p, "%s/name", base);
	if (!bench_name_valid(name))
		problem(rd, p, "must be 1 to %d characters of A-Z a-z 0-9 _ . -", BENCH_NAME_MAX);
	else if (json_object_get(seen, name))
		problem(rd, p, "'%s' names another case already", name);
	else
		json_object_set_new(seen, name, json_true());
	snprintf(p, sizeof p, "%s/case", base);
	if (!file || !file[0] || strlen(file) >= sizeof sc->path) {
		problem(rd, p, "must be the path of a case file, relative to the suite file");
		return;
	}
	long long repeats, threads, wall;
	int_member(rd, c, base, "repeats", 1, SUITE_REPEATS_MAX, 1, &repeats);
	int_member(rd, c, base, "threads", 1, SUITE_THREADS_MAX, 1, &threads);
	int_member(rd, c, base, "wall_time_seconds", 1, SUITE_WALL_MAX, 0, &wall);
	const json_t *exclusive = json_object_get(c, "exclusive"), *figures = json_object_get(c, "figures");
	snprintf(p, sizeof p, "%s/exclusive", base);
	if (exclusive && !json_is_boolean(exclusive))
		problem(rd, p, "must be true or false");
	json_t *spec = read_case_file(rd, s, file, json_object_get(c, "patch"), base);
	if (!spec || !bench_name_valid(name)) {
		json_decref(spec);
		return;
	}
	*sc = (struct suite_case){ .spec = spec, .repeats = (int)repeats, .threads = (int)threads,
				   .wall_time_seconds = wall, .figures = json_array() };
	snprintf(sc->name, sizeof sc->name, "%s", name);
	snprintf(sc->path, sizeof sc->path, "%s", file);
	s->count++;
	const char *schema = json_string_value(json_object_get(spec, "schema"));
	int element = schema && !strcmp(schema, "poro-element/1"), history = 0;
	snprintf(p, sizeof p, "%s/figures", base);
	if (!json_is_object(figures) || json_object_size(figures) < 1 || json_object_size(figures) > SUITE_FIGURES_MAX) {
		problem(rd, p, "must be an object of 1 to %d figures: {\"terzaghi_rms\": {\"band\": [0, 0.02]}, ...}",
			SUITE_FIGURES_MAX);
		return;
	}
	const char *kind;
	json_t *f;
	json_object_foreach((json_t *)figures, kind, f)
		read_figure(rd, sc, kind, f, p, element, &history);
	sc->exclusive = exclusive ? json_is_true(exclusive) : history;
	snprintf(p, sizeof p, "%s/repeats", base);
	if (history && sc->repeats < SUITE_HISTORY_REPEATS_MIN)
		problem(rd, p, "a case judged against history needs at least %d repeats: one sample alone can never make "
			"the rank test significant", SUITE_HISTORY_REPEATS_MIN);
	snprintf(p, sizeof p, "%s/exclusive", base);
	if (history && !sc->exclusive)
		problem(rd, p, "a case timed against history runs alone on its worker: leave \"exclusive\" out or true");
}

/* The cases named in only[], in the suite's order; a name the suite lacks is a problem. */
static void keep_only(struct reader *rd, struct suite *s, const char *const *only, int only_count)
{
	for (int k = 0; k < only_count; k++) {
		int found = 0;
		for (int i = 0; i < s->count && !found; i++)
			found = !strcmp(s->cases[i].name, only[k]);
		if (!found)
			problem(rd, "/cases", "no case named '%s' (--only)", only[k]);
	}
	int kept = 0;
	for (int i = 0; i < s->count; i++) {
		int want = 0;
		for (int k = 0; k < only_count && !want; k++)
			want = !strcmp(s->cases[i].name, only[k]);
		if (want)
			s->cases[kept++] = s->cases[i];
		else {
			json_decref(s->cases[i].spec);
			json_decref(s->cases[i].figures);
		}
	}
	s->count = kept;
}

int suite_load(const char *path, const char *const *only, int only_count, struct suite *s)
{
	static const char *const keys[] = { "schema", "name", "description", "settings", "cases", NULL };
	struct reader rd = { .file = path };
	memset(s, 0, sizeof *s);
	json_error_t jerr;
	json_t *doc = json_load_file(path, JSON_REJECT_DUPLICATES, &jerr);
	if (!doc || !json_is_object(doc)) {
		if (doc)
			fprintf(stderr, "poro: %s: /: the suite must be a JSON object\n", path);
		else if (jerr.line > 0)
			fprintf(stderr, "poro: '%s' is not JSON: line %d column %d: %s\n", path, jerr.line, jerr.column, jerr.text);
		else
			fprintf(stderr, "poro: cannot read the suite '%s': %s\n", path, jerr.text);
		json_decref(doc);
		return PORO_EXIT_INVALID_CASE;
	}
	char copy[4096];
	snprintf(copy, sizeof copy, "%s", path);
	snprintf(s->dir, sizeof s->dir, "%s", dirname(copy));
	unknown_keys(&rd, doc, "", keys);
	const char *schema = json_string_value(json_object_get(doc, "schema"));
	const char *name = json_string_value(json_object_get(doc, "name"));
	if (!schema || strcmp(schema, SUITE_SCHEMA))
		problem(&rd, "/schema", "must be \"%s\"", SUITE_SCHEMA);
	if (!bench_name_valid(name))
		problem(&rd, "/name", "must be 1 to %d characters of A-Z a-z 0-9 _ . -", BENCH_NAME_MAX);
	else
		snprintf(s->name, sizeof s->name, "%s", name);
	check_settings(&rd, json_object_get(doc, "settings"));
	s->settings = json_incref(json_object_get(doc, "settings"));
	const json_t *cases = json_object_get(doc, "cases"), *c;
	size_t n = json_array_size(cases), i;
	if (!json_is_array(cases) || n < 1 || n > SUITE_CASES_MAX)
		problem(&rd, "/cases", "must be an array of 1 to %d cases", SUITE_CASES_MAX);
	else if ((s->cases = calloc(n, sizeof *s->cases))) {
		json_t *seen = json_object();
		json_array_foreach(cases, i, c)
			read_case(&rd, s, c, i, seen);
		json_decref(seen);
	}
	if (only_count)
		keep_only(&rd, s, only, only_count);
	json_decref(doc);
	if (rd.problems) {
		fprintf(stderr, "poro: %s: %d problem%s: nothing was submitted\n", path, rd.problems,
			rd.problems == 1 ? "" : "s");
		suite_release(s);
		return PORO_EXIT_INVALID_CASE;
	}
	return 0;
}

void suite_release(struct suite *s)
{
	for (int i = 0; i < s->count; i++) {
		json_decref(s->cases[i].spec);
		json_decref(s->cases[i].figures);
	}
	free(s->cases);
	json_decref(s->settings);
	memset(s, 0, sizeof *s);
}
