/*
 * poro_solve.c - the poro-solve command: the solver library behind a command line.
 *
 *   poro-solve run CASE.json --out DIR   run a case, write DIR/result.h5 and DIR/result.xdmf
 *   poro-solve validate CASE.json        check a case; every problem as "JSON-pointer: message"
 *   poro-solve version
 *
 * Exit codes come from the status table in error.h: 0 success, 2 invalid input, 3 solver failure
 * (NaN, a point leaving the grid, a failed factorisation), 4 I/O, 5 out of memory, 6 interrupted.
 * Progress goes to stdout, one line per report; errors to stderr, prefixed "poro-solve: ".
 */
#include <signal.h>
#include <stdio.h>
#include <string.h>

#include "case.h"
#include "poro.h"

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
	fprintf(stderr, "usage: poro-solve run CASE.json --out DIR\n"
			"       poro-solve validate CASE.json\n"
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
	printf("step %ld/%ld  t = %.6g s  wall = %.2f s  %.3f us per material-point step\n", p->step,
	       p->steps_total, p->time, p->wall_seconds, p->us_per_point_step);
	fflush(stdout);
}

static int cmd_validate(const char *path)
{
	struct case_spec *c = NULL;
	struct poro_error err = {0};
	enum poro_status st = case_load_file(path, &c, &err);
	if (st)
		return fail(st, &err, path);
	printf("%s: valid\n", path);
	case_destroy(&c);
	return 0;
}

static int cmd_run(const char *path, const char *out_dir)
{
	struct case_spec *c = NULL;
	struct sim *s = NULL;
	struct poro_error err = {0};
	enum poro_status st = case_load_file(path, &c, &err);
	if (st)
		return fail(st, &err, path);
	st = sim_create(&s, c, &err);
	if (st) {
		case_destroy(&c);
		return fail(st, &err, path);
	}
	printf("case '%s': %ld soil points, %ld water points, %ld steps\n", c->title,
	       (long)sim_soil(s)->n, sim_is_double_point(s) ? (long)sim_water(s)->n : 0L, sim_steps_total(s));
	signal(SIGTERM, on_signal);
	signal(SIGINT, on_signal);
	st = sim_run(s, out_dir, PORO_VERSION, print_progress, NULL, &stop_requested);
	int code = 0;
	if (st)
		code = fail(st, sim_error(s), path);
	else
		printf("done: %s/result.h5\n", out_dir);
	sim_destroy(&s);
	case_destroy(&c);
	return code;
}

int main(int argc, char **argv)
{
	if (argc >= 2 && !strcmp(argv[1], "version")) {
		printf("poro-solve %s\n", PORO_VERSION);
		return 0;
	}
	if (argc == 3 && !strcmp(argv[1], "validate"))
		return cmd_validate(argv[2]);
	if (argc == 5 && !strcmp(argv[1], "run") && !strcmp(argv[3], "--out"))
		return cmd_run(argv[2], argv[4]);
	return usage();
}
