/*
 * poro_solve.c - the poro-solve command: the solver library behind a command line.
 *
 *   poro-solve run CASE.json --out DIR [--resume CHECKPOINT] [--checkpoint-wall SECONDS]
 *                                        run a case, write DIR/result.h5 and DIR/result.xdmf
 *   poro-solve validate CASE.json        check a case (a simulation case, or an element case by its
 *                                        "schema"); every problem as "JSON-pointer: message"
 *   poro-solve element CASE.json --out DIR
 *                                        single-element triaxial test (element.h, docs/element.md):
 *                                        DIR/element.csv (poro-plot draws it)
 *   poro-solve report RESULT.h5 [--out FILE] [--ground Y] [--crest X] [--tolerance M]
 *                     [--line X0,Y0,X1,Y1[,...][,N] --line-out FILE [--at TIME]]
 *                                        derived quantities of a run (report.h, docs/report.md): a
 *                                        CSV row per frame (toe, run-out, crest settlement, soil-water
 *                                        gap, oscillation index) to stdout or FILE, and the pore
 *                                        pressure along a line at the frame nearest TIME (default the
 *                                        last) to the --line-out FILE
 *   poro-solve probes RESULT.h5 --job ID --attempt N [--out FILE]
 *                                        the probe series of a run as the JSON document the job
 *                                        service serves (docs/service.md §3, GET .../probes):
 *                                        {"job", "attempt", "probes": {name: {"unit", "time",
 *                                        "value"}}}, names in the order of the case, to stdout or FILE
 *   poro-solve version
 *
 * run writes DIR/checkpoint.h5 every checkpoint.interval of simulated time (case key) and every
 * --checkpoint-wall seconds of wall time, whichever comes first, and prints
 * "checkpoint step=N time=T" after each; --resume continues from such a checkpoint, keeping the
 * frames of DIR/result.h5 up to it (checkpoint.h, docs/service.md §2). A checkpoint of another
 * case is refused with exit 2, naming the first difference.
 *
 * probes runs in its own process because a result file is untrusted input for whoever reads it: the
 * worker runs it on each result.h5 it uploads, so a damaged file can crash only this process, never
 * the server (which no longer links HDF5). Numbers are written with 17 significant digits, so they
 * read back to the same doubles; a value that is not finite is written as null (JSON has no NaN).
 *
 * Exit codes come from the status table in error.h: 0 success, 2 invalid input, 3 solver failure
 * (NaN, a point leaving the grid, a failed factorisation), 4 I/O, 5 out of memory, 6 interrupted.
 * Progress goes to stdout, one line per report; errors to stderr, prefixed "poro-solve: ".
 */
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "case.h"
#include "checkpoint.h"
#include "element.h"
#include "poro.h"
#include "report.h"
#include "results_read.h"

#ifndef PORO_VERSION
#define PORO_VERSION "unknown"
#endif

static volatile int stop_requested;

static void on_signal(int sig)
{
	(void)sig;
	stop_requested = 1;
}

static int usage(void)
{
	fprintf(stderr, "usage: poro-solve run CASE.json --out DIR [--resume CHECKPOINT] [--checkpoint-wall SECONDS]\n"
			"       poro-solve validate CASE.json\n"
			"       poro-solve element CASE.json --out DIR\n"
			"       poro-solve report RESULT.h5 [--out FILE] [--ground Y] [--crest X] [--tolerance M]\n"
			"                         [--line X0,Y0,X1,Y1[,...][,N] --line-out FILE [--at TIME]]\n"
			"       poro-solve probes RESULT.h5 --job ID --attempt N [--out FILE]\n"
			"       poro-solve version\n");
	return 2;
}

static int fail(enum poro_status st, const struct poro_error *err, const char *what)
{
	fprintf(stderr, "poro-solve: %s: %s\n%s\n", what, poro_status_meaning(st), err->message);
	return poro_status_exit_code(st);
}

static void print_progress(const struct sim_progress *p, void *user)
{
	(void)user;
	if (p->checkpoint) {   /* the worker uploads checkpoint.h5 and result.h5 on this line */
		printf("checkpoint step=%ld time=%.9g\n", p->step, p->time);
		fflush(stdout);
		return;
	}
	printf("step %ld/%ld  t = %.6g s  wall = %.2f s  %.3f us per material-point step\n", p->step,
	       p->steps_total, p->time, p->wall_seconds, p->us_per_point_step);
	fflush(stdout);
}

/* A valid case's warnings (case.h), each line as "PATH: warning: POINTER: message" on stderr. */
static void print_warnings(const char *path, const char *warnings)
{
	for (const char *line = warnings; *line;) {
		size_t len = strcspn(line, "\n");
		fprintf(stderr, "%s: warning: %.*s\n", path, (int)len, line);
		line += len + (line[len] == '\n');
	}
}

static int cmd_validate(const char *path)
{
	struct case_spec *c = NULL;
	struct poro_error err = {0};
	if (element_case_file_is_element(path)) {
		struct element_case e;
		enum poro_status st = element_case_load_file(path, &e, &err);
		if (st)
			return fail(st, &err, path);
		print_warnings(path, e.warnings);
		printf("%s: valid element case\n", path);
		return 0;
	}
	enum poro_status st = case_load_file(path, &c, &err);
	if (st)
		return fail(st, &err, path);
	print_warnings(path, c->warnings);
	printf("%s: valid\n", path);
	case_destroy(&c);
	return 0;
}

/* element CASE.json --out DIR: an element case (its own schema, "poro-element/1") through the
 * single-element driver. */
static int cmd_element(const char *path, const char *out_dir)
{
	struct element_case c;
	struct element_result r = {0};
	struct poro_error err = {0};
	enum poro_status st = element_case_load_file(path, &c, &err);
	if (st)
		return fail(st, &err, path);
	print_warnings(path, c.warnings);
	st = element_run(&c, &r, &err);
	if (!st)
		st = element_write(&c, &r, out_dir, &err);
	if (st) {
		element_result_release(&r);
		return fail(st, &err, path);
	}
	const struct element_row *last = &r.row[r.rows - 1];
	printf("%d steps: axial strain %.6g, p = %.6g Pa, q = %.6g Pa, volumetric strain %.6g\n", r.rows - 1,
	       last->axial_strain, last->p, last->q, last->volumetric_strain);
	printf("done: %s/element.csv (pictures: poro-plot %s/element.csv)\n", out_dir, out_dir);
	element_result_release(&r);
	return 0;
}

/* text as a whole finite number into *value; -1 when it is not one. */
static int parse_number(const char *text, double *value)
{
	char *end;
	*value = strtod(text, &end);
	return end == text || *end || !isfinite(*value) ? -1 : 0;
}

/* What `run` was asked for besides the case. */
struct run_options {
	const char *out_dir;
	const char *resume;         /* checkpoint to continue from, or NULL */
	double checkpoint_wall;     /* s of wall time between checkpoints, 0 = none */
};

static int cmd_run(const char *path, const struct run_options *opt)
{
	const char *out_dir = opt->out_dir;
	struct case_spec *c = NULL;
	struct sim *s = NULL;
	struct poro_error err = {0};
	enum poro_status st = case_load_file(path, &c, &err);
	if (st)
		return fail(st, &err, path);
	print_warnings(path, c->warnings);
	st = sim_create(&s, c, &err);
	if (st) {
		case_destroy(&c);
		return fail(st, &err, path);
	}
	if (opt->resume && (st = checkpoint_load(s, opt->resume))) {
		int code = fail(st, sim_error(s), opt->resume);
		sim_destroy(&s);
		case_destroy(&c);
		return code;
	}
	sim_set_checkpoint_wall(s, opt->checkpoint_wall);
	printf("case '%s': %ld soil points, %ld water points, %ld steps\n", c->title,
	       (long)sim_soil(s)->n, sim_is_double_point(s) ? (long)sim_water(s)->n : 0L, sim_steps_total(s));
	if (c->time.dt_auto)
		printf("dt \"auto\": %.6g s, the %s scheme's recommended step\n", c->time.dt,
		       c->formulation.scheme == SCHEME_EXPLICIT ? "explicit" : "semi-implicit");
	if (opt->resume)
		printf("resumed from '%s' at step %ld, t = %.6g s\n", opt->resume, sim_steps_taken(s), sim_time(s));
	signal(SIGTERM, on_signal);
	signal(SIGINT, on_signal);
	st = sim_run(s, out_dir, PORO_VERSION, print_progress, NULL, &stop_requested);
	if (!st && sim_warning(s))   /* a failure's message quotes it already (step_health.c) */
		printf("warning: %s\n", sim_warning(s));
	int code = 0;
	if (st)
		code = fail(st, sim_error(s), path);
	else
		printf("done: %s/result.h5\n", out_dir);
	sim_destroy(&s);
	case_destroy(&c);
	return code;
}

/* run CASE.json --out DIR [--resume CHECKPOINT] [--checkpoint-wall SECONDS], options in any order. */
static int parse_run(int argc, char **argv)
{
	struct run_options opt = {0};
	for (int i = 3; i < argc; i += 2) {
		if (i + 1 >= argc)
			return usage();
		if (!strcmp(argv[i], "--out")) {
			opt.out_dir = argv[i + 1];
		} else if (!strcmp(argv[i], "--resume")) {
			opt.resume = argv[i + 1];
		} else if (!strcmp(argv[i], "--checkpoint-wall")) {
			if (parse_number(argv[i + 1], &opt.checkpoint_wall) || !(opt.checkpoint_wall > 0) ||
			    opt.checkpoint_wall > 1e9) {
				fprintf(stderr, "poro-solve: --checkpoint-wall: '%s' is not a number of seconds > 0\n",
					argv[i + 1]);
				return 2;
			}
		} else {
			return usage();
		}
	}
	return opt.out_dir ? cmd_run(argv[2], &opt) : usage();
}

/* What `report` was asked for besides the result file. */
struct report_options {
	const char *out;            /* the per-frame table, or NULL for stdout */
	const char *line;           /* "X0,Y0,X1,Y1[,...][,N]", or NULL for no line */
	const char *line_out;       /* the line table */
	double at;                  /* s, NAN = the last frame */
	struct report_settings settings;
};

/* Opens path for writing, or reports why not (exit 4) and returns NULL. */
static FILE *create_output(const char *path)
{
	FILE *f = fopen(path, "w");
	if (!f) {
		struct poro_error err = {0};
		fail(poro_error_set(&err, PORO_EIO, "cannot create '%s': %s", path, strerror(errno)), &err, path);
	}
	return f;
}

/* Writes the two tables once everything is computed, so invalid input leaves no file behind. */
static int write_report(const struct report_options *opt, const struct report_row *rows, long count,
			const struct report_sample *samples, int sample_count)
{
	struct poro_error err = {0};
	FILE *f = opt->out ? create_output(opt->out) : stdout;
	if (!f)
		return poro_status_exit_code(PORO_EIO);
	enum poro_status st = report_frames_write(f, opt->out ? opt->out : "stdout", rows, count, &err);
	if (opt->out && fclose(f) != 0 && !st)
		st = poro_error_set(&err, PORO_EIO, "cannot write '%s': %s", opt->out, strerror(errno));
	if (!st && samples) {
		if (!(f = create_output(opt->line_out)))
			return poro_status_exit_code(PORO_EIO);
		st = report_line_write(f, opt->line_out, samples, sample_count, &err);
		if (fclose(f) != 0 && !st)
			st = poro_error_set(&err, PORO_EIO, "cannot write '%s': %s", opt->line_out, strerror(errno));
	}
	return st ? fail(st, &err, "report") : 0;
}

static int cmd_report(const char *path, const struct report_options *opt)
{
	struct report *rep = NULL;
	struct report_row *rows = NULL;
	struct report_sample *samples = NULL;
	struct report_line line = {0};
	struct poro_error err = {0};
	double frame_time = NAN;
	long count = 0;
	enum poro_status st = opt->line ? report_line_parse(opt->line, &line, &err) : PORO_OK;
	if (st)
		return fail(st, &err, "--line");
	if (!(st = report_open(&rep, path, &opt->settings, &err)))
		st = report_frames(rep, &rows, &count, &err);
	if (!st && opt->line)
		st = report_line_sample(rep, &line, opt->at, &samples, &frame_time, &err);
	int code = st ? fail(st, &err, path) : write_report(opt, rows, count, samples, line.samples);
	if (!code && opt->out) {
		const struct report_settings *set = report_settings_used(rep);
		printf("report: %ld frames, ground y = %.9g m, crest x = %.9g m, tolerance %.9g m: %s\n", count,
		       set->ground, set->crest, set->tolerance, opt->out);
		if (samples)
			printf("line: %d samples at the frame of t = %.9g s: %s\n", line.samples, frame_time, opt->line_out);
	}
	free(rows);
	free(samples);
	report_close(&rep);
	return code;
}

/* One refused command line of `report`: the problem, then the usage. */
static int report_usage(const char *problem, const char *subject)
{
	fprintf(stderr, "poro-solve: report: %s '%s'\n", problem, subject);
	return usage();
}

/* report RESULT.h5 [options], options in any order (struct report_options). */
static int parse_report(int argc, char **argv)
{
	struct report_options opt = {.at = NAN, .settings = REPORT_SETTINGS_DEFAULT};
	for (int i = 3; i < argc; i += 2) {
		const char *key = argv[i], *value = i + 1 < argc ? argv[i + 1] : NULL;
		double *number = !strcmp(key, "--ground") ? &opt.settings.ground :
				 !strcmp(key, "--crest") ? &opt.settings.crest :
				 !strcmp(key, "--tolerance") ? &opt.settings.tolerance :
				 !strcmp(key, "--at") ? &opt.at : NULL;
		const char **text = !strcmp(key, "--out") ? &opt.out :
				    !strcmp(key, "--line") ? &opt.line :
				    !strcmp(key, "--line-out") ? &opt.line_out : NULL;
		if (!number && !text)
			return report_usage("unknown option", key);
		if (!value)
			return report_usage("no value after", key);
		if (number && parse_number(value, number)) {
			fprintf(stderr, "poro-solve: %s: '%s' is not a number\n", key, value);
			return 2;
		}
		if (text)
			*text = value;
	}
	if (opt.line && !opt.line_out)
		return report_usage("no --line-out FILE for", "--line");
	if (!opt.line && (opt.line_out || !isnan(opt.at)))
		return report_usage("no --line for", opt.line_out ? "--line-out" : "--at");
	return cmd_report(argv[2], &opt);
}

/* ---- probes ---------------------------------------------------------------------------------- */

/* Writes text as a JSON string. Probe names come from the case, which jansson has read, so they are
 * valid UTF-8; units are the solver's ASCII names, and any other byte in them is a damaged file's,
 * written as '?' so the document stays valid UTF-8 whatever the file holds. */
static void write_json_string(FILE *f, const char *text, int ascii_only)
{
	fputc('"', f);
	for (const unsigned char *p = (const unsigned char *)text; *p; p++) {
		if (*p == '"' || *p == '\\')
			fprintf(f, "\\%c", *p);
		else if (*p < 0x20)
			fprintf(f, "\\u%04x", *p);
		else
			fputc(ascii_only && *p >= 0x7f ? '?' : *p, f);
	}
	fputc('"', f);
}

static void write_json_numbers(FILE *f, const double *x, long n)
{
	fputc('[', f);
	for (long k = 0; k < n; k++) {
		if (k)
			fputc(',', f);
		if (!isfinite(x[k])) {
			fputs("null", f);
			continue;
		}
		char text[32];   /* the shortest of 15, 16, 17 digits that reads back to x[k] */
		for (int digits = 15; digits <= 17; digits++) {
			snprintf(text, sizeof text, "%.*g", digits, x[k]);
			if (strtod(text, NULL) == x[k])
				break;
		}
		fputs(text, f);
	}
	fputc(']', f);
}

/* The "probes" object: each probe of the case, in its order, read from the file. */
static enum poro_status write_probes(FILE *f, struct results *res, const struct case_spec *c,
				     struct poro_error *err)
{
	fputs("\"probes\": {", f);
	for (int i = 0; i < c->probe_count; i++) {
		double *t = NULL, *v = NULL;
		char *units = NULL;
		long n = 0;
		enum poro_status st = results_probe_read(res, c->probes[i].name, &t, &v, &n, &units, err);
		if (st)
			return st;
		if (i)
			fputs(", ", f);
		write_json_string(f, c->probes[i].name, 0);
		fputs(": {\"unit\": ", f);
		write_json_string(f, units ? units : "", 1);
		fputs(", \"time\": ", f);
		write_json_numbers(f, t, n);
		fputs(", \"value\": ", f);
		write_json_numbers(f, v, n);
		fputc('}', f);
		free(t), free(v), free(units);
	}
	fputs("}", f);
	return PORO_OK;
}

/* probes RESULT.h5: the whole document, or nothing (an --out FILE is removed) when the file cannot be
 * read. The case comes from the file itself, so its probe order is the run's. */
static int cmd_probes(const char *path, long long job, long long attempt, const char *out)
{
	struct poro_error err = {0};
	struct results *res = NULL;
	struct case_spec *c = NULL;
	enum poro_status st = results_check_file(path, &err);
	if (!st)
		st = results_open(&res, path, &err);
	if (!st)
		st = case_load_string(results_case_json(res), &c, &err);
	FILE *f = NULL;
	if (!st && !(f = out ? create_output(out) : stdout)) {
		results_close(&res);
		case_destroy(&c);
		return poro_status_exit_code(PORO_EIO);
	}
	if (!st) {
		fprintf(f, "{\"job\": %lld, \"attempt\": %lld, ", job, attempt);
		st = write_probes(f, res, c, &err);
		fputs("}\n", f);
		if (!st && (fflush(f) != 0 || ferror(f)))
			st = poro_error_set(&err, PORO_EIO, "cannot write '%s': %s", out ? out : "stdout", strerror(errno));
	}
	if (out && f && fclose(f) != 0 && !st)
		st = poro_error_set(&err, PORO_EIO, "cannot write '%s': %s", out, strerror(errno));
	if (st && out && f)
		remove(out);
	results_close(&res);
	case_destroy(&c);
	return st ? fail(st, &err, path) : 0;
}

/* An integer option value in [0, 10^18]; -1 after saying why not. */
static int parse_count(const char *key, const char *text, long long *value)
{
	char *end;
	errno = 0;
	*value = strtoll(text, &end, 10);
	if (errno || end == text || *end || *value < 0 || *value > 1000000000000000000LL) {
		fprintf(stderr, "poro-solve: %s: '%s' is not a whole number >= 0\n", key, text);
		return -1;
	}
	return 0;
}

/* probes RESULT.h5 --job ID --attempt N [--out FILE], options in any order. */
static int parse_probes(int argc, char **argv)
{
	long long job = -1, attempt = -1;
	const char *out = NULL;
	for (int i = 3; i < argc; i += 2) {
		const char *key = argv[i], *value = i + 1 < argc ? argv[i + 1] : NULL;
		if (!value || (strcmp(key, "--job") && strcmp(key, "--attempt") && strcmp(key, "--out")))
			return usage();
		if (!strcmp(key, "--out"))
			out = value;
		else if (parse_count(key, value, !strcmp(key, "--job") ? &job : &attempt))
			return 2;
	}
	return job < 0 || attempt < 0 ? usage() : cmd_probes(argv[2], job, attempt, out);
}

int main(int argc, char **argv)
{
	if (argc >= 2 && !strcmp(argv[1], "version")) {
		printf("poro-solve %s\n", PORO_VERSION);
		return 0;
	}
	if (argc == 3 && !strcmp(argv[1], "validate"))
		return cmd_validate(argv[2]);
	if (argc >= 3 && !strcmp(argv[1], "run"))
		return parse_run(argc, argv);
	if (argc >= 3 && !strcmp(argv[1], "report"))
		return parse_report(argc, argv);
	if (argc >= 3 && !strcmp(argv[1], "probes"))
		return parse_probes(argc, argv);
	if (argc == 5 && !strcmp(argv[1], "element") && !strcmp(argv[3], "--out"))
		return cmd_element(argv[2], argv[4]);
	return usage();
}
