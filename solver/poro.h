/*
 * poro.h - the public solver API: build a simulation from a case, step it, read its state.
 *
 * The library knows nothing of HTTP, SQL or queues (DESIGN §1). Typical use:
 *
 *     struct case_spec *c; struct poro_error err = {0}; struct sim *s;
 *     if (case_load_file(path, &c, &err)) ...report err.message, exit 2...
 *     if (sim_create(&s, c, &err)) ...
 *     while (!sim_done(s)) if (sim_step(s)) ...report sim_error(s)->message...
 *     sim_destroy(&s); case_destroy(&c);
 *
 * sim_run() does the loop with result files and progress reporting (the poro-solve driver).
 * A sim borrows the case: keep it alive until sim_destroy().
 */
#ifndef PORO_H
#define PORO_H

#include "case.h"
#include "error.h"
#include "particles.h"

struct sim;

/* Builds grid, particles, materials and solver workspaces for a validated case. Everything a
 * step needs is allocated here. */
enum poro_status sim_create(struct sim **s, const struct case_spec *c, struct poro_error *err);
void sim_destroy(struct sim **s);

/* Advances one time step dt. On failure the error is in sim_error(s) and the state is the one at
 * the failure (for the message; not meant to be continued). */
enum poro_status sim_step(struct sim *s);
int sim_done(const struct sim *s);               /* time has reached the case's end time */
double sim_time(const struct sim *s);
long sim_steps_taken(const struct sim *s);
long sim_steps_total(const struct sim *s);
const struct poro_error *sim_error(const struct sim *s);
/* The first warning the run raised (a small-strain model far outside its validity, step_health.c),
 * or NULL. A warning does not stop the run; drivers print it in the run's log. */
const char *sim_warning(const struct sim *s);

/* Point sets. The water set is the double-point water points, or for single point the water
 * phase riding on the soil points (positions shared with the soil set). */
const struct particles *sim_soil(const struct sim *s);
const struct particles *sim_water(const struct sim *s);
int sim_is_double_point(const struct sim *s);

/* Physical pore pressure (positive in compression, Pa) at the points that carry it: the water
 * points in double point, the soil points in single point. Writes sim_pressure_point_count(s)
 * values and their positions (2 per point) if positions is not NULL. */
idx_t sim_pressure_point_count(const struct sim *s);
void sim_pore_pressure(const struct sim *s, double *pressure, double *positions);

/* Totals for conservation checks, kg per m: soil sum (1 - n) rho_s V over soil points; water
 * sum n rho_w V over water points (double point; single point: the water in the pores). */
double sim_soil_mass(const struct sim *s);
double sim_water_mass(const struct sim *s);
/* Water mass that left the grid through drained faces (double point), kg per m. */
double sim_water_outflow_mass(const struct sim *s);
/* Nodal soil and water-point mass sums of the last P2G, and the point mass sums they were mapped
 * from (they agree to rounding by the partition of unity). */
void sim_grid_masses(const struct sim *s, double *grid_soil, double *grid_water, double *point_soil,
		     double *point_water);

/* Wall time spent in each phase of the steps taken so far (benchmarks). Phases, in step order:
 * shape functions, particle-to-grid, predictors, pressure assembly, pressure factor-and-solve,
 * correction, grid-to-particle, kinematics, stress update. */
enum sim_phase { PHASE_SHAPE, PHASE_P2G, PHASE_PREDICT, PHASE_PRESSURE_ASSEMBLY, PHASE_PRESSURE_SOLVE,
		 PHASE_CORRECT, PHASE_G2P, PHASE_KINEMATICS, PHASE_STRESS, PHASE_COUNT };
const char *sim_phase_name(enum sim_phase phase);   /* the semi-implicit scheme's names */
/* What the phase slot times in s's scheme; NULL for a slot the scheme does not use. */
const char *sim_phase_name_of(const struct sim *s, enum sim_phase phase);
double sim_phase_seconds(const struct sim *s, enum sim_phase phase);

/* The nonlinear iterations of a scheme that iterates (the implicit u-p-U scheme's Newton loop):
 * the last step's count, the run's total, and *energies (may be NULL) the last step's |delta . r|
 * per iteration, *count of them (at most the first SIM_ITERATIONS_KEPT). Returns 0 for a scheme
 * that takes each step in one pass (and sets the counts to 0). */
#define SIM_ITERATIONS_KEPT 64
int sim_iterations(const struct sim *s, int *last, long *total, const double **energies, int *count);

/* The sparse direct solver's work so far, for a scheme with one (the implicit u-p-U scheme's LU):
 * symbolic analyses, numeric factorisations, solves and the nonzeros of the last factors. Returns
 * 0 (and zeros) for the others. */
int sim_linear_solver_counts(const struct sim *s, long *analyses, long *factorisations, long *solves,
			     long *factor_nonzeros);

/* Value of probe i of the case at the current state (units: Pa, m). */
double sim_probe_value(const struct sim *s, int i);

/* Progress report given to sim_run's callback after steps; wall_seconds since the run started. */
struct sim_progress {
	long step, steps_total;
	double time, end_time, wall_seconds;
	double us_per_point_step;        /* wall microseconds per material-point step of this run so far */
	int checkpoint;                  /* 1: not a progress report but the announcement that
					    DIR/checkpoint.h5 now holds this step (checkpoint.h) */
	int iterations_last;             /* a scheme that iterates (sim_iterations): the last step's */
	double iterations_mean;          /* and the mean a step since the start; 0 for the others */
	const double *energies;          /* the last step's |delta . r| per iteration (its first
					    energy_count, at most SIM_ITERATIONS_KEPT); NULL for the others */
	int energy_count;
};
typedef void (*sim_progress_fn)(const struct sim_progress *p, void *user);

/* Runs to the end time writing out_dir/result.h5 and result.xdmf (frames at the case's
 * frame_interval, probes every step); calls progress every progress_interval of wall time and
 * at the end. stop (may be NULL) is polled each step: non-zero interrupts with PORO_EINTERRUPTED;
 * SIM_STOP_CHECKPOINT writes a checkpoint of the current step first, so that the run can be
 * resumed elsewhere without losing work (a worker whose allocation ends hands its job back so).
 * Writes out_dir/checkpoint.h5 every checkpoint.interval of simulated time (case) or every
 * sim_set_checkpoint_wall() seconds of wall time, whichever comes first, and calls progress with
 * checkpoint = 1 after each. A sim loaded from a checkpoint (checkpoint_load) continues from its
 * step and continues out_dir/result.h5 when it exists (run.c says how). */
#define SIM_STOP_CHECKPOINT 2
enum poro_status sim_run(struct sim *s, const char *out_dir, const char *solver_version,
			 sim_progress_fn progress, void *user, volatile int *stop);

/* Wall-clock interval between checkpoints in sim_run, s; 0 (the default) = by simulated time only. */
void sim_set_checkpoint_wall(struct sim *s, double seconds);

/* What the steps sim_run took in this process cost (a resumed run counts from its checkpoint):
 * wall and processor seconds (CLOCK_PROCESS_CPUTIME_ID: every thread), the steps, and the points
 * stepped (soil plus water points), for the timing figures (figures.h). Frames, probes and
 * checkpoints between the steps are not counted. */
struct sim_timing {
	double wall_seconds, cpu_seconds;
	double median_step_cpu;          /* s: the median step's processor time (step_timing.h) */
	double median_reference_cpu;     /* s: the reference kernel's median processor time, timed after
					  * each step when sim_time_reference asked; NAN otherwise */
	long steps;
	long points;
};
void sim_get_timing(const struct sim *s, struct sim_timing *t);

/* A test knob, never set by a case (docs/benchmarks.md, "Test knobs"): with factor > 1 sim_run
 * repeats, before each step, the step's first phase (the shape functions at the points' present
 * positions, which the step then computes again from the same positions) until that costs
 * (factor - 1) times the previous step's processor time, so each step costs about factor times
 * as much and every result stays bit-identical. 1 (the default) is off. */
void sim_set_slowdown(struct sim *s, double factor);

/* From now on sim_run times the reference kernel (reference_kernel.h) after each step, outside
 * the step's own timing, for the figures reference_kernel_us and relative_step_cost: the steps'
 * cost in units of what the machine gives at that moment (docs/benchmarks.md, "A machine with two
 * speeds"). About 45 us a step on the machine of docs/benchmarks.md; off until asked. 0, or
 * PORO_ENOMEM. */
enum poro_status sim_time_reference(struct sim *s);

#endif
