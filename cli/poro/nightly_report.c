/*
 * nightly_report.c - the reports of a benchmark run (nightly.h, docs/benchmarks.md "Reports"):
 *
 *   JUnit XML   the format every CI reads: <testsuites> holding one <testsuite> (the suite), a
 *               <testcase> per figure; regressed is a <failure>, failed an <error>, did not run
 *               <skipped>; the run's label, commit, solver version and machine are <properties>,
 *               each figure's value and verdict its <system-out>.
 *   HTML        one self-contained page, nothing fetched: the figures' table, then per figure a
 *               plot of its series over the runs, drawn here as inline SVG (no script, no library:
 *               a browser, or a CI's artifact viewer, shows it as it is): the accepted band
 *               shaded, every sample a grey dot, the medians joined by a line, the verdict of each
 *               run in its dot's colour, runs that failed or did not run marked with a red cross at
 *               the bottom, this run ringed. A timing figure's series is that of this run's
 *               machine only (the server refuses to mix machines).
 */
#define _GNU_SOURCE
#include "cli.h"
#include "nightly.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "json_get.h"

#define SERIES_POINTS 60      /* runs a plot shows, the latest */
#define PLOT_W 760
#define PLOT_H 260
#define PLOT_L 78             /* margins, px */
#define PLOT_R 24
#define PLOT_T 16
#define PLOT_B 64
#define X_LABELS_MAX 12

/* text with &, <, >, " and ' escaped, for XML and HTML alike; control characters dropped. */
static void escaped(FILE *f, const char *text)
{
	for (const unsigned char *p = (const unsigned char *)(text ? text : ""); *p; p++) {
		switch (*p) {
		case '&': fputs("&amp;", f); break;
		case '<': fputs("&lt;", f); break;
		case '>': fputs("&gt;", f); break;
		case '"': fputs("&quot;", f); break;
		case '\'': fputs("&#39;", f); break;
		default:
			if (*p >= 0x20 || *p == '\n' || *p == '\t')
				fputc(*p, f);
		}
	}
}

static const char *number(const json_t *v, char out[32])
{
	if (json_is_number(v))
		snprintf(out, 32, "%.6g", json_number_value(v));
	else
		snprintf(out, 32, "-");
	return out;
}

/* ---- JUnit XML ---- */

static void property(FILE *f, const char *name, const char *value)
{
	fputs("      <property name=\"", f);
	escaped(f, name);
	fputs("\" value=\"", f);
	escaped(f, value ? value : "");
	fputs("\"/>\n", f);
}

static void junit_case(FILE *f, const char *suite, const json_t *fig)
{
	const char *status = json_get_str(fig, "status", "?"), *detail = json_get_str(fig, "detail", "");
	char value[32], out[600];
	fputs("    <testcase classname=\"", f);
	escaped(f, suite);
	fputc('.', f);
	escaped(f, json_get_str(fig, "case", "?"));
	fputs("\" name=\"", f);
	escaped(f, json_get_str(fig, "kind", "?"));
	fputs("\">\n", f);
	const char *element = !strcmp(status, "regressed") ? "failure" : !strcmp(status, "failed") ? "error"
			      : !strcmp(status, "did_not_run") ? "skipped" : NULL;
	if (element) {
		fprintf(f, "      <%s message=\"", element);
		escaped(f, detail);
		fprintf(f, "\"%s>", strcmp(element, "skipped") ? " type=\"" : "/");
		if (strcmp(element, "skipped")) {
			fputs(status, f);
			fputs("\">", f);
			escaped(f, detail);
			fprintf(f, "</%s>", element);
		}
		fputc('\n', f);
	}
	snprintf(out, sizeof out, "%s = %s %s (%s, check %s): %s", json_get_str(fig, "figure", "?"),
		 number(json_object_get(fig, "median"), value), json_get_str(fig, "unit", ""), status,
		 json_get_str(fig, "check", "?"), detail);
	fputs("      <system-out>", f);
	escaped(f, out);
	fputs("</system-out>\n    </testcase>\n", f);
}

void nightly_junit(FILE *f, const json_t *run)
{
	const json_t *figures = json_object_get(run, "figures"), *fig, *m = json_object_get(run, "machine");
	int tests = 0, failures = 0, errors = 0, skipped = 0;
	size_t i;
	json_array_foreach(figures, i, fig) {
		const char *s = json_get_str(fig, "status", "");
		tests++;
		failures += !strcmp(s, "regressed");
		errors += !strcmp(s, "failed");
		skipped += !strcmp(s, "did_not_run");
	}
	const char *suite = json_get_str(run, "suite", "suite");
	fputs("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n", f);
	fprintf(f, "<testsuites name=\"poro nightly\" tests=\"%d\" failures=\"%d\" errors=\"%d\" skipped=\"%d\">\n", tests,
		failures, errors, skipped);
	fputs("  <testsuite name=\"", f);
	escaped(f, suite);
	fprintf(f, "\" tests=\"%d\" failures=\"%d\" errors=\"%d\" skipped=\"%d\" timestamp=\"", tests, failures, errors,
		skipped);
	escaped(f, json_get_str(run, "created_at", ""));
	fputs("\" hostname=\"", f);
	escaped(f, json_get_str(run, "client_host", ""));
	fputs("\">\n    <properties>\n", f);
	char id[32], cores[32];
	snprintf(id, sizeof id, "%lld", json_get_int(run, "id", 0));
	property(f, "benchmark_run", id);
	property(f, "label", json_get_str(run, "label", ""));
	property(f, "commit", json_get_str(run, "commit", ""));
	property(f, "solver_version", json_get_str(run, "solver_version", ""));
	property(f, "state", json_get_str(run, "state", ""));
	property(f, "machine_fingerprint", json_get_str(run, "fingerprint", ""));
	if (json_is_object(m)) {
		snprintf(cores, sizeof cores, "%lld", json_get_int(m, "cores", 0));
		property(f, "cpu_model", json_get_str(m, "cpu_model", ""));
		property(f, "cores", cores);
		property(f, "kernel", json_get_str(m, "kernel", ""));
		property(f, "compiler", json_get_str(m, "compiler", ""));
		property(f, "blas", json_get_str(m, "blas", ""));
	}
	fputs("    </properties>\n", f);
	json_array_foreach(figures, i, fig)
		junit_case(f, suite, fig);
	fputs("  </testsuite>\n</testsuites>\n", f);
}

/* ---- HTML ---- */

static const char *status_colour(const char *status)
{
	if (!strcmp(status, "regressed") || !strcmp(status, "failed"))
		return "#c62828";
	if (!strcmp(status, "improved"))
		return "#2e7d32";
	if (!strcmp(status, "ok"))
		return "#1f77b4";
	return "#757575";
}

/* The y range of a series: its samples, medians and band ends, widened when flat. */
static void y_range(const json_t *points, double *lo, double *hi)
{
	*lo = INFINITY;
	*hi = -INFINITY;
	const json_t *p, *v;
	size_t i, k;
	json_array_foreach(points, i, p) {
		json_array_foreach(json_object_get(p, "samples"), k, v)
			if (json_is_number(v))
				*lo = fmin(*lo, json_number_value(v)), *hi = fmax(*hi, json_number_value(v));
		json_array_foreach(json_object_get(p, "band"), k, v)
			if (json_is_number(v))
				*lo = fmin(*lo, json_number_value(v)), *hi = fmax(*hi, json_number_value(v));
	}
	if (!isfinite(*lo)) {
		*lo = 0;
		*hi = 1;
	}
	double pad = *hi > *lo ? 0.08 * (*hi - *lo) : fabs(*hi) > 0 ? 0.05 * fabs(*hi) : 1;
	*lo -= pad;
	*hi += pad;
}

struct frame {
	double lo, hi;
	int n;
};

static double px_x(const struct frame *fr, int i)
{
	return PLOT_L + (PLOT_W - PLOT_L - PLOT_R) * (fr->n > 1 ? (double)i / (fr->n - 1) : 0.5);
}

static double px_y(const struct frame *fr, double v)
{
	return PLOT_T + (PLOT_H - PLOT_T - PLOT_B) * (1 - (v - fr->lo) / (fr->hi - fr->lo));
}

/* Axes, grid, the band of the last point (the suite's current band) and the x labels. */
static void plot_frame(FILE *f, const struct frame *fr, const json_t *points, const char *unit)
{
	const json_t *band = json_object_get(json_array_get(points, fr->n - 1), "band");
	if (json_is_array(band)) {
		double b0 = json_is_number(json_array_get(band, 0)) ? json_number_value(json_array_get(band, 0)) : fr->lo;
		double b1 = json_is_number(json_array_get(band, 1)) ? json_number_value(json_array_get(band, 1)) : fr->hi;
		fprintf(f, "<rect class=\"band\" x=\"%d\" y=\"%.1f\" width=\"%d\" height=\"%.1f\" fill=\"#dff0d8\"/>\n", PLOT_L,
			px_y(fr, fmin(b1, fr->hi)), PLOT_W - PLOT_L - PLOT_R,
			px_y(fr, fmax(b0, fr->lo)) - px_y(fr, fmin(b1, fr->hi)));
	}
	for (int t = 0; t <= 4; t++) {
		double v = fr->lo + (fr->hi - fr->lo) * t / 4, y = px_y(fr, v);
		fprintf(f, "<line x1=\"%d\" y1=\"%.1f\" x2=\"%d\" y2=\"%.1f\" stroke=\"#e0e0e0\"/>\n", PLOT_L, y,
			PLOT_W - PLOT_R, y);
		fprintf(f, "<text x=\"%d\" y=\"%.1f\" font-size=\"11\" text-anchor=\"end\">%.4g</text>\n", PLOT_L - 6, y + 4, v);
	}
	fprintf(f, "<rect x=\"%d\" y=\"%d\" width=\"%d\" height=\"%d\" fill=\"none\" stroke=\"#444\"/>\n", PLOT_L, PLOT_T,
		PLOT_W - PLOT_L - PLOT_R, PLOT_H - PLOT_T - PLOT_B);
	fprintf(f, "<text x=\"14\" y=\"%d\" font-size=\"11\" transform=\"rotate(-90 14 %d)\" text-anchor=\"middle\">",
		(PLOT_H - PLOT_B + PLOT_T) / 2, (PLOT_H - PLOT_B + PLOT_T) / 2);
	escaped(f, unit[0] && strcmp(unit, "1") ? unit : "ratio");
	fputs("</text>\n", f);
	int step = fr->n > X_LABELS_MAX ? (fr->n + X_LABELS_MAX - 1) / X_LABELS_MAX : 1;
	for (int i = 0; i < fr->n; i++) {
		if (i % step && i != fr->n - 1)
			continue;
		const json_t *p = json_array_get(points, (size_t)i);
		double x = px_x(fr, i), y = PLOT_H - PLOT_B + 14;
		fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" font-size=\"10\" text-anchor=\"end\" transform=\"rotate(-30 %.1f %.1f)\">"
			"#%lld ", x, y, x, y, json_get_int(p, "run", 0));
		escaped(f, json_get_str(p, "commit", ""));
		fputs("</text>\n", f);
	}
}

/* The series' samples, medians and verdicts; this run (id) ringed. */
static void plot_points(FILE *f, const struct frame *fr, const json_t *points, long long id)
{
	const json_t *p, *v;
	size_t i, k;
	fputs("<polyline class=\"median\" fill=\"none\" stroke=\"#1f77b4\" stroke-width=\"2\" points=\"", f);
	json_array_foreach(points, i, p)
		if (json_is_number(json_object_get(p, "median")))
			fprintf(f, "%.1f,%.1f ", px_x(fr, (int)i), px_y(fr, json_number_value(json_object_get(p, "median"))));
	fputs("\"/>\n", f);
	json_array_foreach(points, i, p) {
		double x = px_x(fr, (int)i);
		const char *status = json_get_str(p, "status", "?");
		json_array_foreach(json_object_get(p, "samples"), k, v)
			if (json_is_number(v))
				fprintf(f, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"2.5\" fill=\"#9e9e9e\"/>\n", x + 3.0 * ((int)k % 3 - 1),
					px_y(fr, json_number_value(v)));
		const json_t *median = json_object_get(p, "median");
		if (json_is_number(median)) {
			double y = px_y(fr, json_number_value(median));
			fprintf(f, "<circle class=\"verdict\" cx=\"%.1f\" cy=\"%.1f\" r=\"5\" fill=\"%s\"><title>run %lld: %s</title>"
				"</circle>\n", x, y, status_colour(status), json_get_int(p, "run", 0), status);
			if (json_get_int(p, "run", 0) == id)
				fprintf(f, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"9\" fill=\"none\" stroke=\"#000\" stroke-width=\"1.5\"/>\n",
					x, y);
		} else {
			fprintf(f, "<text x=\"%.1f\" y=\"%d\" font-size=\"16\" fill=\"#c62828\" text-anchor=\"middle\">&#215;"
				"<title>run %lld: %s</title></text>\n", x, PLOT_H - PLOT_B - 4, json_get_int(p, "run", 0), status);
		}
	}
}

static void html_plot(FILE *f, const json_t *fig, const json_t *series, long long id)
{
	const json_t *points = json_object_get(series, "points");
	int n = (int)json_array_size(points);
	if (n > SERIES_POINTS) {   /* the latest runs */
		json_t *last = json_array();
		for (int i = n - SERIES_POINTS; i < n; i++)
			json_array_append(last, json_array_get(points, (size_t)i));
		points = last;
		n = SERIES_POINTS;
	} else {
		json_incref((json_t *)points);
	}
	if (n == 0) {
		fputs("<p>No series: the figure was never measured on this machine.</p>\n", f);
		json_decref((json_t *)points);
		return;
	}
	struct frame fr = { .n = n };
	y_range(points, &fr.lo, &fr.hi);
	fprintf(f, "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" viewBox=\"0 0 %d %d\" role=\"img\">\n"
		"<title>", PLOT_W, PLOT_H, PLOT_W, PLOT_H);
	escaped(f, json_get_str(fig, "figure", ""));
	fputs(" over the runs</title>\n", f);
	plot_frame(f, &fr, points, json_get_str(fig, "unit", ""));
	plot_points(f, &fr, points, id);
	fputs("</svg>\n", f);
	json_decref((json_t *)points);
}

static void html_head(FILE *f, const json_t *run)
{
	const json_t *m = json_object_get(run, "machine");
	fputs("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>PoroMPM nightly ", f);
	escaped(f, json_get_str(run, "suite", ""));
	fprintf(f, ", run %lld</title>\n", json_get_int(run, "id", 0));
	fputs("<style>\nbody { font-family: sans-serif; margin: 24px; color: #222; }\n"
	      "table { border-collapse: collapse; }\n"
	      "td, th { padding: 3px 10px; border-bottom: 1px solid #ddd; text-align: left; }\n"
	      ".regressed, .failed { color: #c62828; font-weight: bold; } .did_not_run { color: #8a6d00; }\n"
	      ".ok { color: #1a7f37; } .improved { color: #2e7d32; } section { margin: 28px 0; }\n"
	      "svg { border: 1px solid #ccc; background: #fff; }\n</style>\n</head>\n<body>\n", f);
	fprintf(f, "<h1>Nightly %s, run %lld: <span class=\"%s\">%s</span></h1>\n", json_get_str(run, "suite", ""),
		json_get_int(run, "id", 0), json_get_str(run, "state", ""), json_get_str(run, "state", ""));
	/* the parts of the two lines: literal text, then the member of run (or of its machine) escaped */
	static const struct {
		const char *before, *key;
		int of_machine;
	} PARTS[] = {
		{ "<p>Label ", "label", 0 }, { ", commit ", "commit", 0 }, { ", solver ", "solver_version", 0 },
		{ ", from ", "created_at", 0 }, { " to ", "finished_at", 0 }, { ".</p>\n<p>Machine ", "fingerprint", 0 },
		{ ": ", "cpu_model", 1 }, { ", ", "kernel", 1 }, { ", ", "compiler", 1 }, { ", BLAS ", "blas", 1 },
	};
	for (size_t i = 0; i < sizeof PARTS / sizeof PARTS[0]; i++) {
		if (PARTS[i].of_machine && !json_is_object(m))
			break;
		fputs(PARTS[i].before, f);
		escaped(f, json_get_str(PARTS[i].of_machine ? m : run, PARTS[i].key, "unknown"));
	}
	if (json_is_object(m))
		fprintf(f, ", %lld cores, %lld MiB", json_get_int(m, "cores", 0), json_get_int(m, "memory_mb", 0));
	fputs(". Timing figures are plotted against this machine's runs only.</p>\n", f);
}

void nightly_html(FILE *f, const json_t *run, json_t *const *series)
{
	const json_t *fig;
	size_t i;
	char value[32];
	html_head(f, run);
	fputs("<table>\n<tr><th>figure</th><th>check</th><th>value</th><th>unit</th><th>verdict</th>"
	      "<th>detail</th></tr>\n", f);
	json_array_foreach(json_object_get(run, "figures"), i, fig) {
		const char *status = json_get_str(fig, "status", "?");
		fprintf(f, "<tr><td><a href=\"#f%zu\">", i);
		escaped(f, json_get_str(fig, "figure", ""));
		fprintf(f, "</a></td><td>%s</td><td>%s</td><td>", json_get_str(fig, "check", ""),
			number(json_object_get(fig, "median"), value));
		escaped(f, json_get_str(fig, "unit", ""));
		fprintf(f, "</td><td class=\"%s\">%s</td><td>", status, status);
		escaped(f, json_get_str(fig, "detail", ""));
		fputs("</td></tr>\n", f);
	}
	fputs("</table>\n", f);
	json_array_foreach(json_object_get(run, "figures"), i, fig) {
		fprintf(f, "<section id=\"f%zu\">\n<h2>", i);
		escaped(f, json_get_str(fig, "figure", ""));
		fprintf(f, " <span class=\"%s\">%s</span></h2>\n<p>", json_get_str(fig, "status", ""),
			json_get_str(fig, "status", ""));
		escaped(f, json_get_str(fig, "detail", ""));
		fputs("</p>\n", f);
		html_plot(f, fig, series[i], json_get_int(run, "id", 0));
		fputs("</section>\n", f);
	}
	fputs("</body>\n</html>\n", f);
}

/* The series of every figure of run: a timing figure's on its machine only. NULL entries for a
 * figure that has none to show. */
static json_t **fetch_series(const json_t *run, int *rc)
{
	const json_t *figures = json_object_get(run, "figures"), *fig;
	size_t n = json_array_size(figures), i;
	json_t **series = calloc(n + 1, sizeof *series);
	*rc = series ? 0 : PORO_EXIT_ERROR;
	json_array_foreach(figures, i, fig) {
		if (*rc)
			break;
		const char *machine = json_get_str(fig, "machine", NULL);
		int timing = !strcmp(json_get_str(fig, "class", ""), "timing");
		if (timing && !machine)
			continue;   /* never measured: no machine to draw it for */
		char path[512];
		snprintf(path, sizeof path, "/v1/benchmarks/series?suite=%s&figure=%s&limit=%d%s%s",
			 json_get_str(run, "suite", ""), json_get_str(fig, "figure", ""), SERIES_POINTS,
			 timing ? "&machine=" : "", timing ? machine : "");
		struct http_response r;
		if (cli_call("GET", path, NULL, NULL, &r) != 200)
			*rc = cli_fail(&r);
		else
			series[i] = json_incref(r.json);
		http_response_release(&r);
	}
	return series;
}

int nightly_write_report(const char *path, const json_t *run, int html)
{
	int rc = 0;
	size_t n = json_array_size(json_object_get(run, "figures"));
	json_t **series = html ? fetch_series(run, &rc) : NULL;
	char tmp[4200];
	snprintf(tmp, sizeof tmp, "%s.part", path);
	FILE *f = rc ? NULL : fopen(tmp, "w");
	if (!rc && !f) {
		fprintf(stderr, "poro: cannot create '%s': %s\n", tmp, strerror(errno));
		rc = PORO_EXIT_ERROR;
	}
	if (f) {
		if (html)
			nightly_html(f, run, series);
		else
			nightly_junit(f, run);
		int failed = ferror(f) != 0;
		if (fclose(f) != 0 || failed || rename(tmp, path) != 0) {
			fprintf(stderr, "poro: cannot write '%s': %s\n", path, strerror(errno));
			remove(tmp);
			rc = PORO_EXIT_ERROR;
		} else {
			fprintf(stderr, "poro: %s report of benchmark run %lld: %s\n", html ? "HTML" : "JUnit XML",
				json_get_int(run, "id", 0), path);
		}
	}
	for (size_t i = 0; series && i < n; i++)
		json_decref(series[i]);
	free(series);
	return rc;
}
