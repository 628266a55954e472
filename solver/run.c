/*
 * run.c - sim_run: the time loop with result files and progress (what poro-solve run does).
 *
 * Frames are written at t = 0, whenever the time passes a multiple of frame_interval, and at the
 * end (also at a failure, so the state that failed can be inspected). Probes are sampled every
 * step, thinned to at most about PROBE_SAMPLES_TARGET samples per run.
 */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "output.h"
#include "sim_internal.h"

#define PROBE_SAMPLES_TARGET 20000

static double wall_now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static enum poro_status write_frame(struct sim *s, struct output *o)
{
	struct output_frame fr = {.time = s->time, .step = s->step, .soil = &s->soil,
				  .water = s->double_point ? &s->water : NULL};
	if (!s->double_point)    /* single point: the soil points carry the pore pressure */
		memcpy(s->soil.pressure, s->water.pressure, sizeof(double) * (size_t)s->soil.n);
	return output_frame_write(o, &fr, &s->err);
}

static enum poro_status sample_probes(struct sim *s, struct output *o, double *values)
{
	for (int i = 0; i < s->spec->probe_count; i++)
		values[i] = sim_probe_value(s, i);
	return output_probe_sample(o, s->time, values, &s->err);
}

static void report(struct sim *s, sim_progress_fn progress, void *user, double t0)
{
	if (!progress)
		return;
	double wall = wall_now() - t0;
	long points = (long)s->soil.n + (s->double_point ? (long)s->water.n : 0);
	struct sim_progress pr = {
		.step = s->step, .steps_total = s->steps_total, .time = s->time,
		.end_time = s->spec->time.end, .wall_seconds = wall,
		.us_per_point_step = s->step > 0 ? 1e6 * wall / ((double)s->step * points) : 0.0,
	};
	progress(&pr, user);
}

static enum poro_status open_output(struct sim *s, const char *dir, const char *version, struct output **o)
{
	if (mkdir(dir, 0777) && errno != EEXIST)
		return poro_error_set(&s->err, PORO_EIO, "cannot create output directory '%s': %s", dir, strerror(errno));
	int n = s->spec->probe_count;
	const char **names = calloc((size_t)n + 1, sizeof *names), **units = calloc((size_t)n + 1, sizeof *units);
	if (!names || !units) {
		free(names);
		free(units);
		return poro_error_set(&s->err, PORO_ENOMEM, "cannot allocate probe names");
	}
	for (int i = 0; i < n; i++) {
		const struct case_probe *p = &s->spec->probes[i];
		names[i] = p->name;
		int pa = p->kind == PROBE_PORE_PRESSURE ||
			 (p->kind == PROBE_AVERAGE && p->field != FIELD_DISPLACEMENT_X && p->field != FIELD_DISPLACEMENT_Y);
		units[i] = pa ? "Pa" : "m";
	}
	enum poro_status st = output_create(o, dir, s->spec->json, version, n, names, units, &s->err);
	free(names);
	free(units);
	return st;
}

enum poro_status sim_run(struct sim *s, const char *out_dir, const char *solver_version,
			 sim_progress_fn progress, void *user, volatile int *stop)
{
	struct output *o = NULL;
	const double t0 = wall_now();
	double *values = calloc((size_t)s->spec->probe_count + 1, sizeof(double));
	if (!values)
		return poro_error_set(&s->err, PORO_ENOMEM, "cannot allocate probe values");
	enum poro_status st = open_output(s, out_dir, solver_version, &o);
	const double interval = s->spec->output.frame_interval;
	const long thin = s->steps_total / PROBE_SAMPLES_TARGET + 1;
	double last_report = t0;
	long next_frame = 1;
	if (!st)
		st = write_frame(s, o);
	if (!st)
		st = sample_probes(s, o, values);
	while (!st && !sim_done(s)) {
		if (stop && *stop) {
			st = poro_error_set(&s->err, PORO_EINTERRUPTED, "interrupted at step %ld (t = %.6g s)",
					    s->step, s->time);
			break;
		}
		st = sim_step(s);
		if (st)
			break;
		if (s->step % thin == 0 || sim_done(s))
			st = sample_probes(s, o, values);
		if (!st && interval > 0 && s->time >= next_frame * interval * (1 - 1e-9) && !sim_done(s)) {
			st = write_frame(s, o);
			next_frame = (long)floor(s->time / interval * (1 + 1e-9)) + 1;
		}
		if (wall_now() - last_report >= s->spec->output.progress_interval) {
			report(s, progress, user, t0);
			last_report = wall_now();
		}
	}
	enum poro_status final = st;
	if (o) {
		struct poro_error ignored = {0};
		if (st != PORO_EIO)
			write_frame(s, o);   /* the last state, succeeded or failed */
		enum poro_status fin = output_finish(o, final ? "failed" : "succeeded", s->step,
						     (long)s->soil.n + (s->double_point ? (long)s->water.n : 0),
						     wall_now() - t0, final ? &ignored : &s->err);
		if (!final && fin)
			final = fin;
		output_destroy(&o);
	}
	report(s, progress, user, t0);
	free(values);
	return final;
}
