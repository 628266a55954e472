/*
 * figures.h - the figures a run reports about itself (its "metrics"): what each one means, its
 * unit and class, and the functions that compute the accuracy figures from a run's state and the
 * closed forms of analytic.h. A figure is computed here, once, by the code that owns the state
 * it measures; poro-solve writes them into the run's metrics.json and result.h5's /metrics group
 * (metrics.h; schemas/results.md), and the benchmark nightlies judge them (docs/benchmarks.md).
 *
 * Every simulation run reports the timing figures, its steps and max_displacement; every element
 * run the element figures marked "always". The others a case asks for by name in its optional
 * "metrics" object ({"terzaghi_rms": true}), because they assume a kind of problem: the loader
 * refuses a figure the case cannot yield (figure_check), naming why, before anything runs.
 *
 * Classes: accuracy figures measure an answer (an error against a closed form, a quantity a paper
 * reports); timing figures measure speed and depend on the machine; counts (steps, Newton
 * iterations) are exact and machine-free.
 *
 * Timings: the wall figures are what a user waits; the cpu figures count the processor time the
 * process spent in its steps (CLOCK_PROCESS_CPUTIME_ID, every thread), which other processes on
 * a shared machine change far less (docs/benchmarks.md, "Which clock").
 */
#ifndef PORO_FIGURES_H
#define PORO_FIGURES_H

#include <stddef.h>

enum figure_class { FIGURE_ACCURACY, FIGURE_TIMING, FIGURE_COUNT_CLASS };

/* Where a figure comes from: simulation runs and element runs may report it (FIGURE_SIM,
 * FIGURE_ELEMENT), and every such run does without being asked (the _ALWAYS bits). A figure a kind
 * of run reports only when asked needs its case's "metrics" object to name it. */
enum { FIGURE_SIM = 1, FIGURE_ELEMENT = 2, FIGURE_SIM_ALWAYS = 4, FIGURE_ELEMENT_ALWAYS = 8 };
#define FIGURE_EVERY_RUN (FIGURE_SIM | FIGURE_ELEMENT | FIGURE_SIM_ALWAYS | FIGURE_ELEMENT_ALWAYS)
#define FIGURE_EVERY_SIM (FIGURE_SIM | FIGURE_SIM_ALWAYS)
#define FIGURE_EVERY_ELEMENT (FIGURE_ELEMENT | FIGURE_ELEMENT_ALWAYS)

/*      kind                            name                      unit  class               where */
#define FIGURE_MAP(X)                                                                                                \
	X(FIGURE_WALL_SECONDS, "wall_seconds", "s", FIGURE_TIMING, FIGURE_EVERY_RUN)                                 \
	X(FIGURE_CPU_SECONDS, "cpu_seconds", "s", FIGURE_TIMING, FIGURE_EVERY_RUN)                                   \
	X(FIGURE_US_PER_POINT_STEP, "us_per_point_step", "us", FIGURE_TIMING, FIGURE_EVERY_SIM)                      \
	X(FIGURE_CPU_US_PER_POINT_STEP, "cpu_us_per_point_step", "us", FIGURE_TIMING, FIGURE_EVERY_SIM)              \
	X(FIGURE_MEDIAN_STEP_CPU_US, "median_cpu_us_per_point_step", "us", FIGURE_TIMING, FIGURE_EVERY_SIM)          \
	X(FIGURE_REFERENCE_KERNEL_US, "reference_kernel_us", "us", FIGURE_TIMING, FIGURE_SIM)                        \
	X(FIGURE_RELATIVE_STEP_COST, "relative_step_cost", "1", FIGURE_TIMING, FIGURE_SIM)                           \
	X(FIGURE_STEPS, "steps", "1", FIGURE_COUNT_CLASS, FIGURE_EVERY_RUN)                                          \
	X(FIGURE_MAX_DISPLACEMENT, "max_displacement", "m", FIGURE_ACCURACY, FIGURE_EVERY_SIM)                       \
	X(FIGURE_TERZAGHI_RMS, "terzaghi_rms", "1", FIGURE_ACCURACY, FIGURE_SIM)                                     \
	X(FIGURE_XIE_LEO_SETTLEMENT, "xie_leo_settlement", "1", FIGURE_ACCURACY, FIGURE_SIM)                         \
	X(FIGURE_RUNOUT, "runout", "m", FIGURE_ACCURACY, FIGURE_SIM)                                                 \
	X(FIGURE_PEAK_Q, "peak_q", "Pa", FIGURE_ACCURACY, FIGURE_EVERY_ELEMENT)                                      \
	X(FIGURE_NEWTON_ITERATIONS, "newton_iterations", "1", FIGURE_COUNT_CLASS, FIGURE_EVERY_ELEMENT | FIGURE_SIM) \
	X(FIGURE_MOHR_COULOMB_PEAK, "mohr_coulomb_peak_error", "1", FIGURE_ACCURACY, FIGURE_ELEMENT)

/* What each figure is, for docs and reports (figures.c holds the sentences):
 *   wall_seconds          wall time of the steps this process took (element: of the driver)
 *   cpu_seconds           processor time of the same, all threads
 *   us_per_point_step     wall microseconds per material-point step (soil plus water points)
 *   cpu_us_per_point_step processor microseconds per material-point step
 *   median_cpu_us_per_point_step  the median step's processor time over its points, us: what a
 *                         step costs on warm caches (step_timing.h), the timing figure the
 *                         nightlies record
 *   reference_kernel_us   the median processor time of the reference kernel (reference_kernel.h),
 *                         timed after each step when this or the next figure is asked for: how
 *                         fast the machine ran that kind of work during the run
 *   relative_step_cost    1000 x median_cpu_us_per_point_step / reference_kernel_us: a material-
 *                         point step's cost in thousandths of the reference kernel, both timed in
 *                         the same process step by step, so that a machine running slower for a
 *                         while leaves it nearly unchanged and a slower solver does not: the
 *                         timing figure the nightlies judge against history (docs/benchmarks.md,
 *                         "A machine with two speeds")
 *   steps                 steps taken (element: axial increments)
 *   max_displacement      largest displacement |x - x0| of a soil point at the end, m
 *   terzaghi_rms          RMS over the pressure points of (p - p_Terzaghi) / q at the end, each
 *                         point at the soil's reference height there (a loaded column: the first
 *                         body, loaded on its top face by the first load; drained at the top, and
 *                         at the bottom when the bottom face drains)
 *   xie_leo_settlement    |S - S_Xie-Leo| / S_Xie-Leo of the top's settlement at the end (000 Eq.
 *                         87; the same column, Poisson ratio 0)
 *   runout                how far the slope's soil travelled by the last frame (report.h), m
 *   peak_q                largest deviator q of the element test, Pa
 *   newton_iterations     Newton iterations of all steps: of the drained element test (0
 *                         undrained), or, asked for, of a simulation by a scheme that iterates
 *                         within a step (implicit_upU: sim_iterations)
 *   mohr_coulomb_peak_error  |q_peak - q_closed form| / q_closed form of a drained Mohr-Coulomb
 *                         element test (analytic.h), q taken at the last step */

enum figure_kind {
#define FIGURE_ENUM(kind, name, unit, cls, where) kind,
	FIGURE_MAP(FIGURE_ENUM)
#undef FIGURE_ENUM
	FIGURE_COUNT
};

/* The figures a case's "metrics" bits (1u << kind) ask for that need the reference kernel timed
 * beside the steps (sim_time_reference). */
#define FIGURES_NEEDING_REFERENCE (1u << FIGURE_REFERENCE_KERNEL_US | 1u << FIGURE_RELATIVE_STEP_COST)

const char *figure_name(enum figure_kind k);
const char *figure_unit(enum figure_kind k);
enum figure_class figure_class(enum figure_kind k);
const char *figure_class_name(enum figure_class c);   /* "accuracy", "timing", "count" */
unsigned figure_where(enum figure_kind k);
const char *figure_meaning(enum figure_kind k);
/* The figure of a name; -1 when unknown. */
int figure_parse(const char *name);

struct case_spec;
struct element_case;
struct particles;

/* 0 when the case can yield figure k; else -1 with why (a message for "/metrics/NAME: ..."). */
int figure_check(const struct case_spec *c, enum figure_kind k, char *why, size_t why_size);
int figure_check_element(const struct element_case *c, enum figure_kind k, char *why, size_t why_size);

/* The reference height of the soil at current height y, read off the soil points on the vertical
 * line of soil point 0 (linear between the two that bracket y; below the lowest y0/y is kept;
 * above the highest, top0), for comparisons with theories written in the reference coordinate. */
double figure_reference_height(const struct particles *soil, double y, double top0);

/* RMS of (p - p_Terzaghi) / q over n pressure points (p[n], Pa; positions xy[2n]) at time t, each
 * at its reference height; NAN when the case is not a loaded column. */
double figure_terzaghi_rms(const struct case_spec *c, const struct particles *soil, double t, const double *p,
			   const double *xy, long n);
/* |S - S_Xie-Leo| / S_Xie-Leo at time t, S the mean current top edge of the top row of soil points
 * below the column's top (y0 within a seeding spacing of it). */
double figure_xie_leo_settlement(const struct case_spec *c, const struct particles *soil, double t);
/* Largest |x - x0| over the soil points, m. */
double figure_max_displacement(const struct particles *soil);
/* |q_peak - q_MC| / q_MC for a drained Mohr-Coulomb element case, q_peak and J of the last step. */
double figure_mohr_coulomb_peak_error(const struct element_case *c, double q_last, double J_last);

#endif
