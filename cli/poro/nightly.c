/*
 * nightly.c - `poro nightly` (docs/benchmarks.md): the benchmark suite through the job service.
 *
 *   poro nightly run SUITE.json [--label L] [--commit C] [--only CASE]... [--junit FILE] [--html FILE] [--json]
 *   poro nightly show [ID] [--json]        the latest run without ID
 *   poro nightly compare A B [--json]
 *   poro nightly ls [--suite S] [--limit N] [--json]
 *   poro nightly report ID [--junit FILE] [--html FILE]
 *   poro nightly check SUITE.json [--out DIR] [--only CASE]...
 *
 * run reads and checks the suite (suite.c) before anything is sent, submits every case's repeats
 * as jobs of one batch (each carries the run's label; a case with a figure judged against history
 * runs its jobs exclusive, alone on a worker), creates the benchmark run with its plan, follows
 * the batch with one request a second (a bar on a terminal, else a line per job that ends), asks
 * the server to finish the run once every job has ended, and prints the verdicts. Exit 0 when the
 * run passed, 9 (PORO_EXIT_REGRESSED) when a figure regressed, failed or did not run.
 *
 * check reads and checks a suite without a server and prints what run would submit; with --out it
 * writes each case as submitted (patched, with the metrics it asks for) into DIR/NAME.json, which
 * `poro-solve validate` checks as the server would.
 *
 * The commit is `git describe --always --dirty --tags` of the suite file's checkout (--commit
 * overrides it; "unknown" outside a checkout): what the nightly ran, for the reports' x-axis.
 */
#define _GNU_SOURCE
#include "cli.h"
#include "nightly.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <sys/stat.h>
#include <unistd.h>

#include "bench_names.h"
#include "digest.h"
#include "json_get.h"

#define POLL_SECONDS 1.0
#define ONLY_MAX 64
#define LS_LIMIT_MAX 1000
#define LS_LIMIT_DEFAULT 20
#define BAR_WIDTH 30

struct nightly_options {
	const char *label, *commit, *junit, *html, *suite, *out;
	const char *only[ONLY_MAX];
	int only_count, json;
	long long limit;
};

/* ---- run ---- */

/* "SUITE-20261205T020000Z-1a2b": unique per run, valid as a batch label. */
static void make_label(const char *suite, char *out, size_t size)
{
	char stamp[32], token[DIGEST_TOKEN_SIZE];
	time_t now = time(NULL);
	struct tm tm;
	gmtime_r(&now, &tm);
	strftime(stamp, sizeof stamp, "%Y%m%dT%H%M%SZ", &tm);
	if (digest_new_token(token) < 0)
		snprintf(token, sizeof token, "poro_%08lx", (unsigned long)getpid());
	snprintf(out, size, "%.64s-%s-%.6s", suite, stamp, token + 5);
}

/* git describe of the checkout holding dir, or "unknown". */
static void git_describe(const char *dir, char *out, size_t size)
{
	char cmd[4400];
	snprintf(out, size, "unknown");
	snprintf(cmd, sizeof cmd, "git -C '%s' describe --always --dirty --tags 2>/dev/null", dir);
	if (strchr(dir, '\''))
		return;
	FILE *p = popen(cmd, "r");
	char line[256];
	if (p && fgets(line, sizeof line, p) && line[0] != '\n')
		snprintf(out, size, "%.*s", (int)strcspn(line, "\n"), line);
	if (p)
		pclose(p);
}

/* Why a submission was refused: the server's message and its first problem. */
static void refusal(const struct http_response *r, char *out, size_t size)
{
	const json_t *p = json_array_get(json_object_get(json_object_get(r->json, "error"), "problems"), 0);
	snprintf(out, size, "refused (%ld %s): %s%s%s%s%s", r->status, r->code, r->error, p ? "; " : "",
		 p ? json_get_str(p, "field", "") : "", p ? ": " : "", p ? json_get_str(p, "message", "") : "");
}

/* Submits the repeats of case c with the run's label; the ids into *jobs. A refused case is not
 * fatal (its figures did not run: *error says why); 0, or the exit status of a failure that ends
 * the run (no server, no token). */
static int submit_case(const struct suite *s, const struct suite_case *c, const char *label, json_t *jobs,
		       char *error, size_t error_size)
{
	error[0] = '\0';
	for (int k = 0; k < c->repeats; k++) {
		char name[160], header[300];
		snprintf(name, sizeof name, "%s/%s#%d", s->name, c->name, k + 1);
		snprintf(header, sizeof header, "Idempotency-Key: %.120s/%.64s/%d", label, c->name, k + 1);
		json_t *body = json_pack("{s:O, s:s, s:b, s:i, s:s}", "case", c->spec, "batch", label, "exclusive",
					 c->exclusive, "threads", c->threads, "name", name);
		if (c->wall_time_seconds)
			json_object_set_new(body, "wall_time_seconds", json_integer(c->wall_time_seconds));
		struct http_response r;
		long status = cli_call("POST", "/v1/jobs", body, header, &r);
		json_decref(body);
		if (status == 200 || status == 201) {
			json_array_append_new(jobs, json_integer(json_get_int(r.json, "id", 0)));
		} else if (status == 413 || status == 422) {
			refusal(&r, error, error_size);
			fprintf(stderr, "poro: case '%s' %s\n", c->name, error);
			http_response_release(&r);
			json_array_clear(jobs);   /* a case runs whole or not at all */
			return 0;
		} else {
			return cli_fail(&r);
		}
		http_response_release(&r);
	}
	return 0;
}

/* The creation body (schemas/openapi.yaml, BenchmarkCreate) once every case is submitted. */
static int submit_all(const struct suite *s, const char *label, json_t *cases)
{
	for (int i = 0; i < s->count; i++) {
		const struct suite_case *c = &s->cases[i];
		char error[1024];
		json_t *jobs = json_array();
		int rc = submit_case(s, c, label, jobs, error, sizeof error);
		if (rc) {
			json_decref(jobs);
			return rc;
		}
		json_t *entry = json_pack("{s:s, s:o, s:O}", "name", c->name, "jobs", jobs, "figures", c->figures);
		if (error[0])
			json_object_set_new(entry, "error", json_string(error));
		json_array_append_new(cases, entry);
	}
	return 0;
}

/* One line of the batch's progress: a bar on a terminal, redrawn; else a line per job that ends. */
static void show_progress(long long id, const json_t *run, int bar, double started, long long *last_ended)
{
	const json_t *p = json_object_get(run, "progress");
	long long jobs = json_get_int(p, "jobs", 0), ended = json_get_int(p, "ended", 0);
	double fraction = json_get_real(p, "fraction", 0);
	char d[32];
	if (bar) {
		char cells[BAR_WIDTH + 1];
		int filled = (int)(fraction * BAR_WIDTH + 0.5);
		for (int i = 0; i < BAR_WIDTH; i++)
			cells[i] = i < filled ? '#' : '.';
		cells[BAR_WIDTH] = '\0';
		fprintf(stderr, "\rbenchmark run %lld [%s] %3.0f%%  %lld/%lld jobs ended  %s elapsed ", id, cells,
			100 * fraction, ended, jobs, cli_duration(cli_now() - started, d));
		fflush(stderr);
	} else if (ended != *last_ended) {
		fprintf(stderr, "benchmark run %lld: %lld/%lld jobs ended, %s elapsed\n", id, ended, jobs,
			cli_duration(cli_now() - started, d));
	}
	*last_ended = ended;
}

/* Polls the run until every job of its batch has ended. */
static int follow(long long id)
{
	int bar = isatty(STDOUT_FILENO) && isatty(STDERR_FILENO);
	double started = cli_now();
	long long last = -1;
	char path[64];
	snprintf(path, sizeof path, "/v1/benchmarks/%lld", id);
	for (;;) {
		struct http_response r;
		if (cli_call("GET", path, NULL, NULL, &r) != 200) {
			if (bar)
				fputc('\n', stderr);
			return cli_fail(&r);
		}
		const json_t *p = json_object_get(r.json, "progress");
		int done = !p || json_get_int(p, "ended", 0) >= json_get_int(p, "jobs", 0);
		show_progress(id, r.json, bar, started, &last);
		http_response_release(&r);
		if (done) {
			if (bar)
				fputc('\n', stderr);
			return 0;
		}
		cli_sleep(POLL_SECONDS);
	}
}

/* The exit status of a finished run: 0 passed, PORO_EXIT_REGRESSED otherwise. */
static int exit_of_run(const json_t *run)
{
	return !strcmp(json_get_str(run, "state", ""), "passed") ? PORO_EXIT_OK : PORO_EXIT_REGRESSED;
}

static void print_run(const json_t *run);
static int write_reports(const struct nightly_options *o, const json_t *run);

static int nightly_run(const struct nightly_options *o, const char *path)
{
	struct suite s;
	int rc = suite_load(path, o->only, o->only_count, &s);
	if (rc || (rc = cli_connect())) {
		if (!rc)
			suite_release(&s);
		return rc;
	}
	char label[200], commit[160], host[128] = "";
	if (o->label)
		snprintf(label, sizeof label, "%s", o->label);
	else
		make_label(s.name, label, sizeof label);
	if (o->commit)
		snprintf(commit, sizeof commit, "%s", o->commit);
	else
		git_describe(s.dir, commit, sizeof commit);
	gethostname(host, sizeof host - 1);
	json_t *cases = json_array();
	rc = submit_all(&s, label, cases);
	json_t *body = json_pack("{s:s, s:s, s:s, s:s, s:o}", "suite", s.name, "label", label, "commit", commit,
				 "host", host[0] ? host : "unknown", "cases", cases);
	if (s.settings)
		json_object_set(body, "settings", s.settings);
	struct http_response r = { 0 };
	long long id = 0;
	if (!rc && cli_call("POST", "/v1/benchmarks", body, NULL, &r) != 201)
		rc = cli_fail(&r);
	else if (!rc) {
		id = json_get_int(r.json, "id", 0);
		fprintf(stderr, "benchmark run %lld: suite '%s', label %s, commit %s\n", id, s.name, label, commit);
		http_response_release(&r);
	}
	json_decref(body);
	suite_release(&s);
	if (rc || (rc = follow(id)))
		return rc;
	char path_finish[80];
	snprintf(path_finish, sizeof path_finish, "/v1/benchmarks/%lld/finish", id);
	if (cli_call("POST", path_finish, NULL, NULL, &r) != 200)
		return cli_fail(&r);
	if (o->json)
		rc = cli_print_json(r.json);
	else
		print_run(r.json);
	int reports = write_reports(o, r.json);
	int verdict = exit_of_run(r.json);
	http_response_release(&r);
	return rc ? rc : reports ? reports : verdict;
}

/* check: the plan of a suite, and with out the cases as they would be submitted. */
static int nightly_check(const struct nightly_options *o, const char *path)
{
	struct suite s;
	int rc = suite_load(path, o->only, o->only_count, &s);
	if (rc)
		return rc;
	if (o->out && mkdir(o->out, 0777) && errno != EEXIST) {
		fprintf(stderr, "poro: cannot create '%s': %s\n", o->out, strerror(errno));
		suite_release(&s);
		return PORO_EXIT_ERROR;
	}
	printf("suite %s: %d cases\n", s.name, s.count);
	for (int i = 0; i < s.count && !rc; i++) {
		const struct suite_case *c = &s.cases[i];
		printf("%-24s %-40s %3d repeat%s%s:", c->name, c->path, c->repeats, c->repeats == 1 ? " " : "s",
		       c->exclusive ? ", exclusive" : "");
		size_t k;
		const json_t *f;
		json_array_foreach(c->figures, k, f)
			printf(" %s (%s)", json_get_str(f, "kind", "?"), json_get_str(f, "check", "?"));
		printf("\n");
		char file[8400];
		snprintf(file, sizeof file, "%s/%s.json", o->out ? o->out : ".", c->name);
		if (o->out && json_dump_file(c->spec, file, JSON_INDENT(1)) != 0) {
			fprintf(stderr, "poro: cannot write '%s'\n", file);
			rc = PORO_EXIT_ERROR;
		}
	}
	suite_release(&s);
	return rc;
}

/* ---- show, compare, ls ---- */

/* A value in a column of 12: %.4g, or "-" when absent. */
static const char *value_text(const json_t *v, char out[32])
{
	if (json_is_number(v))
		snprintf(out, 32, "%.4g", json_number_value(v));
	else
		snprintf(out, 32, "-");
	return out;
}

/* What a figure was judged against: its band, or its history's median and size. */
static const char *against_text(const json_t *f, char out[64])
{
	const json_t *band = json_object_get(f, "band"), *stats = json_object_get(f, "stats");
	char a[32], b[32];
	const json_t *lo = json_array_get(band, 0), *hi = json_array_get(band, 1);
	if (json_is_array(band))
		snprintf(out, 64, "[%.24s, %.24s]", json_is_number(lo) ? value_text(lo, a) : "",
			 json_is_number(hi) ? value_text(hi, b) : "");
	else if (json_is_number(json_object_get(stats, "history_median")))
		snprintf(out, 64, "%s (%lld samples)", value_text(json_object_get(stats, "history_median"), a),
			 json_get_int(stats, "history_samples", 0));
	else
		snprintf(out, 64, "-");
	return out;
}

static void print_run(const json_t *run)
{
	const json_t *m = json_object_get(run, "machine"), *summary = json_object_get(run, "summary"), *f, *v;
	printf("benchmark run %lld: suite %s, label %s, commit %s: %s\n", json_get_int(run, "id", 0),
	       json_get_str(run, "suite", "?"), json_get_str(run, "label", "?"), json_get_str(run, "commit", "?"),
	       json_get_str(run, "state", "?"));
	printf("created %s, finished %s, solver %s\n", json_get_str(run, "created_at", "-"),
	       json_get_str(run, "finished_at", "-"), json_get_str(run, "solver_version", "-"));
	if (json_is_object(m))
		printf("machine %s: %s, %lld cores, %lld MiB, %s, %s, BLAS %s\n", json_get_str(run, "fingerprint", "?"),
		       json_get_str(m, "cpu_model", "?"), json_get_int(m, "cores", 0), json_get_int(m, "memory_mb", 0),
		       json_get_str(m, "kernel", "?"), json_get_str(m, "compiler", "?"), json_get_str(m, "blas", "?"));
	printf("\n%-44s %-8s %-12s %-5s %-24s %-8s %s\n", "FIGURE", "CHECK", "VALUE", "UNIT", "AGAINST", "CHANGE", "STATUS");
	size_t i;
	json_array_foreach(json_object_get(run, "figures"), i, f) {
		char val[32], against[64], change[16] = "";
		double ratio = json_get_real(json_object_get(f, "stats"), "ratio", NAN);
		if (isfinite(ratio))
			snprintf(change, sizeof change, "%+.1f%%", 100 * (ratio - 1));
		printf("%-44s %-8s %-12s %-5s %-24s %-8s %s\n", json_get_str(f, "figure", "?"), json_get_str(f, "check", "?"),
		       value_text(json_object_get(f, "median"), val), json_get_str(f, "unit", ""), against_text(f, against),
		       change, json_get_str(f, "status", "?"));
	}
	json_array_foreach(json_object_get(run, "figures"), i, f) {
		const char *status = json_get_str(f, "status", "ok");
		if (strcmp(status, "ok") && strcmp(status, "recorded"))
			printf("  %s %s: %s\n", json_get_str(f, "figure", "?"), status, json_get_str(f, "detail", ""));
	}
	const char *key;
	printf("\nfigures:");
	json_object_foreach((json_t *)summary, key, v)
		printf(" %lld %s", (long long)json_integer_value(v), key);
	printf("\n");
}

static int get_run(long long id, struct http_response *r)
{
	char path[64];
	snprintf(path, sizeof path, "/v1/benchmarks/%lld", id);
	return cli_call("GET", path, NULL, NULL, r) == 200 ? 0 : cli_fail(r);
}

/* The newest run's id; 0 with none. */
static int latest_run(long long *id)
{
	struct http_response r;
	if (cli_call("GET", "/v1/benchmarks?limit=1", NULL, NULL, &r) != 200)
		return cli_fail(&r);
	*id = json_get_int(json_array_get(json_object_get(r.json, "runs"), 0), "id", 0);
	http_response_release(&r);
	if (!*id) {
		fprintf(stderr, "poro: no benchmark runs yet\n");
		return PORO_EXIT_NOT_FOUND;
	}
	return 0;
}

static int nightly_show(const struct nightly_options *o, long long id)
{
	struct http_response r;
	int rc = id ? 0 : latest_run(&id);
	if (rc || (rc = get_run(id, &r)))
		return rc;
	if (o->json)
		rc = cli_print_json(r.json);
	else
		print_run(r.json);
	int verdict = !strcmp(json_get_str(r.json, "state", ""), "running") ? PORO_EXIT_OK : exit_of_run(r.json);
	http_response_release(&r);
	return rc ? rc : verdict;
}

/* The figure named name in run's figures, or NULL. */
static const json_t *figure_of(const json_t *run, const char *name)
{
	size_t i;
	const json_t *f;
	json_array_foreach(json_object_get(run, "figures"), i, f)
		if (!strcmp(json_get_str(f, "figure", ""), name))
			return f;
	return NULL;
}

/* One row of compare: both medians, the change, both verdicts; timings of two machines are shown
 * but not compared. */
static void compare_row(const char *name, const json_t *fa, const json_t *fb)
{
	char a[32], b[32], change[40] = "";
	const json_t *va = json_object_get(fa, "median"), *vb = json_object_get(fb, "median");
	const char *ma = json_get_str(fa, "machine", ""), *mb = json_get_str(fb, "machine", "");
	const char *cls = json_get_str(fa ? fa : fb, "class", "");
	if (fa && fb && !strcmp(cls, "timing") && strcmp(ma, mb))
		snprintf(change, sizeof change, "not compared: machines differ");
	else if (json_is_number(va) && json_is_number(vb) && json_number_value(va) != 0)
		snprintf(change, sizeof change, "%+.1f%%", 100 * (json_number_value(vb) / json_number_value(va) - 1));
	printf("%-44s %-12s %-12s %-30s %-12s %s\n", name, value_text(va, a), value_text(vb, b), change,
	       fa ? json_get_str(fa, "status", "?") : "-", fb ? json_get_str(fb, "status", "?") : "-");
}

static int nightly_compare(const struct nightly_options *o, long long a, long long b)
{
	struct http_response ra, rb;
	int rc = get_run(a, &ra);
	if (rc)
		return rc;
	if ((rc = get_run(b, &rb))) {
		http_response_release(&ra);
		return rc;
	}
	if (o->json) {
		json_t *both = json_pack("{s:O, s:O}", "a", ra.json, "b", rb.json);
		rc = cli_print_json(both);
		json_decref(both);
	} else {
		const json_t *runs[2] = { ra.json, rb.json };
		for (int k = 0; k < 2; k++)
			printf("%s: run %lld, suite %s, commit %s, machine %s, %s\n", k ? "B" : "A",
			       json_get_int(runs[k], "id", 0), json_get_str(runs[k], "suite", "?"),
			       json_get_str(runs[k], "commit", "?"), json_get_str(runs[k], "fingerprint", "-"),
			       json_get_str(runs[k], "state", "?"));
		if (strcmp(json_get_str(ra.json, "fingerprint", ""), json_get_str(rb.json, "fingerprint", "")))
			printf("the runs' machines differ: their timing figures are not compared\n");
		printf("\n%-44s %-12s %-12s %-30s %-12s %s\n", "FIGURE", "A", "B", "CHANGE", "A STATUS", "B STATUS");
		size_t i;
		const json_t *f;
		json_array_foreach(json_object_get(ra.json, "figures"), i, f) {
			const char *name = json_get_str(f, "figure", "?");
			compare_row(name, f, figure_of(rb.json, name));
		}
		json_array_foreach(json_object_get(rb.json, "figures"), i, f)
			if (!figure_of(ra.json, json_get_str(f, "figure", "")))
				compare_row(json_get_str(f, "figure", "?"), NULL, f);
	}
	http_response_release(&ra);
	http_response_release(&rb);
	return rc;
}

static int nightly_ls(const struct nightly_options *o)
{
	char path[160];
	snprintf(path, sizeof path, "/v1/benchmarks?limit=%lld%s%s", o->limit, o->suite ? "&suite=" : "",
		 o->suite ? o->suite : "");
	struct http_response r;
	if (cli_call("GET", path, NULL, NULL, &r) != 200)
		return cli_fail(&r);
	int rc = PORO_EXIT_OK;
	if (o->json) {
		rc = cli_print_json(r.json);
	} else {
		printf("%-6s %-12s %-40s %-20s %-10s %s\n", "ID", "SUITE", "LABEL", "COMMIT", "STATE", "CREATED");
		size_t i;
		const json_t *run;
		json_array_foreach(json_object_get(r.json, "runs"), i, run)
			printf("%-6lld %-12.12s %-40.40s %-20.20s %-10s %s\n", json_get_int(run, "id", 0),
			       json_get_str(run, "suite", "?"), json_get_str(run, "label", "?"), json_get_str(run, "commit", "?"),
			       json_get_str(run, "state", "?"), json_get_str(run, "created_at", "?"));
	}
	http_response_release(&r);
	return rc;
}

/* ---- reports ---- */

static int write_reports(const struct nightly_options *o, const json_t *run)
{
	int rc = 0;
	if (o->junit && (rc = nightly_write_report(o->junit, run, 0)))
		return rc;
	if (o->html)
		rc = nightly_write_report(o->html, run, 1);
	return rc;
}

static int nightly_report(const struct nightly_options *o, long long id)
{
	struct http_response r;
	int rc = get_run(id, &r);
	if (rc)
		return rc;
	if (!strcmp(json_get_str(r.json, "state", ""), "running")) {
		fprintf(stderr, "poro: benchmark run %lld is still running: it has no verdicts to report yet\n", id);
		rc = PORO_EXIT_ERROR;
	} else {
		rc = write_reports(o, r.json);
	}
	http_response_release(&r);
	return rc;
}

/* ---- command line ---- */

/* The options each command takes beyond --json and --help; a misplaced one is refused. */
static int check_options(const struct subcommand *self, const char *what, const struct nightly_options *o)
{
	int run = !strcmp(what, "run"), report = !strcmp(what, "report"), plan = !strcmp(what, "check");
	if (!run && (o->label || o->commit))
		return cli_usage_error(self, "--label and --commit are options of 'nightly run'");
	if (!run && !plan && o->only_count)
		return cli_usage_error(self, "--only is an option of 'nightly run' and 'nightly check'");
	if (!plan && o->out)
		return cli_usage_error(self, "--out is an option of 'nightly check'");
	if (!run && !report && (o->junit || o->html))
		return cli_usage_error(self, "--junit and --html are options of 'nightly run' and 'nightly report'");
	if (strcmp(what, "ls") && (o->suite || o->limit != LS_LIMIT_DEFAULT))
		return cli_usage_error(self, "--suite and --limit are options of 'nightly ls'");
	if (report && !o->junit && !o->html)
		return cli_usage_error(self, "'nightly report' needs --junit FILE, --html FILE or both");
	if (o->label && !bench_label_valid(o->label))
		return cli_usage_error(self, "--label '%s' must be 1 to 128 characters of A-Z a-z 0-9 . _ : -", o->label);
	if (o->suite && !bench_label_valid(o->suite))
		return cli_usage_error(self, "--suite '%s' is not a suite name", o->suite);
	return 0;
}

/* The command word and its arguments, once the options are parsed. */
static int nightly_dispatch(const struct subcommand *self, int argc, char **argv, const struct nightly_options *o)
{
	static const char *const words[] = { "run", "show", "compare", "ls", "report", "check", NULL };
	const char *what = optind < argc ? argv[optind] : NULL;
	int known = 0, rc;
	for (const char *const *w = words; what && *w && !known; w++)
		known = !strcmp(*w, what);
	if (!what)
		return cli_usage_error(self, "missing the command: run, show, compare, ls, report or check");
	if (!known)
		return cli_usage_error(self, "unknown nightly command '%s': run, show, compare, ls, report or check", what);
	if ((rc = check_options(self, what, o)))
		return rc;
	optind++;
	long long a = 0, b = 0;
	if (!strcmp(what, "run"))
		return (rc = cli_positional(self, argc, argv, 1, "the suite file SUITE.json")) ? rc
											    : nightly_run(o, argv[optind]);
	if (!strcmp(what, "check"))
		return (rc = cli_positional(self, argc, argv, 1, "the suite file SUITE.json")) ? rc
											    : nightly_check(o, argv[optind]);
	if (!strcmp(what, "ls"))
		return (rc = cli_positional(self, argc, argv, 0, "")) || (rc = cli_connect()) ? rc : nightly_ls(o);
	if (!strcmp(what, "show")) {
		if (argc - optind > 0 && ((rc = cli_positional(self, argc, argv, 1, "")) ||
					  (rc = cli_parse_id(self, argv[optind], &a))))
			return rc;
		return (rc = cli_connect()) ? rc : nightly_show(o, a);
	}
	if (!strcmp(what, "report"))
		return (rc = cli_positional(self, argc, argv, 1, "the run ID")) ||
		       (rc = cli_parse_id(self, argv[optind], &a)) || (rc = cli_connect()) ? rc : nightly_report(o, a);
	if ((rc = cli_positional(self, argc, argv, 2, "the two run IDs A B")) ||
	    (rc = cli_parse_id(self, argv[optind], &a)) || (rc = cli_parse_id(self, argv[optind + 1], &b)) ||
	    (rc = cli_connect()))
		return rc;
	return nightly_compare(o, a, b);
}

int cmd_nightly(const struct subcommand *self, int argc, char **argv)
{
	static const struct option opts[] = {
		{ "label", required_argument, NULL, 'l' }, { "commit", required_argument, NULL, 'c' },
		{ "only", required_argument, NULL, 'o' },  { "junit", required_argument, NULL, 'J' },
		{ "html", required_argument, NULL, 'H' },  { "json", no_argument, NULL, 'j' },
		{ "suite", required_argument, NULL, 's' }, { "limit", required_argument, NULL, 'n' },
		{ "out", required_argument, NULL, 'O' },
		{ "help", no_argument, NULL, 'h' },        { NULL, 0, NULL, 0 }
	};
	struct nightly_options o = { .limit = LS_LIMIT_DEFAULT };
	int c, rc;
	while ((c = getopt_long(argc, argv, "hj", opts, NULL)) != -1) {
		switch (c) {
		case 'h': return cli_help(self);
		case 'l': o.label = optarg; break;
		case 'c': o.commit = optarg; break;
		case 'J': o.junit = optarg; break;
		case 'H': o.html = optarg; break;
		case 'j': o.json = 1; break;
		case 's': o.suite = optarg; break;
		case 'O': o.out = optarg; break;
		case 'o':
			if (o.only_count == ONLY_MAX)
				return cli_usage_error(self, "at most %d --only", ONLY_MAX);
			o.only[o.only_count++] = optarg;
			break;
		case 'n':
			if ((rc = cli_parse_int(self, "--limit", optarg, 1, LS_LIMIT_MAX, &o.limit)))
				return rc;
			break;
		default: return cli_usage_error(self, NULL);
		}
	}
	return nightly_dispatch(self, argc, argv, &o);
}
