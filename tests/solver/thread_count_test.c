/*
 * thread_count_test.c - a run is the same bit for bit whatever the thread count.
 *
 * A job's result must not depend on how many threads the worker gave it: a user who reruns a case
 * on another host, or with another `threads`, gets the same numbers. The reduced loose landslide
 * (double point, consistent projection, Nor-Sand) is stepped side by side on one and on two
 * threads, through the elastic gravity ramp (4,167 steps at this size) and 240 steps into the
 * plastic slide, and every point's position, velocity, stress and pore pressure is compared for
 * exact equality at every step. Before the pressure solve held its BLAS to one thread
 * (spd_solve.c) the two runs differed at the first step (nodal pressure increments by 2e-14 Pa),
 * and at paper size the slide then ran out 0.352 m on one thread and 0.324 m on two
 * (docs/performance.md, "Threads"). The stress update, threaded over the points, runs elastic,
 * resets its reference at the ramp's end and returns Nor-Sand plastically here.
 *
 * Then several points are broken so that their stress update fails, and the step's error must be
 * the lowest-numbered failing point's, on one thread as on two (the threaded loop updates every
 * point and keeps each thread's first failure; semi_implicit.c).
 *
 * The particle-to-grid scatters run in parallel in the block order of point_blocks.h. The
 * landslide takes the consistent projection's paths; shorter runs side by side take the others,
 * each with a check that the path was taken: the Laplacian with the linear fit of p^t, the point
 * divergences and a strip load through the points under APIC (paper 002's strip load), single
 * point with AFLIP (the water set riding on the soil set's blocks), storage of cavitating water
 * points (the cavitation column pulled faster), and water points leaving through a drained face,
 * after which the blocks of the shrunk set are sorted again (a permeable drained column).
 * Paper 002's explicit scheme (the strip load on 0.25 m cells: its masses, forces, cell averages
 * and pressure-rate moments scattered in block order; and a column with the linear basis) and
 * paper 001's implicit scheme (the footing turning plastic under the consistent tangent: the
 * kinematics' scatter, the residual with its stress updates and the matrix assembled in block
 * order) are compared the same way.
 */
#include <omp.h>
#include <string.h>

#include "../harness.h"
#include "../verify/slope_case.h"
#include "case.h"
#include "poro.h"
#include "sim_internal.h"

#define CASE_FILE "tests/cases/landslide_loose_double_point.json"
#define STEPS 4407   /* the ramp ends at step 4,167 */

static void run_long(json_t *doc, void *user)
{
	(void)user;
	slope_case_set(doc, "time", "end", json_real(10.0));
	json_object_del(doc, "checkpoint");
}

/* Number of entries of a and b (count each) that differ in any bit. */
static long differing(const double *a, const double *b, idx_t count)
{
	long n = 0;
	for (idx_t i = 0; i < count; i++)
		n += memcmp(a + i, b + i, sizeof(double)) != 0;
	return n;
}

static long differing_points(const struct particles *a, const struct particles *b, int with_stress)
{
	if (a->n != b->n)
		return -1;
	long n = differing(a->x, b->x, 2 * a->n) + differing(a->v, b->v, 2 * a->n) +
		 differing(a->pressure, b->pressure, a->n);
	if (with_stress)
		n += differing(a->stress, b->stress, 4 * a->n);
	return n;
}

/* Steps one and two, side by side on one and on two threads, for at most `steps` steps or until
 * their points differ; returns the step they first differ at (0 if never; -1 if a step failed)
 * with the count of differing values in *differences. */
static long first_difference(struct sim *one, struct sim *two, long steps, long *differences)
{
	const int threads = omp_get_max_threads();
	long first = 0;
	*differences = 0;
	for (long k = 1; k <= steps && !first; k++) {
		omp_set_num_threads(1);
		int ok = sim_step(one) == PORO_OK;
		omp_set_num_threads(2);
		ok = ok && sim_step(two) == PORO_OK;
		if (!ok)
			first = -1;
		else if ((*differences = differing_points(&one->soil, &two->soil, 1) +
					 differing_points(&one->water, &two->water, 0)))
			first = k;
	}
	omp_set_num_threads(threads);
	return first;
}

/* A shorter run of another case (file comment): `label` names the path it takes, `taken` says
 * whether the run took it (after the steps, on the one-thread run). */
struct variant {
	const char *label, *file;
	double h;
	int ppc;
	long steps;
	void (*adjust)(json_t *doc, void *user);
	int (*taken)(const struct sim *s, char *what, size_t size);
};

static void with_apic(json_t *doc, void *user)
{
	(void)user;
	slope_case_set(doc, "formulation", "velocity_update", json_string("apic"));
}

static void with_aflip(json_t *doc, void *user)
{
	(void)user;
	slope_case_set(doc, "formulation", "velocity_update", json_string("aflip"));
}

/* The cavitation column's pull over 0.05 s instead of 1 s: its water reaches the cavitation
 * pressure within about 170 steps. */
static void pulled_fast(json_t *doc, void *user)
{
	(void)user;
	json_t *load = json_array_get(json_object_get(doc, "loads"), 0);
	json_object_set_new(json_object_get(load, "time_function"), "ramp_time", json_real(0.05));
}

/* The column drained at both ends, a thousand times as permeable and under its weight: its water
 * drains through the bottom, where it moves freely, at about k = 1 m/s, and the bottom rows of
 * water points leave within the run. */
static void permeable(json_t *doc, void *user)
{
	(void)user;
	json_t *body = json_array_get(json_object_get(doc, "bodies"), 0);
	json_object_set_new(body, "hydraulic_conductivity", json_real(1.0));
	json_t *g = json_array();
	json_array_append_new(g, json_real(0.0));
	json_array_append_new(g, json_real(-9.81));
	slope_case_set(doc, "gravity", "acceleration", g);
}

/* 002's explicit scheme with the linear basis of the pressure-rate projection (its moment
 * scatter; the default constant basis runs in the strip load variant). */
static void with_linear_basis(json_t *doc, void *user)
{
	(void)user;
	slope_case_set(doc, "formulation", "pressure_rate_basis", json_string("linear"));
}

/* 001's footing with the consistent tangent (the assembly every Newton iteration), its load rising
 * to 5 c in 1 s: the Tresca soil under the footing turns plastic within the run's 20 steps. */
static void footing_fast(json_t *doc, void *user)
{
	(void)user;
	slope_case_set(doc, "formulation", "tangent", json_string("consistent"));
	json_t *load = json_array_get(json_object_get(doc, "loads"), 0);
	json_object_set_new(json_object_get(load, "time_function"), "ramp_time", json_real(2.0));
}

static int explicit_taken(const struct sim *s, char *what, size_t size)
{
	const struct case_formulation *f = &s->spec->formulation;
	snprintf(what, size, "scheme %d, strain-rate smoothing %d, pressure-rate projection %d, basis %d", (int)f->scheme,
		 (int)f->strain_rate_smoothing, (int)f->pressure_rate_projection, (int)f->pressure_rate_basis);
	return f->scheme == SCHEME_EXPLICIT && f->strain_rate_smoothing == STRAIN_RATE_SMOOTHING_CELL_AVERAGE &&
	       f->pressure_rate_projection == PRESSURE_RATE_MULTI_FIELD;
}

static int implicit_taken(const struct sim *s, char *what, size_t size)
{
	int last = 0, count = 0;
	long total = 0;
	sim_iterations(s, &last, &total, NULL, &count);
	idx_t plastic = 0;
	for (idx_t q = 0; q < s->soil.n; q++)
		plastic += s->soil.plastic_strain[q] > 0.0;
	snprintf(what, size, "scheme %d, %ld Newton iterations, %ld plastic points", (int)s->spec->formulation.scheme,
		 total, (long)plastic);
	return s->spec->formulation.scheme == SCHEME_IMPLICIT_UPU && total > 0 && plastic > 0;
}

static int laplacian_taken(const struct sim *s, char *what, size_t size)
{
	snprintf(what, size, "projection %d, velocity update %d, load through the points %d",
		 (int)s->spec->formulation.pressure_projection, (int)s->spec->formulation.velocity_update,
		 s->load_bands[0].through_points);
	return s->spec->formulation.pressure_projection == PROJECTION_LAPLACIAN && s->double_point &&
	       s->spec->formulation.velocity_update == VELOCITY_UPDATE_APIC && s->load_bands[0].through_points;
}

static int single_point_taken(const struct sim *s, char *what, size_t size)
{
	snprintf(what, size, "double point %d, water rides on the soil %d", s->double_point, s->water.alias_of != NULL);
	return !s->double_point && s->water.alias_of == &s->soil;
}

static int cavitation_taken(const struct sim *s, char *what, size_t size)
{
	const double boiling = -s->spec->fluid.cavitation_pressure;
	idx_t cavitating = 0;
	for (idx_t q = 0; q < s->water.n; q++)
		cavitating += s->water.pressure[q] >= boiling;
	snprintf(what, size, "%ld water points at the cavitation pressure", (long)cavitating);
	return cavitating > 0;
}

static int outflow_taken(const struct sim *s, char *what, size_t size)
{
	snprintf(what, size, "%ld of %ld water points left", (long)(s->soil.n - s->water.n), (long)s->soil.n);
	return s->water.n < s->soil.n;
}

static void check_variant(const struct variant *v)
{
	struct case_spec *c1 = NULL, *c2 = NULL;
	struct sim *one = NULL, *two = NULL;
	char name[128], what[160] = "";
	long differences = 0, first = -1;
	if (!slope_case_create(v->file, v->h, v->ppc, v->adjust, NULL, &c1, &one) &&
	    !slope_case_create(v->file, v->h, v->ppc, v->adjust, NULL, &c2, &two))
		first = first_difference(one, two, v->steps, &differences);
	const int taken = first == 0 && v->taken(one, what, sizeof what);
	printf("INFO %s: %ld steps; %s\n", v->label, first == 0 ? v->steps : first, what);
	snprintf(name, sizeof name, "thread_count_%s_one_and_two_threads_bit_identical", v->label);
	CHECK(first == 0 && taken, name, "%s; %ld point values differ at step %ld (-1: a step failed: %s / %s)", what,
	      differences, first, one ? sim_error(one)->message : "", two ? sim_error(two)->message : "");
	sim_destroy(&one);
	sim_destroy(&two);
	case_destroy(&c1);
	case_destroy(&c2);
}

/* Points whose stress update must fail, in no particular order, each with its own negative
 * out-of-plane elastic stretch Be_zz = -(q + 1), which the failure message prints ("non-positive
 * stretch (..., -(q + 1)), ..."): the message says which point was reported. */
static const idx_t broken[] = { 1000, 341, 702, 1100, 301 };
#define LOWEST_BROKEN_MARK "-302)"   /* point 301 */

/* Breaks the points above and takes one step: it must fail in the stress update. */
static enum poro_status step_with_broken_points(struct sim *s)
{
	for (size_t i = 0; i < sizeof broken / sizeof broken[0]; i++)
		s->soil.Be[4 * broken[i] + 3] = -(double)(broken[i] + 1);
	return sim_step(s);
}

int main(void)
{
	struct case_spec *c1 = NULL, *c2 = NULL;
	struct sim *one = NULL, *two = NULL;
	int ok = !slope_case_create(CASE_FILE, 0.05, 2, run_long, NULL, &c1, &one) &&
		 !slope_case_create(CASE_FILE, 0.05, 2, run_long, NULL, &c2, &two);
	CHECK(ok, "thread_count_cases_load", "cannot create the reduced landslide");
	long differences = 0;
	const int threads = omp_get_max_threads();
	const long first_step = ok ? first_difference(one, two, STEPS, &differences) : -1;
	ok = first_step >= 0;
	CHECK(ok, "thread_count_runs_step", "a step failed: %s / %s", one ? sim_error(one)->message : "",
	      two ? sim_error(two)->message : "");
	CHECK(first_step == 0, "thread_count_one_and_two_threads_bit_identical",
	      "%ld point values differ at step %ld", differences, first_step);
	if (ok) {
		omp_set_num_threads(1);
		const enum poro_status st1 = step_with_broken_points(one);
		omp_set_num_threads(2);
		const enum poro_status st2 = step_with_broken_points(two);
		omp_set_num_threads(threads);
		const char *m1 = sim_error(one)->message, *m2 = sim_error(two)->message;
		CHECK(st1 == PORO_ESOLVER && st2 == PORO_ESOLVER && !strcmp(m1, m2) && strstr(m1, LOWEST_BROKEN_MARK),
		      "thread_count_stress_failure_reports_the_lowest_point",
		      "status %d / %d, messages '%s' / '%s', want the point marked %s", st1, st2, m1, m2,
		      LOWEST_BROKEN_MARK);
	}
	sim_destroy(&one);
	sim_destroy(&two);
	case_destroy(&c1);
	case_destroy(&c2);
	static const struct variant variants[] = {
		{"strip_load_laplacian_apic", "tests/cases/strip_load_002.json", 0.5, 2, 500, with_apic, laplacian_taken},
		{"single_point_aflip", "tests/cases/terzaghi_single_point.json", 0.025, 2, 600, with_aflip,
		 single_point_taken},
		{"cavitation", "tests/cases/cavitation_column.json", 0.025, 2, 400, pulled_fast, cavitation_taken},
		{"water_outflow", "tests/cases/terzaghi_double_drained.json", 0.025, 2, 600, permeable, outflow_taken},
		{"explicit_strip_load", "tests/cases/strip_load_002_explicit.json", 0.25, 2, 300, NULL, explicit_taken},
		{"explicit_linear_basis", "tests/cases/terzaghi_002.json", 0.025, 2, 300, with_linear_basis,
		 explicit_taken},
		{"implicit_footing_consistent", "tests/cases/strip_footing_001.json", 0.25, 2, 20, footing_fast,
		 implicit_taken},
	};
	for (size_t k = 0; k < sizeof variants / sizeof variants[0]; k++)
		check_variant(&variants[k]);
	HARNESS_EXIT();
}
