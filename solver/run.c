/*
 * run.c - sim_run: the time loop with result files and progress (what poro-solve run does).
 *
 * Frames are written at t = 0, whenever the time passes a multiple of frame_interval, and at the
 * end (also at a failure, so the state that failed can be inspected). Probes are sampled every
 * step, thinned to at most about PROBE_SAMPLES_TARGET samples per run.
 *
 * Checkpoints (checkpoint.h) are written after the frame of a step, whenever the time passes a
 * multiple of the case's checkpoint.interval or checkpoint_wall seconds of wall time have gone by
 * since the last one, whichever comes first (never at the end: the run is then complete).
 * result.h5 is flushed first, so a copy of it taken after the checkpoint holds every frame and
 * probe sample up to the checkpoint time.
 *
 * A run resumed from a checkpoint keeps the same schedules: frames, probe samples (the thinning
 * depends on the step number only) and checkpoints fall on the same steps as in an uninterrupted
 * run. If DIR/result.h5 exists, its frames and samples up to the checkpoint time are kept and the
 * run appends to it; otherwise a new result.h5 begins with a frame and a probe sample at the
 * checkpoint time.
 *
 * The steps' own cost is measured around each sim_step (sim_get_timing): wall time and the
 * process's processor time, without the frames, probes and checkpoints between steps, which
 * depend on the disk more than on the solver. The slowdown knob (sim_set_slowdown) is counted
 * with its step: it stands for a slower step.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "checkpoint.h"
#include "output.h"
#include "phases.h"
#include "reference_kernel.h"
#include "sim_internal.h"

#define PROBE_SAMPLES_TARGET 20000

static double wall_now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* Processor time of the process (every thread), s. */
static double cpu_now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
	return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

void sim_set_slowdown(struct sim *s, double factor) { s->slowdown = factor > 1 ? factor : 1; }

void sim_get_timing(const struct sim *s, struct sim_timing *t)
{
	*t = s->timing;
	t->points = (long)s->soil.n + (s->double_point ? (long)s->water.n : 0);
	t->median_step_cpu = step_histogram_median(&s->step_cpu);
	t->median_reference_cpu = step_histogram_median(&s->reference_cpu);
}

enum poro_status sim_time_reference(struct sim *s)
{
	if (s->reference)
		return PORO_OK;
	s->reference = reference_kernel_create();
	if (!s->reference || step_histogram_init(&s->reference_cpu)) {
		reference_kernel_destroy(s->reference);
		s->reference = NULL;
		return poro_error_set(&s->err, PORO_ENOMEM, "cannot allocate the reference kernel");
	}
	return PORO_OK;
}

/* The slowdown knob: step 1 (the shape functions at the present positions, which the step about
 * to be taken computes again from the same positions) repeated for (slowdown - 1) times the
 * processor time of the previous step. */
static enum poro_status slow_down(struct sim *s, double previous_step_cpu)
{
	double t0 = cpu_now(), want = (s->slowdown - 1) * previous_step_cpu;
	while (cpu_now() - t0 < want)
		TRY(point_map_shapes(s));
	return PORO_OK;
}

/* One step, timed (sim_get_timing), after the slowdown knob's repeats; then, when asked, the
 * reference kernel, timed on its own: the two alternate every step, so both see the same state of
 * the machine. */
static enum poro_status timed_step(struct sim *s, double *last_cpu)
{
	double c0 = cpu_now(), w0 = wall_now();
	enum poro_status st = s->slowdown > 1 && *last_cpu > 0 ? slow_down(s, *last_cpu) : PORO_OK;
	double c1 = cpu_now();
	if (!st)
		st = sim_step(s);
	double c2 = cpu_now();
	*last_cpu = c2 - c1;
	if (!st)
		step_histogram_add(&s->step_cpu, c2 - c0);
	s->timing.cpu_seconds += c2 - c0;
	s->timing.wall_seconds += wall_now() - w0;
	s->timing.steps += !st;
	if (!st && s->reference)
		step_histogram_add(&s->reference_cpu, reference_kernel_run(s->reference));
	return st;
}

static enum poro_status write_frame(struct sim *s, struct output *o)
{
	struct output_frame fr = {.time = s->time, .step = s->step, .soil = &s->soil,
				  .water = s->double_point ? &s->water : NULL};
	/* single point: the soil points carry the pore pressure; those of dry bodies, the last ones
	 * (sim.c), carry no water and keep 0 */
	if (!s->double_point)
		memcpy(s->soil.pressure, s->water.pressure, sizeof(double) * (size_t)s->water.n);
	return output_frame_write(o, &fr, &s->err);
}

static enum poro_status sample_probes(struct sim *s, struct output *o, double *values)
{
	for (int i = 0; i < s->spec->probe_count; i++)
		values[i] = sim_probe_value(s, i);
	return output_probe_sample(o, s->time, values, &s->err);
}

/* step0: the step the run started from (non-zero after a resume), so the speed counts only the
 * steps this process took. */
static void report(struct sim *s, sim_progress_fn progress, void *user, double t0, long step0, int checkpoint)
{
	if (!progress)
		return;
	double wall = wall_now() - t0;
	long points = (long)s->soil.n + (s->double_point ? (long)s->water.n : 0);
	long steps = s->step - step0;
	struct sim_progress pr = {
		.step = s->step, .steps_total = s->steps_total, .time = s->time,
		.end_time = s->spec->time.end, .wall_seconds = wall,
		.us_per_point_step = steps > 0 ? 1e6 * wall / ((double)steps * points) : 0.0,
		.checkpoint = checkpoint,
	};
	long total;
	int count;
	if (sim_iterations(s, &pr.iterations_last, &total, &pr.energies, &count)) {
		pr.iterations_mean = steps > 0 ? (double)total / (double)s->step : 0.0;
		pr.energy_count = count;
	}
	progress(&pr, user);
}

/* Creates DIR/result.h5, or after a resume continues it when it exists (*appended = 1). */
static enum poro_status open_output(struct sim *s, const char *dir, const char *version, struct output **o,
				    int *appended)
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
	char path[1024];
	struct stat sb;
	snprintf(path, sizeof path, "%s/result.h5", dir);
	*appended = s->resumed && stat(path, &sb) == 0;
	/* every frame or sample of a later step is at least dt later than the checkpoint */
	enum poro_status st = *appended ?
		output_reopen(o, dir, s->spec->json, version, n, names, units, s->time + 0.5 * s->dt, &s->err) :
		output_create(o, dir, s->spec->json, version, n, names, units, &s->err);
	free(names);
	free(units);
	return st;
}

void sim_set_checkpoint_wall(struct sim *s, double seconds) { s->checkpoint_wall = seconds > 0 ? seconds : 0; }

/* Number of the first multiple of interval after time (1 at t = 0), with the same tolerance the
 * due tests use, so a resumed run schedules what the uninterrupted run would. */
static long next_multiple(double time, double interval)
{
	return interval > 0 ? (long)floor(time / interval * (1 + 1e-9)) + 1 : 1;
}

/* Flushes result.h5, writes the checkpoint and announces it. */
static enum poro_status checkpoint(struct sim *s, struct output *o, const char *dir, sim_progress_fn progress,
				   void *user, double t0, long step0)
{
	enum poro_status st = output_flush(o, &s->err);
	if (!st)
		st = checkpoint_write(s, dir);
	if (!st)
		report(s, progress, user, t0, step0, 1);
	return st;
}

enum poro_status sim_run(struct sim *s, const char *out_dir, const char *solver_version,
			 sim_progress_fn progress, void *user, volatile int *stop)
{
	struct output *o = NULL;
	const double t0 = wall_now();
	const long step0 = s->step;
	int appended = 0;
	double *values = calloc((size_t)s->spec->probe_count + 1, sizeof(double));
	if (!values || (!s->step_cpu.count && step_histogram_init(&s->step_cpu))) {
		free(values);
		return poro_error_set(&s->err, PORO_ENOMEM, "cannot allocate probe values and step times");
	}
	enum poro_status st = open_output(s, out_dir, solver_version, &o, &appended);
	const double interval = s->spec->output.frame_interval;
	const double checkpoint_interval = s->spec->checkpoint.interval;
	const long thin = s->steps_total / PROBE_SAMPLES_TARGET + 1;
	double last_report = t0, last_checkpoint = t0, last_step_cpu = 0;
	long next_frame = next_multiple(s->time, interval);
	long next_checkpoint = next_multiple(s->time, checkpoint_interval);
	if (!st && !appended)
		st = write_frame(s, o);
	if (!st && !appended)
		st = sample_probes(s, o, values);
	while (!st && !sim_done(s)) {
		if (stop && *stop) {
			if (*stop == SIM_STOP_CHECKPOINT && s->step > step0)
				st = checkpoint(s, o, out_dir, progress, user, t0, step0);
			if (!st)
				st = poro_error_set(&s->err, PORO_EINTERRUPTED, "interrupted at step %ld (t = %.6g s)",
					    s->step, s->time);
			break;
		}
		st = timed_step(s, &last_step_cpu);
		if (st)
			break;
		if (s->step % thin == 0 || sim_done(s))
			st = sample_probes(s, o, values);
		if (!st && interval > 0 && s->time >= next_frame * interval * (1 - 1e-9) && !sim_done(s)) {
			st = write_frame(s, o);
			next_frame = next_multiple(s->time, interval);
		}
		int due = (checkpoint_interval > 0 && s->time >= next_checkpoint * checkpoint_interval * (1 - 1e-9)) ||
			  (s->checkpoint_wall > 0 && wall_now() - last_checkpoint >= s->checkpoint_wall);
		if (!st && due && !sim_done(s)) {
			st = checkpoint(s, o, out_dir, progress, user, t0, step0);
			next_checkpoint = next_multiple(s->time, checkpoint_interval);
			last_checkpoint = wall_now();
		}
		if (wall_now() - last_report >= s->spec->output.progress_interval) {
			report(s, progress, user, t0, step0, 0);
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
	report(s, progress, user, t0, step0, 0);
	free(values);
	return final;
}
