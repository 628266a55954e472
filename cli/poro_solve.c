/*
 * poro_solve.c - the poro-solve command: the solver library behind a command line.
 *
 *   poro-solve run CASE.json --out DIR [--resume CHECKPOINT] [--checkpoint-wall SECONDS]
 *                                        run a case, write DIR/result.h5 and DIR/result.xdmf, and at
 *                                        the end DIR/metrics.json (metrics.h: the run's figures, also
 *                                        in result.h5's /metrics); an element case runs as `element`,
 *                                        with a result.h5 that holds its figures
 *   poro-solve validate CASE.json        check a case (a simulation case, or an element case by its
 *                                        "schema"); every problem as "JSON-pointer: message"
 *   poro-solve element CASE.json --out DIR
 *                                        single-element triaxial test (element.h, docs/element.md):
 *                                        DIR/element.csv (poro-plot draws it), DIR/metrics.json
 *   poro-solve report RESULT.h5 [--out FILE] [--ground Y] [--crest X] [--tolerance M]
 *                     [--line X0,Y0,X1,Y1[,...][,N] --line-out FILE [--at TIME]]
 *                                        derived quantities of a run (report.h, docs/report.md): a
 *                                        CSV row per frame (toe, run-out, crest settlement, soil-water
 *                                        gap, oscillation index, pressure pattern index) to stdout
 *                                        or FILE, and the pore pressure along a line at the frame
 *                                        nearest TIME (default the last) to the --line-out FILE
 *   poro-solve probes RESULT.h5 --job ID --attempt N [--out FILE]
 *                                        the probe series of a run as the JSON document the job
 *                                        service serves (docs/service.md §3, GET .../probes):
 *                                        {"job", "attempt", "probes": {name: {"unit", "time",
 *                                        "value"}}}, names in the order of the case, to stdout or FILE
 *   poro-solve frames RESULT.h5 --out DIR [--job ID --attempt N]
 *                                        every frame in the dashboard's compact form: DIR/frames.bin
 *                                        and its index DIR/frames.json (frames_export.h); probes
 *                                        --frames DIR writes the same beside the probes
 *   poro-solve version | --version | --help;  poro-solve COMMAND --help
 *
 * Options are parsed by getopt_long, with GNU habits: "--out DIR" and "--out=DIR", options before
 * or after the file, "--" ends them. Without arguments the usage goes to stderr (exit 2); the
 * worker reads it to learn whether this solver knows --checkpoint-wall.
 *
 * run writes DIR/checkpoint.h5 every checkpoint.interval of simulated time (case key) and every
 * --checkpoint-wall seconds of wall time, whichever comes first, and prints
 * "checkpoint step=N time=T" after each; --resume continues from such a checkpoint, keeping the
 * frames of DIR/result.h5 up to it (checkpoint.h, docs/service.md §2). A checkpoint of another
 * case is refused with exit 2, naming the first difference. SIGUSR1 writes a checkpoint of the
 * current step and stops (exit 6), SIGTERM and SIGINT stop without one.
 *
 * probes runs in its own process because a result file is untrusted input for whoever reads it: the
 * worker runs it on each result.h5 it uploads, so a damaged file can crash only this process, never
 * the server (which no longer links HDF5). Numbers are written with 17 significant digits, so they
 * read back to the same doubles; a value that is not finite is written as null (JSON has no NaN).
 *
 * The test knob PORO_DEBUG_SLOWDOWN=F (F in (1, 100]) makes each step of `run` cost about F times
 * as much, results unchanged (sim_set_slowdown; docs/benchmarks.md, "Test knobs"): the benchmark
 * tests' stand-in for a slower solver.
 *
 * Exit codes come from the status table in error.h: 0 success, 2 invalid input, 3 solver failure
 * (NaN, a point leaving the grid, a failed factorisation), 4 I/O, 5 out of memory, 6 interrupted.
 * Progress goes to stdout, one line per report; errors to stderr, prefixed "poro-solve: ".
 */
#define _GNU_SOURCE
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "case.h"
#include "checkpoint.h"
#include "element.h"
#include "frames_export.h"
#include "json_text.h"
#include "metrics.h"
#include "output.h"
#include "poro.h"
#include "report.h"
#include "results_read.h"
#include "subcommand.h"

#ifndef PORO_VERSION
#define PORO_VERSION "unknown"
#endif

static volatile int stop_requested;

/* SIGTERM, SIGINT: stop. SIGUSR1: write a checkpoint of the current step, then stop (a worker
 * handing its job back before its allocation ends). */
static void on_signal(int sig)
{
	stop_requested = sig == SIGUSR1 ? SIM_STOP_CHECKPOINT : 1;
}

#define PROGRAM "poro-solve"
/* The iterations of the last step whose energy the progress line prints, at most. */
#define PROGRESS_ENERGIES 8

static int parse_run(const struct subcommand *self, int argc, char **argv);
static int parse_validate(const struct subcommand *self, int argc, char **argv);
static int parse_element(const struct subcommand *self, int argc, char **argv);
static int parse_report(const struct subcommand *self, int argc, char **argv);
static int parse_probes(const struct subcommand *self, int argc, char **argv);
static int parse_frames(const struct subcommand *self, int argc, char **argv);
static int parse_version(const struct subcommand *self, int argc, char **argv);

static const struct subcommand COMMANDS[] = {
	{ "run", "run CASE.json --out DIR [--resume CHECKPOINT] [--checkpoint-wall SECONDS]",
	  "Runs a case; writes DIR/result.h5 and DIR/result.xdmf, and DIR/checkpoint.h5 every\n"
	  "checkpoint.interval of simulated time and every --checkpoint-wall seconds of wall time; at the\n"
	  "end DIR/metrics.json, the run's figures (also in result.h5's /metrics). An element case\n"
	  "(\"schema\": \"poro-element/1\") runs as `element` does, with a result.h5 of its figures.\n"
	  "  -o, --out DIR                 the output directory (required)\n"
	  "      --resume CHECKPOINT       continue from a checkpoint of the same case, keeping the\n"
	  "                                frames of DIR/result.h5 up to it\n"
	  "      --checkpoint-wall SECONDS also write a checkpoint every SECONDS of wall time (> 0)\n",
	  parse_run },
	{ "validate", "validate CASE.json",
	  "Checks a case (a simulation case, or an element case by its \"schema\"): every problem as\n"
	  "'JSON-pointer: message' on stderr, exit 2 when there is one.\n",
	  parse_validate },
	{ "element", "element CASE.json --out DIR",
	  "A single-element triaxial test (docs/element.md): DIR/element.csv, which poro-plot draws,\n"
	  "and DIR/metrics.json, its figures.\n"
	  "  -o, --out DIR                 the output directory (required)\n",
	  parse_element },
	{ "report", "report RESULT.h5 [--out FILE] [--ground Y] [--crest X] [--tolerance M]\n"
		    "                         [--line X0,Y0,X1,Y1[,...][,N] --line-out FILE [--at TIME]]",
	  "Derived quantities of a run (docs/report.md): a CSV row per frame (toe, run-out, crest\n"
	  "settlement, soil-water gap, oscillation index, pressure pattern index) to stdout or FILE, and\n"
	  "the pore pressure along a line at the frame nearest TIME (default the last) to the --line-out\n"
	  "FILE.\n"
	  "  -o, --out FILE                the per-frame table (default stdout)\n"
	  "      --ground Y, --crest X, --tolerance M   the report's settings, m\n"
	  "      --line X0,Y0,X1,Y1[,...][,N]           a polyline and its number of samples\n"
	  "      --line-out FILE           the table of the line (needed with --line)\n"
	  "      --at TIME                 the time of the line's frame, s\n",
	  parse_report },
	{ "probes", "probes RESULT.h5 --job ID --attempt N [--out FILE] [--frames DIR]",
	  "The probe series of a run as the JSON document the job service serves (docs/service.md §3):\n"
	  "{\"job\", \"attempt\", \"probes\": {name: {\"unit\", \"time\", \"value\"}}}, to stdout or FILE.\n"
	  "      --job ID, --attempt N     the job and attempt the document names (whole numbers >= 0)\n"
	  "  -o, --out FILE                where to write it (nothing is left there on failure)\n"
	  "      --frames DIR              also write DIR/frames.bin and DIR/frames.json (as 'frames')\n",
	  parse_probes },
	{ "frames", "frames RESULT.h5 --out DIR [--job ID --attempt N]",
	  "Every frame of a run in the dashboard's compact form (docs/web.md, \"Frames\"): DIR/frames.bin,\n"
	  "the points' positions and fields as 32-bit floats, and its index DIR/frames.json.\n"
	  "  -o, --out DIR                 the directory to write them in (required)\n"
	  "      --job ID, --attempt N     the job and attempt the index names (default 0)\n",
	  parse_frames },
	{ "version", "version", "Prints \"poro-solve VERSION\" (git describe of the build).\n", parse_version },
};
static const int COMMAND_COUNT = (int)(sizeof COMMANDS / sizeof COMMANDS[0]);

static int help(void)
{
	printf("poro-solve: the PoroMPM solver from the command line\n\n");
	subcommand_list(stdout, PROGRAM, COMMANDS, COMMAND_COUNT);
	printf("\nExit status:\n");
#define PORO_STATUS_HELP(code, exit_code, meaning) printf("  %d  %s\n", exit_code, meaning);
	PORO_STATUS_MAP(PORO_STATUS_HELP)
#undef PORO_STATUS_HELP
	printf("  (a bad command line is invalid input: 2)\n");
	return 0;
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
	printf("step %ld/%ld  t = %.6g s  wall = %.2f s  %.3f us per material-point step", p->step,
	       p->steps_total, p->time, p->wall_seconds, p->us_per_point_step);
	if (p->iterations_mean > 0.0)   /* after the figures the worker reads (worker/log_pump.c) */
		printf("  Newton iterations %d (mean %.2f)", p->iterations_last, p->iterations_mean);
	/* the last step's convergence, each iteration's energy against the first's: linear (modified
	 * Newton) or quadratic (the consistent tangent) at a glance */
	if (p->energies && p->energy_count > 1 && p->energies[0] > 0.0) {
		printf("  |delta . r| / first:");
		for (int k = 1; k < p->energy_count && k <= PROGRESS_ENERGIES; k++)
			printf(" %.1e", p->energies[k] / p->energies[0]);
		if (p->energy_count > PROGRESS_ENERGIES + 1)
			printf(" ...");
	}
	printf("\n");
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

/* Processor time of this process, s (every thread). */
static double cpu_seconds(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double wall_seconds(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Writes DIR/metrics.json and result.h5's /metrics (metrics.h); 0, or the exit status of an I/O
 * failure after saying so. */
static int write_metrics(const struct metrics *m, const char *out_dir)
{
	struct poro_error err = {0};
	enum poro_status st = metrics_write(m, out_dir, &err);
	return st ? fail(st, &err, out_dir) : 0;
}

/* The whole text of a file, or NULL (errno set). The caller frees it. */
static char *read_text(const char *path)
{
	FILE *f = fopen(path, "rb");
	char *text = NULL, buf[8192];
	size_t n = 0, cap = 0, got;
	while (f && (got = fread(buf, 1, sizeof buf, f)) > 0) {
		if (n + got + 1 > cap) {
			char *grown = realloc(text, cap = 2 * (n + got + 1));
			if (!grown)
				break;
			text = grown;
		}
		memcpy(text + n, buf, got);
		n += got;
		text[n] = '\0';
	}
	if (f)
		fclose(f);
	return text;
}

/* An element run's result.h5: the case, /run (status, steps, wall time) and no frames, so that the
 * job service, which requires a result.h5 of every successful job, takes element tests too (the
 * figures go into its /metrics next). */
static enum poro_status element_result_file(const char *path, const char *out_dir, int ok, long steps,
					    double wall, struct poro_error *err)
{
	char *json = read_text(path);
	if (!json)
		return poro_error_set(err, PORO_EIO, "cannot read '%s': %s", path, strerror(errno));
	const char *none[1] = { NULL };
	struct output *o = NULL;
	enum poro_status st = output_create(&o, out_dir, json, PORO_VERSION, 0, none, none, err);
	if (!st)
		st = output_finish(o, ok ? "succeeded" : "failed", steps, 1, wall, err);
	output_destroy(&o);
	free(json);
	return st;
}

/* element CASE.json --out DIR: an element case (its own schema, "poro-element/1") through the
 * single-element driver: DIR/element.csv and DIR/metrics.json, and with result_file (what `run`
 * does with an element case) DIR/result.h5, which holds the figures too. */
static int cmd_element(const char *path, const char *out_dir, int result_file)
{
	struct element_case c;
	struct element_result r = {0};
	struct poro_error err = {0}, io = {0};
	enum poro_status st = element_case_load_file(path, &c, &err);
	if (st)
		return fail(st, &err, path);
	print_warnings(path, c.warnings);
	if (mkdir(out_dir, 0777) && errno != EEXIST) {
		poro_error_set(&io, PORO_EIO, "cannot create output directory '%s': %s", out_dir, strerror(errno));
		return fail(PORO_EIO, &io, path);
	}
	double w0 = wall_seconds(), c0 = cpu_seconds();
	st = element_run(&c, &r, &err);
	double wall = wall_seconds() - w0, cpu = cpu_seconds() - c0;
	struct metrics m;
	metrics_init(&m, "element", c.title, PORO_VERSION);
	metrics_of_element(&m, &c, &r, wall, cpu, st ? err.message : NULL);
	enum poro_status ran = st;
	if (!st)
		st = element_write(&c, &r, out_dir, &err);
	enum poro_status io_st = result_file ? element_result_file(path, out_dir, !ran, r.rows - 1, wall, &io) : PORO_OK;
	int code = io_st ? fail(io_st, &io, out_dir) : write_metrics(&m, out_dir);
	if (st) {
		element_result_release(&r);
		return fail(st, &err, path);
	}
	const struct element_row *last = &r.row[r.rows - 1];
	printf("%d steps: axial strain %.6g, p = %.6g Pa, q = %.6g Pa, volumetric strain %.6g\n", r.rows - 1,
	       last->axial_strain, last->p, last->q, last->volumetric_strain);
	if (!code)
		printf("done: %s/element.csv (pictures: poro-plot %s/element.csv), %s/%s\n", out_dir, out_dir, out_dir,
		       METRICS_FILE);
	element_result_release(&r);
	return code;
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

/* The test knob PORO_DEBUG_SLOWDOWN (sim_set_slowdown, docs/benchmarks.md "Test knobs"): unset, or a
 * factor in (1, 100]. 0 with *factor set (1 when unset), or -1 after saying why not. */
static int slowdown_knob(double *factor)
{
	const char *text = getenv("PORO_DEBUG_SLOWDOWN");
	*factor = 1;
	if (!text || !*text)
		return 0;
	if (parse_number(text, factor) || !(*factor > 1) || *factor > 100) {
		fprintf(stderr, "poro-solve: PORO_DEBUG_SLOWDOWN='%s' is not a factor in (1, 100]\n", text);
		return -1;
	}
	printf("test knob PORO_DEBUG_SLOWDOWN=%g: each step repeats its shape functions to cost about %gx "
	       "(results unchanged)\n", *factor, *factor);
	return 0;
}

/* run on a simulation case: result.h5, result.xdmf, checkpoints, and metrics.json when the run
 * ends (succeeded, or failed in a step; not when it is interrupted: a resumed run writes them). An
 * element case goes to the element driver, with a result.h5 (cmd_element). */
static int cmd_run(const char *path, const struct run_options *opt)
{
	const char *out_dir = opt->out_dir;
	struct case_spec *c = NULL;
	struct sim *s = NULL;
	struct poro_error err = {0};
	double slowdown;
	if (element_case_file_is_element(path)) {
		if (!opt->resume)
			return cmd_element(path, out_dir, 1);
		return fail(poro_error_set(&err, PORO_EINVAL, "an element test has no checkpoint to resume from"), &err,
			    opt->resume);
	}
	if (slowdown_knob(&slowdown))
		return poro_status_exit_code(PORO_EINVAL);
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
	sim_set_slowdown(s, slowdown);
	if (c->metrics & FIGURES_NEEDING_REFERENCE && (st = sim_time_reference(s))) {
		int code = fail(st, sim_error(s), path);
		sim_destroy(&s);
		case_destroy(&c);
		return code;
	}
	printf("case '%s': %ld soil points, %ld water points, %ld steps\n", c->title,
	       (long)sim_soil(s)->n, sim_is_double_point(s) ? (long)sim_water(s)->n : 0L, sim_steps_total(s));
	if (c->time.dt_auto)
		printf("dt \"auto\": %.6g s, the %s scheme's recommended step\n", c->time.dt,
		       c->formulation.scheme == SCHEME_EXPLICIT ? "explicit" : "semi-implicit");
	if (opt->resume)
		printf("resumed from '%s' at step %ld, t = %.6g s\n", opt->resume, sim_steps_taken(s), sim_time(s));
	signal(SIGTERM, on_signal);
	signal(SIGINT, on_signal);
	signal(SIGUSR1, on_signal);
	st = sim_run(s, out_dir, PORO_VERSION, print_progress, NULL, &stop_requested);
	if (!st && sim_warning(s))   /* a failure's message quotes it already (step_health.c) */
		printf("warning: %s\n", sim_warning(s));
	int code = 0;
	if (st == PORO_OK || st == PORO_ESOLVER) {
		struct metrics m;
		metrics_init(&m, "simulation", c->title, PORO_VERSION);
		metrics_of_run(&m, s, c, out_dir, st ? sim_error(s)->message : NULL);
		code = write_metrics(&m, out_dir);
	}
	if (st)
		code = fail(st, sim_error(s), path);
	else if (!code)
		printf("done: %s/result.h5, %s/%s\n", out_dir, out_dir, METRICS_FILE);
	sim_destroy(&s);
	case_destroy(&c);
	return code;
}

static int parse_run(const struct subcommand *self, int argc, char **argv)
{
	static const struct option opts[] = {
		{ "out", required_argument, NULL, 'o' },         { "resume", required_argument, NULL, 'r' },
		{ "checkpoint-wall", required_argument, NULL, 'w' }, { "help", no_argument, NULL, 'h' },
		{ NULL, 0, NULL, 0 }
	};
	struct run_options opt = {0};
	int c, rc;
	while ((c = getopt_long(argc, argv, "ho:", opts, NULL)) != -1) {
		switch (c) {
		case 'h': return subcommand_help(PROGRAM, self);
		case 'o': opt.out_dir = optarg; break;
		case 'r': opt.resume = optarg; break;
		case 'w':
			if (parse_number(optarg, &opt.checkpoint_wall) || !(opt.checkpoint_wall > 0) ||
			    opt.checkpoint_wall > 1e9) {
				fprintf(stderr, "poro-solve: --checkpoint-wall: '%s' is not a number of seconds > 0\n", optarg);
				return 2;
			}
			break;
		default: return subcommand_usage_error(PROGRAM, self, NULL);
		}
	}
	if ((rc = subcommand_positional(PROGRAM, self, argc, argv, 1, "CASE.json")))
		return rc;
	if (!opt.out_dir)
		return subcommand_usage_error(PROGRAM, self, "missing --out DIR");
	return cmd_run(argv[optind], &opt);
}

static int parse_validate(const struct subcommand *self, int argc, char **argv)
{
	static const struct option opts[] = { { "help", no_argument, NULL, 'h' }, { NULL, 0, NULL, 0 } };
	int c = getopt_long(argc, argv, "h", opts, NULL), rc;
	if (c != -1)
		return c == 'h' ? subcommand_help(PROGRAM, self) : subcommand_usage_error(PROGRAM, self, NULL);
	return (rc = subcommand_positional(PROGRAM, self, argc, argv, 1, "CASE.json")) ? rc : cmd_validate(argv[optind]);
}

static int parse_element(const struct subcommand *self, int argc, char **argv)
{
	static const struct option opts[] = {
		{ "out", required_argument, NULL, 'o' }, { "help", no_argument, NULL, 'h' }, { NULL, 0, NULL, 0 }
	};
	const char *out = NULL;
	int c, rc;
	while ((c = getopt_long(argc, argv, "ho:", opts, NULL)) != -1) {
		if (c == 'h')
			return subcommand_help(PROGRAM, self);
		if (c != 'o')
			return subcommand_usage_error(PROGRAM, self, NULL);
		out = optarg;
	}
	if ((rc = subcommand_positional(PROGRAM, self, argc, argv, 1, "CASE.json")))
		return rc;
	return out ? cmd_element(argv[optind], out, 0) : subcommand_usage_error(PROGRAM, self, "missing --out DIR");
}

static int parse_version(const struct subcommand *self, int argc, char **argv)
{
	static const struct option opts[] = { { "help", no_argument, NULL, 'h' }, { NULL, 0, NULL, 0 } };
	int c = getopt_long(argc, argv, "h", opts, NULL), rc;
	if (c != -1)
		return c == 'h' ? subcommand_help(PROGRAM, self) : subcommand_usage_error(PROGRAM, self, NULL);
	if ((rc = subcommand_positional(PROGRAM, self, argc, argv, 0, "")))
		return rc;
	printf("poro-solve %s\n", PORO_VERSION);
	return 0;
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

/* report RESULT.h5 [options] (struct report_options). */
static int parse_report(const struct subcommand *self, int argc, char **argv)
{
	static const struct option opts[] = {
		{ "out", required_argument, NULL, 'o' },   { "ground", required_argument, NULL, 'g' },
		{ "crest", required_argument, NULL, 'c' }, { "tolerance", required_argument, NULL, 't' },
		{ "at", required_argument, NULL, 'a' },    { "line", required_argument, NULL, 'l' },
		{ "line-out", required_argument, NULL, 'L' }, { "help", no_argument, NULL, 'h' },
		{ NULL, 0, NULL, 0 }
	};
	struct report_options opt = {.at = NAN, .settings = REPORT_SETTINGS_DEFAULT};
	int c, index = 0, rc;
	while ((c = getopt_long(argc, argv, "ho:", opts, &index)) != -1) {
		double *number = c == 'g' ? &opt.settings.ground : c == 'c' ? &opt.settings.crest :
				 c == 't' ? &opt.settings.tolerance : c == 'a' ? &opt.at : NULL;
		if (c == 'h')
			return subcommand_help(PROGRAM, self);
		else if (c == 'o')
			opt.out = optarg;
		else if (c == 'l')
			opt.line = optarg;
		else if (c == 'L')
			opt.line_out = optarg;
		else if (!number)
			return subcommand_usage_error(PROGRAM, self, NULL);
		else if (parse_number(optarg, number)) {
			fprintf(stderr, "poro-solve: --%s: '%s' is not a number\n", opts[index].name, optarg);
			return 2;
		}
	}
	if ((rc = subcommand_positional(PROGRAM, self, argc, argv, 1, "RESULT.h5")))
		return rc;
	if (opt.line && !opt.line_out)
		return subcommand_usage_error(PROGRAM, self, "no --line-out FILE for '--line'");
	if (!opt.line && (opt.line_out || !isnan(opt.at)))
		return subcommand_usage_error(PROGRAM, self, "no --line for '%s'", opt.line_out ? "--line-out" : "--at");
	return cmd_report(argv[optind], &opt);
}

/* ---- probes ---------------------------------------------------------------------------------- */

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
		json_text_string(f, c->probes[i].name, 0);   /* jansson read it: valid UTF-8 */
		fputs(": {\"unit\": ", f);
		json_text_string(f, units ? units : "", 1);   /* the file may be damaged */
		fputs(", \"time\": ", f);
		json_text_numbers(f, t, n);
		fputs(", \"value\": ", f);
		json_text_numbers(f, v, n);
		fputc('}', f);
		free(t), free(v), free(units);
	}
	fputs("}", f);
	return PORO_OK;
}

/* probes RESULT.h5: the whole document, or nothing (an --out FILE is removed) when the file cannot be
 * read. The case comes from the file itself, so its probe order is the run's. FILE is written as
 * FILE.tmp and renamed, so it is whole whenever it exists: a worker that had to kill this process
 * while it wrote the frames after it still has complete probes. */
static int cmd_probes(const char *path, long long job, long long attempt, const char *out, const char *frames)
{
	struct poro_error err = {0};
	struct results *res = NULL;
	struct case_spec *c = NULL;
	enum poro_status st = results_check_file(path, &err);
	if (!st)
		st = results_open(&res, path, &err);
	struct element_case element;
	struct poro_error ignored = {0};
	/* an element test's result.h5 (run on an element case) has no probes: an empty set */
	int is_element = !st && element_case_load_string(results_case_json(res), &element, &ignored) == PORO_OK;
	if (!st && !is_element)
		st = case_load_string(results_case_json(res), &c, &err);
	FILE *f = NULL;
	char tmp[4200] = "";
	if (out)
		snprintf(tmp, sizeof tmp, "%s.tmp", out);
	if (!st && !(f = out ? create_output(tmp) : stdout)) {
		results_close(&res);
		case_destroy(&c);
		return poro_status_exit_code(PORO_EIO);
	}
	if (!st) {
		fprintf(f, "{\"job\": %lld, \"attempt\": %lld, ", job, attempt);
		if (is_element)
			fputs("\"probes\": {}", f);
		else
			st = write_probes(f, res, c, &err);
		fputs("}\n", f);
		if (!st && (fflush(f) != 0 || ferror(f)))
			st = poro_error_set(&err, PORO_EIO, "cannot write '%s': %s", out ? out : "stdout", strerror(errno));
	}
	if (out && f && fclose(f) != 0 && !st)
		st = poro_error_set(&err, PORO_EIO, "cannot write '%s': %s", tmp, strerror(errno));
	if (!st && out && f && rename(tmp, out) != 0)
		st = poro_error_set(&err, PORO_EIO, "cannot rename '%s' to '%s': %s", tmp, out, strerror(errno));
	if (st && out && f)
		remove(tmp);
	results_close(&res);
	case_destroy(&c);
	if (st)
		return fail(st, &err, path);
	/* the frames are the dashboard's and do not hold up the probes: a failure is said, and the
	 * probes stand (frames_export leaves no frames file behind) */
	if (frames && (st = frames_export(path, frames, job, attempt, &err)))
		fprintf(stderr, "poro-solve: no frames written in '%s': %s\n", frames, err.message);
	return 0;
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

/* The options of probes and frames: --job, --attempt, --out and (probes) --frames; 0, -1 after
 * printing the help (exit 0), or an exit status after saying why. */
struct extract_options {
	long long job, attempt;
	const char *out, *frames;
};

static int parse_extract(const struct subcommand *self, int argc, char **argv, int with_frames,
			 struct extract_options *o)
{
	static const struct option opts[] = {
		{ "job", required_argument, NULL, 'j' }, { "attempt", required_argument, NULL, 'a' },
		{ "out", required_argument, NULL, 'o' }, { "frames", required_argument, NULL, 'f' },
		{ "help", no_argument, NULL, 'h' }, { NULL, 0, NULL, 0 }
	};
	int c;
	while ((c = getopt_long(argc, argv, "ho:", opts, NULL)) != -1) {
		if (c == 'h')
			return subcommand_help(PROGRAM, self) == 0 ? -1 : 2;
		else if (c == 'o')
			o->out = optarg;
		else if (c == 'f' && with_frames)
			o->frames = optarg;
		else if (c == 'j' || c == 'a') {
			if (parse_count(c == 'j' ? "--job" : "--attempt", optarg, c == 'j' ? &o->job : &o->attempt))
				return 2;
		} else
			return subcommand_usage_error(PROGRAM, self, NULL);
	}
	return subcommand_positional(PROGRAM, self, argc, argv, 1, "RESULT.h5");
}

/* probes RESULT.h5 --job ID --attempt N [--out FILE] [--frames DIR]. */
static int parse_probes(const struct subcommand *self, int argc, char **argv)
{
	struct extract_options o = { -1, -1, NULL, NULL };
	int rc = parse_extract(self, argc, argv, 1, &o);
	if (rc)
		return rc < 0 ? 0 : rc;
	if (o.job < 0 || o.attempt < 0)
		return subcommand_usage_error(PROGRAM, self, "missing %s", o.job < 0 ? "--job ID" : "--attempt N");
	return cmd_probes(argv[optind], o.job, o.attempt, o.out, o.frames);
}

/* frames RESULT.h5 --out DIR [--job ID --attempt N]. */
static int parse_frames(const struct subcommand *self, int argc, char **argv)
{
	struct extract_options o = { 0, 0, NULL, NULL };
	int rc = parse_extract(self, argc, argv, 0, &o);
	if (rc)
		return rc < 0 ? 0 : rc;
	if (!o.out)
		return subcommand_usage_error(PROGRAM, self, "missing --out DIR");
	struct poro_error err = { 0 };
	enum poro_status st = frames_export(argv[optind], o.out, o.job, o.attempt, &err);
	return st ? fail(st, &err, argv[optind]) : 0;
}

int main(int argc, char **argv)
{
	return subcommand_main(PROGRAM, PORO_VERSION, COMMANDS, COMMAND_COUNT, help, argc, argv);
}
