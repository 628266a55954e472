/*
 * dry_body_test.c - dry bodies ("saturated": false, docs/numerics.md "Dry bodies"), double and
 * single point.
 *
 *  a. A dry embankment fill on a saturated clay layer (tests/cases/dry_embankment.json: clay 1 m,
 *     E = 5 MPa, nu = 0.3, n = 0.5, k = 1e-3 m/s, impermeable base; fill 0.5 m, dry, n = 0.35,
 *     rho_s = 2650 kg/m^3, so q = (1 - n) rho_s g H_fill = 8449 Pa; the fill spans the grid, so
 *     the loading is one-dimensional). The run starts from the clay's geostatic state under its
 *     own weight (hydrostatic pore pressure, sigma'_yy = -gamma' d, K0 = nu / (1 - nu)) and the
 *     fill's under its own (sigma'_yy = -rho_d g d): the fill's weight then reaches the clay at
 *     once, an undrained one-dimensional loading, which the fill's dry base drains. The fill
 *     then rings on the clay, undamped, with its own period 4 H_fill / c_p (32 ms, about 1.5%
 *     of q in the clay's pressure once the first transient has passed), so the clay's excess is
 *     read as its mean over a window of WINDOW_TV (0.01 in Tv, 146 ms, four periods): the mean of
 *     the ringing is the static response. Oracles:
 *       - just after loading (the window ending at Tv = 0.03) the excess pore pressure
 *         p - rho_w g (H - y) of the clay's lower half is q (1-D undrained loading of
 *         incompressible constituents; Terzaghi's drainage from the top has taken 0.4% of q
 *         from it by then), within EARLY_TOLERANCE of q;
 *       - the clay then consolidates as Terzaghi's layer drained at its top (drainage length
 *         H): RMS over the clay's pressure points within TERZAGHI_TOLERANCE of q at Tv = 0.05,
 *         0.1, 0.2, compared at the soil's reference height (column.h), and the lower half's
 *         window mean falls from each of these times to the next;
 *       - the fill carries no pore water: its bodies' points are not pressure points (single
 *         point: the water set is the clay's points alone), no pressure point lies above the
 *         clay, and the nodal pore pressure is exactly 0 at every node from the clay's top up, at
 *         every step.
 *  b. A dry column under gravity (tests/cases/dry_column.json: 1 m, n = 0.3, rho_s = 2650 kg/m^3,
 *     gravity ramped over 0.5 s from a stress-free start): no pressure point at all and the nodal
 *     pore pressure exactly 0 at every node and step, so the total stress is the effective stress;
 *     and that stress is the dry weight above: sigma'_yy averaged over the 0.47 s after the ramp
 *     (10 periods 4 H / c_p of the column's undamped ringing, whose mean is the static state)
 *     within COLUMN_TOLERANCE of -rho_d g d at every point deeper than two cells.
 * Each figure is printed on an INFO line before the check that asserts it.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../harness.h"
#include "analytic.h"
#include "case.h"
#include "column.h"
#include "material.h"
#include "poro.h"
#include "sim_internal.h"

#define EMBANKMENT_FILE "tests/cases/dry_embankment.json"
#define COLUMN_FILE "tests/cases/dry_column.json"
#define G 9.81
#define EARLY_TV 0.03
#define WINDOW_TV 0.01            /* the excess is averaged over this span of Tv before a sample */
#define EARLY_TOLERANCE 0.02      /* of q: the lower half's excess just after loading */
#define TERZAGHI_TOLERANCE 0.02   /* of q: RMS against Terzaghi */
#define COLUMN_TOLERANCE 0.01     /* of rho_d g d: the dry column's mean vertical stress */
#define SKIN_CELLS 2.0

static const double check_tv[] = {0.05, 0.1, 0.2};
#define CHECKS (int)(sizeof check_tv / sizeof check_tv[0])

struct embankment {
	double H, top, q, rho_w, cv;   /* clay height and fill top, m; load, Pa; m^2/s */
	const struct case_body *clay, *fill;
};

static struct embankment embankment_of(const struct case_spec *c)
{
	struct embankment e = {.clay = &c->bodies[0], .fill = &c->bodies[1], .rho_w = c->fluid.density};
	const struct case_material *m = &c->materials[e.clay->material], *mf = &c->materials[e.fill->material];
	const double nu = m->poisson_ratio, mv = (1 + nu) * (1 - 2 * nu) / ((1 - nu) * m->youngs_modulus);
	e.H = e.clay->max[1];
	e.top = e.fill->max[1];
	e.q = (1.0 - e.fill->porosity) * mf->density * G * (e.top - e.H);
	e.cv = e.clay->hydraulic_conductivity / (mv * e.rho_w * G);   /* 000 Eq. 86 */
	return e;
}

/* The geostatic state (file comment): each soil point carries the effective weight of its own body
 * above it, buoyant in the clay, dry in the fill; the clay's water is hydrostatic below its top. */
static void set_geostatic(struct sim *s, const struct embankment *e)
{
	const struct case_spec *c = s->spec;
	struct particles *p = &s->soil;
	for (idx_t q = 0; q < p->n; q++) {
		const struct case_body *b = &c->bodies[p->body[q]];
		const struct case_material *m = &c->materials[b->material];
		const double density = (1.0 - b->porosity) * (m->density - (b->saturated ? s->rho_w : 0.0));
		const double K0 = m->poisson_ratio / (1.0 - m->poisson_ratio);
		double *st = p->stress + 4 * q;
		st[1] = -density * G * (b->max[1] - p->x[2 * q + 1]);
		st[0] = st[3] = K0 * st[1];
		st[2] = 0.0;
		material_init_state(&s->materials[b->material], st, p->Be + 4 * q, p->state + STATE_MAX * q);
	}
	struct particles *w = &s->water;   /* tension positive inside the solver */
	for (idx_t q = 0; q < w->n; q++)
		w->pressure[q] = -s->rho_w * G * (e->H - w->x[2 * q + 1]);
}

/* The largest |nodal pore pressure| at the nodes at or above height y. */
static double nodal_pressure_above(const struct sim *s, double y)
{
	const struct grid *g = &s->grid;
	double worst = 0.0;
	for (idx_t I = 0; I < g->node_count; I++)
		if (g->origin[1] + (double)(I / g->nodes[0]) * g->h >= y - 1e-9 * g->h)
			worst = fmax(worst, fabs(s->f.pressure[I]));
	return worst;
}

struct embankment_run {
	int ok;
	double early;              /* window mean of the lower half's excess before EARLY_TV, / q */
	double middle[CHECKS];     /* the same before each check_tv */
	double rms[CHECKS];        /* RMS against Terzaghi, / q */
	double fill_pressure;      /* largest |nodal p| from the clay's top up, over every step, Pa */
	long points_above;         /* pressure points above the clay's top, over the samples */
	int fill_points_dry;       /* no point of the fill among the pressure points */
};

/* The pressure points' pore pressures and positions into p[n], x[2n]; returns n. */
static idx_t pressures(const struct sim *s, double *p, double *x)
{
	sim_pore_pressure(s, p, x);
	return sim_pressure_point_count(s);
}

/* Mean excess pore pressure p - rho_w g (H - y) of the pressure points in the clay's lower half, / q
 * (each step of a window: the points' own heights, which move by less than 0.1% of H). */
static double lower_half_excess(const struct sim *s, const struct embankment *e, double *p, double *x)
{
	const idx_t n = pressures(s, p, x);
	double sum = 0.0;
	long count = 0;
	for (idx_t i = 0; i < n; i++)
		if (x[2 * i + 1] <= 0.5 * e->H)
			sum += p[i] - e->rho_w * G * (e->H - x[2 * i + 1]), count++;
	return count ? sum / (double)count / e->q : NAN;
}

/* RMS of the excess against Terzaghi at Tv, compared at the soil's reference height (column.h),
 * / q; counts the pressure points above the clay's top into *above. */
static double terzaghi_rms(const struct sim *s, const struct embankment *e, double Tv, double *p, double *x,
			   long *above)
{
	const idx_t n = pressures(s, p, x);
	double sq = 0.0;
	for (idx_t i = 0; i < n; i++) {
		const double y = x[2 * i + 1], excess = p[i] - e->rho_w * G * (e->H - y);
		const double d = excess - terzaghi_pressure(e->H - soil_reference_height(s, y, e->H), e->H, Tv, e->q);
		sq += d * d;
		*above += y > e->H;
	}
	return n ? sqrt(sq / (double)n) / e->q : NAN;
}

/* The case in file run with phases: its simulation and case in *c, or NULL (with an INFO line
 * naming what failed, and nothing left to free). */
static struct sim *start(const char *file, enum case_phases phases, struct case_spec **c)
{
	struct sim *s = NULL;
	struct poro_error err = {0};
	*c = NULL;
	if (!case_load_file(file, c, &err)) {
		(*c)->formulation.phases = phases;
		if (!sim_create(&s, *c, &err))
			return s;
	}
	printf("INFO %s: %s\n", file, err.message);
	case_destroy(c);
	return NULL;
}

/* The end of a run that start() began: what failed, if it did, and everything freed. */
static void stop(struct sim **s, struct case_spec **c, int ok)
{
	if (!ok)
		printf("INFO %s: %s\n", (*c)->title, sim_error(*s)->message);
	sim_destroy(s);
	case_destroy(c);
}

static struct embankment_run run_embankment(enum case_phases phases)
{
	struct embankment_run r = {0};
	struct case_spec *c = NULL;
	struct sim *s = start(EMBANKMENT_FILE, phases, &c);
	if (!(r.ok = s != NULL))
		return r;
	const struct embankment e = embankment_of(c);
	set_geostatic(s, &e);
	/* the points that carry water are the clay's: the fill's are none of them */
	const struct particles *soil = sim_soil(s);
	long clay_points = 0;
	for (idx_t q = 0; q < soil->n; q++)
		clay_points += soil->body[q] == 0;
	r.fill_points_dry = sim_pressure_point_count(s) == clay_points;
	for (idx_t q = 0; q < s->water.n; q++)
		r.fill_points_dry &= s->water.body[q] == 0;
	const double steps_per_tv = e.H * e.H / e.cv / c->time.dt;
	const idx_t n = sim_pressure_point_count(s);
	double *p = malloc(sizeof(double) * (size_t)(n + 1)), *x = malloc(2 * sizeof(double) * (size_t)(n + 1));
	for (int k = -1; r.ok && k < CHECKS; k++) {
		const double Tv = k < 0 ? EARLY_TV : check_tv[k];
		const long target = lround(Tv * steps_per_tv), from = lround((Tv - WINDOW_TV) * steps_per_tv);
		double sum = 0.0;
		while (r.ok && sim_steps_taken(s) < target) {
			r.ok = !sim_step(s);
			r.fill_pressure = fmax(r.fill_pressure, nodal_pressure_above(s, e.H));
			if (sim_steps_taken(s) > from)
				sum += lower_half_excess(s, &e, p, x);
		}
		*(k < 0 ? &r.early : &r.middle[k]) = sum / (double)(target - from);
		if (k >= 0)
			r.rms[k] = terzaghi_rms(s, &e, Tv, p, x, &r.points_above);
	}
	free(p);
	free(x);
	stop(&s, &c, r.ok);
	return r;
}

static void test_embankment(enum case_phases phases, const char *label)
{
	char name[160];
	const double t0 = harness_wall_seconds();
	struct embankment_run r = run_embankment(phases);
	snprintf(name, sizeof name, "dry_embankment_%s_runs", label);
	CHECK(r.ok, name, "the run failed");
	if (!r.ok)
		return;
	printf("INFO dry embankment %s: %.1f s; excess in the clay's lower half / q, mean over the %g of Tv before: "
	       "%.4f at Tv = %g", label, harness_wall_seconds() - t0, WINDOW_TV, r.early, EARLY_TV);
	for (int k = 0; k < CHECKS; k++)
		printf(", %.4f at %g", r.middle[k], check_tv[k]);
	printf("; RMS against Terzaghi / q:");
	for (int k = 0; k < CHECKS; k++)
		printf(" %.4f at Tv = %g%s", r.rms[k], check_tv[k], k + 1 < CHECKS ? "," : "");
	printf("; fill: largest |nodal p| %.3g Pa, pressure points above the clay %ld\n", r.fill_pressure,
	       r.points_above);
	snprintf(name, sizeof name, "dry_embankment_%s_undrained_excess_is_fill_weight", label);
	CHECK(fabs(r.early - 1.0) <= EARLY_TOLERANCE, name, "excess %.4f q at Tv = %g, wanted q within %g",
	      r.early, EARLY_TV, EARLY_TOLERANCE);
	double worst = 0.0;
	int falls = r.middle[0] < r.early;
	for (int k = 0; k < CHECKS; k++) {
		worst = fmax(worst, r.rms[k]);
		falls &= k == 0 || r.middle[k] < r.middle[k - 1];
	}
	snprintf(name, sizeof name, "dry_embankment_%s_consolidates_as_terzaghi", label);
	CHECK(worst <= TERZAGHI_TOLERANCE, name, "RMS %.4f q, wanted at most %g", worst, TERZAGHI_TOLERANCE);
	snprintf(name, sizeof name, "dry_embankment_%s_excess_falls_with_time", label);
	CHECK(falls, name, "the lower half's excess did not fall from each sample to the next");
	snprintf(name, sizeof name, "dry_embankment_%s_fill_has_no_pore_pressure", label);
	CHECK(r.fill_points_dry && r.points_above == 0 && r.fill_pressure == 0.0, name,
	      "fill points among the pressure points: %s; pressure points above the clay: %ld; largest |nodal p| "
	      "from the clay's top up: %.3g Pa", r.fill_points_dry ? "no" : "yes", r.points_above, r.fill_pressure);
}

struct column_run {
	int ok;
	long pressure_points;
	double largest_pressure;   /* |nodal p| over every node and step, Pa */
	double stress;             /* largest |mean sigma'_yy + rho_d g d| / (rho_d g d) below the skin */
	double stress_all;         /* the same over every point, / (rho_d g H) */
};

static struct column_run run_column(enum case_phases phases)
{
	struct column_run r = {0};
	struct case_spec *c = NULL;
	struct sim *s = start(COLUMN_FILE, phases, &c);
	if (!(r.ok = s != NULL))
		return r;
	const struct case_body *b = &c->bodies[0];
	const double rho_d = (1.0 - b->porosity) * c->materials[b->material].density, H = b->max[1];
	const struct particles *soil = sim_soil(s);
	double *mean = calloc((size_t)soil->n, sizeof(double));
	long samples = 0;
	r.pressure_points = sim_pressure_point_count(s);
	while (r.ok && !sim_done(s)) {
		r.ok = !sim_step(s);
		r.largest_pressure = fmax(r.largest_pressure, nodal_pressure_above(s, -INFINITY));
		if (sim_time(s) <= c->gravity.ramp_time + 0.5 * c->time.dt)
			continue;
		for (idx_t q = 0; q < soil->n; q++)
			mean[q] += soil->stress[4 * q + 1];
		samples++;
	}
	for (idx_t q = 0; r.ok && q < soil->n; q++) {
		const double d = H - soil->x0[2 * q + 1], want = -rho_d * G * d, e = fabs(mean[q] / samples - want);
		r.stress_all = fmax(r.stress_all, e / (rho_d * G * H));
		if (d > SKIN_CELLS * c->grid.cell_size)
			r.stress = fmax(r.stress, e / -want);
	}
	free(mean);
	stop(&s, &c, r.ok);
	return r;
}

static void test_column(enum case_phases phases, const char *label)
{
	char name[160];
	const double t0 = harness_wall_seconds();
	struct column_run r = run_column(phases);
	snprintf(name, sizeof name, "dry_column_%s_runs", label);
	CHECK(r.ok, name, "the run failed");
	if (!r.ok)
		return;
	printf("INFO dry column %s: %.1f s; %ld pressure points, largest |nodal p| %.3g Pa; mean sigma'_yy after "
	       "the ramp against rho_d g d: %.4f below two cells, %.4f of rho_d g H everywhere\n", label,
	       harness_wall_seconds() - t0, r.pressure_points, r.largest_pressure, r.stress, r.stress_all);
	snprintf(name, sizeof name, "dry_column_%s_has_no_pore_pressure", label);
	CHECK(r.pressure_points == 0 && r.largest_pressure == 0.0, name, "%ld pressure points, |nodal p| up to %.3g Pa",
	      r.pressure_points, r.largest_pressure);
	snprintf(name, sizeof name, "dry_column_%s_effective_stress_is_dry_weight", label);
	CHECK(r.stress <= COLUMN_TOLERANCE, name, "mean sigma'_yy off by %.4f of rho_d g d, wanted at most %g",
	      r.stress, COLUMN_TOLERANCE);
}

int main(void)
{
	test_embankment(PHASES_DOUBLE_POINT, "double_point");
	test_embankment(PHASES_SINGLE_POINT, "single_point");
	test_column(PHASES_DOUBLE_POINT, "double_point");
	test_column(PHASES_SINGLE_POINT, "single_point");
	HARNESS_EXIT();
}
