/*
 * slope_001_test.c - paper 001's slopes (§4.2-4.3) by the implicit u-p-U scheme
 * (solver/schemes/implicit/), each tried as the paper states it; what does not reproduce is
 * reported as XFAIL with the figures measured (docs/numerics.md, "001's slopes").
 *
 *  a. The softening clay slope (§4.2.1, tests/cases/clay_slope_001.json; Figs. 10-11): Tresca
 *     softening from 6.4 to 3.6 kPa, the pore pressure held at zero (001: "forcedly set to zero";
 *     here a water bulk modulus of 1 Pa, so that p = K_w eps_v / n stays below a few Pa while the
 *     water keeps its mass and drag), gravity ramped over 1 s with the soil elastic (001 holds the
 *     horizontal displacements during its ramp; cases have no such key), then 5 s of free failure.
 *     With B-bar and without: the mean-stress oscillation index at the end at most
 *     OSCILLATION_MAX with B-bar and OSCILLATION_RATIO times that without (Fig. 10); the largest
 *     displacement of the upper layer's points at least 1 m with B-bar (spec-001 §9.3) and, without,
 *     under a quarter of that (Fig. 11: locked); and with B-bar from the K0 state with gravity at
 *     once (001's state at its release, set below). The last three are XFAIL (the slope stops at
 *     0.12 m; docs/numerics.md, "001's examples"). make test and make verify alike.
 *  b. The saturated sand slope (§4.2.2, tests/cases/sand_slope_001.json; Figs. 12-14): started
 *     here from the geostatic state 001's initialisation ends in (hydrostatic pore pressure below
 *     the local surface, sigma'_yy = -gamma' d, sigma'_xx = sigma'_zz = K0 sigma'_yy, K0 = nu / (1 -
 *     nu); case files have no initial-stress key) with gravity at once. The excess pore pressure
 *     p - p0 of the point nearest A = (5.5, 1.2) (spec-001 §9.4's reading of Fig. 12a) for k = 1e-2,
 *     1e-4 and 1e-6 m/s: its peak positive (contractive psi = -5 deg) and rising as k falls (Fig. 14),
 *     and the toe's run-out growing as k falls (Fig. 13). make test: k = 1e-4 to SAND_SHORT_END;
 *     make verify: the three k to 50 s.
 *  c. The footing near the slope (§4.3, tests/cases/footing_slope_001.json; Fig. 18): the footing
 *     edge lambda B from the crest, lambda = 0, 1, 2, 4, 6 and level ground, from the same
 *     geostatic state: q at d = 0.1 B and 0.5 B, rising with lambda, lambda = 6 within 5% of level
 *     ground. make verify only.
 */
#include <string.h>

#include "../case_file.h"
#include "../harness.h"
#include "oscillation.h"
#include "poro.h"
#include "sim_internal.h"

#define CASES "tests/cases/"
#define G 9.81
#define CLAY_RUNOUT_MIN 1.0       /* m: B-bar's largest displacement at the end (spec-001 §9.3) */
#define LOCKED_SHARE 0.25         /* without B-bar: below this share of B-bar's */
#define OSCILLATION_MAX 0.05      /* mean-stress oscillation index with B-bar (spec-001 §9.3) */
#define OSCILLATION_RATIO 3.0     /* and at least this many times larger without */
#define SAND_SHORT_END 2.0        /* s: past Fig. 14's peak at about 1.25 s */
#define LEVEL_TOLERANCE 0.05      /* lambda = 6 against level ground */

/* A simulation of c, or NULL after an INFO line naming `what` and the problem. */
static struct sim *build(const struct case_spec *c, const char *what)
{
	struct poro_error err = {0};
	struct sim *s = NULL;
	if (sim_create(&s, c, &err))
		printf("INFO cannot build %s: %s\n", what, err.message);
	return s;
}

/* ---- geostatic state ---- */

/* The ground surface's height above x for the slope of Figs. 9 and 17: crest at y_c up to x_c,
 * a 45 degree face, toe plain at y_t; x_c = +inf is level ground. */
struct ground {
	double x_c, y_c, y_t;
};

static double surface(const struct ground *g, double x)
{
	return x <= g->x_c ? g->y_c : fmax(g->y_t, g->y_c - (x - g->x_c));
}

/* Sets each point's pore pressure to hydrostatic below the local surface and its effective stress
 * to the K0 state of its depth (file comment; 001's simulation starts there); with
 * `dry_pressure` the pore pressure stays 0 and the skeleton carries the saturated weight (the clay
 * of §4.2.1, whose water's weight reaches the skeleton through the drag). */
static void set_geostatic(struct sim *s, const struct ground *gr, int dry_pressure)
{
	struct particles *p = &s->soil, *w = &s->water;
	for (idx_t q = 0; q < p->n; q++) {
		const struct case_body *b = &s->spec->bodies[p->body[q]];
		const struct material *m = &s->materials[b->material];
		const double rho_s = s->spec->materials[b->material].density, nu = s->spec->materials[b->material].poisson_ratio;
		const double d = fmax(0.0, surface(gr, p->x[2 * q]) - p->x[2 * q + 1]);
		const double rho = dry_pressure ? (1.0 - b->porosity) * rho_s + b->porosity * s->rho_w
						: (1.0 - b->porosity) * (rho_s - s->rho_w);
		const double gamma = rho * G, K0 = nu / (1.0 - nu);
		double *st = p->stress + 4 * q;
		st[1] = -gamma * d;
		st[0] = st[3] = K0 * st[1];
		st[2] = 0.0;
		material_init_state(m, st, p->Be + 4 * q, p->state + STATE_MAX * q);
		if (q < w->n)
			w->pressure[q] = dry_pressure ? 0.0 : -s->rho_w * G * d;   /* tension positive */
	}
}

/* The point whose initial position is nearest to x. */
static idx_t nearest_point(const struct sim *s, const double *x)
{
	const struct particles *p = sim_soil(s);
	idx_t best = 0;
	double d = INFINITY;
	for (idx_t q = 0; q < p->n; q++) {
		const double e = hypot(p->x0[2 * q] - x[0], p->x0[2 * q + 1] - x[1]);
		if (e < d)
			d = e, best = q;
	}
	return best;
}

/* ---- a. clay ---- */

struct slope_run {
	int ok;
	double largest, toe_runout, residual_share, index, seconds;
	char failure[256];
};

static void measure_upper(const struct sim *s, int upper_body, double residual_strain, struct slope_run *r)
{
	const struct particles *p = sim_soil(s);
	long count = 0, residual = 0;
	for (idx_t q = 0; q < p->n; q++) {
		if (p->body[q] != upper_body)
			continue;
		const double dx = p->x[2 * q] - p->x0[2 * q], dy = p->x[2 * q + 1] - p->x0[2 * q + 1];
		r->largest = fmax(r->largest, hypot(dx, dy));
		r->toe_runout = fmax(r->toe_runout, p->x[2 * q] - p->x0[2 * q]);
		count++;
		residual += p->plastic_strain[q] >= residual_strain;
	}
	r->residual_share = count ? (double)residual / (double)count : 0.0;
}

/* geostatic: start from the K0 state with gravity at once (001's state after its constrained
 * initialisation) instead of the case's elastic ramp. */
static struct slope_run run_clay(enum soil_stabilisation st, int geostatic)
{
	struct slope_run r = {0};
	struct case_spec *c = test_case_load(CASES "clay_slope_001.json");
	struct sim *s = NULL;
	struct poro_error err = {0};
	if (!c)
		return r;
	c->formulation.soil_stabilisation = st;
	if (geostatic) {
		c->gravity.ramp_time = 0.0, c->gravity.elastic_loading = 0;
		c->time.end -= 1.0;   /* the 5 s of failure after the ramp */
	}
	if (!(s = build(c, "the clay slope"))) {
		case_destroy(&c);
		return r;
	}
	const struct ground gr = {4.0, 3.0, 1.0};
	if (geostatic)
		set_geostatic(s, &gr, 1);
	const double t0 = harness_wall_seconds();
	int ok = 1;
	while (ok && !sim_done(s))
		ok = !sim_step(s);
	r.seconds = harness_wall_seconds() - t0;
	r.ok = ok;
	if (!ok)
		snprintf(r.failure, sizeof r.failure, "t = %.2f s: %.200s", sim_time(s), sim_error(s)->message);
	measure_upper(s, 1, c->materials[0].residual_plastic_strain, &r);
	if (oscillation_index(&c->grid, sim_soil(s), c->grid.cell_size / 2, &r.index, &err))
		r.index = -1;
	sim_destroy(&s);
	case_destroy(&c);
	return r;
}

static void clay_slope(void)
{
	struct slope_run bbar = run_clay(STABILISATION_BBAR, 0), none = run_clay(STABILISATION_NONE, 0);
	struct slope_run k0 = run_clay(STABILISATION_BBAR, 1);
	const struct slope_run *runs[3] = {&bbar, &none, &k0};
	static const char *const labels[3] = {"B-bar", "no B-bar", "B-bar from the K0 state"};
	for (int k = 0; k < 3; k++)
		printf("INFO clay slope 001 %s: %s; upper layer: largest displacement %.3f m, toe run-out %.3f m, %.1f%% "
		       "of its points at residual strength; mean-stress oscillation index %.4f; %.1f s of wall time%s%s\n",
		       labels[k], runs[k]->ok ? "ran to the end" : "FAILED", runs[k]->largest, runs[k]->toe_runout,
		       100 * runs[k]->residual_share, runs[k]->index, runs[k]->seconds, runs[k]->ok ? "" : ": ",
		       runs[k]->failure);
	/* Fig. 10: without B-bar the mean stress oscillates, with it smooth (spec-001 §9.3: at most
	 * OSCILLATION_MAX with B-bar, OSCILLATION_RATIO times more without) */
	CHECK(bbar.ok && none.ok && bbar.index >= 0 && bbar.index <= OSCILLATION_MAX &&
	      none.index >= OSCILLATION_RATIO * bbar.index, "clay_slope_001_bbar_removes_stress_oscillation",
	      "index %.4f with B-bar, %.4f without", bbar.index, none.index);
	CHECK_KNOWN_FAILURE(bbar.ok && bbar.largest >= CLAY_RUNOUT_MIN, "clay_slope_001_bbar_runs_out",
			    "largest displacement %.3f m (%s)", bbar.largest, bbar.ok ? "ran" : bbar.failure);
	CHECK_KNOWN_FAILURE(k0.ok && k0.largest >= CLAY_RUNOUT_MIN, "clay_slope_001_bbar_runs_out_from_k0_state",
			    "largest displacement %.3f m (%s)", k0.largest, k0.ok ? "ran" : k0.failure);
	CHECK_KNOWN_FAILURE(bbar.ok && none.ok && none.largest < LOCKED_SHARE * bbar.largest,
			    "clay_slope_001_locked_without_bbar", "%.3f m against B-bar's %.3f m", none.largest,
			    bbar.largest);
}

/* ---- b. sand ---- */

struct sand_run {
	int ok;
	double peak, peak_time, final, toe_runout, end_time, seconds;
	char failure[256];
};

static struct sand_run run_sand(double k, double end)
{
	struct sand_run r = {0};
	struct case_spec *c = test_case_load(CASES "sand_slope_001.json");
	struct sim *s = NULL;
	if (!c)
		return r;
	for (int b = 0; b < c->body_count; b++)
		c->bodies[b].hydraulic_conductivity = k;
	c->gravity.ramp_time = 0.0, c->gravity.elastic_loading = 0;
	c->time.end = end;
	if (!(s = build(c, "the sand slope"))) {
		case_destroy(&c);
		return r;
	}
	const struct ground gr = {4.0, 3.0, 1.0};
	set_geostatic(s, &gr, 0);
	static const double A[2] = {5.5, 1.2};
	const idx_t qA = nearest_point(s, A);
	const double pA0 = s->water.pressure[qA], t0 = harness_wall_seconds();
	int ok = 1;
	while (ok && !sim_done(s)) {
		ok = !sim_step(s);
		const double excess = -(s->water.pressure[qA] - pA0);   /* compression positive */
		if (ok && excess > r.peak)
			r.peak = excess, r.peak_time = sim_time(s);
		r.final = excess;
	}
	r.seconds = harness_wall_seconds() - t0;
	r.ok = ok, r.end_time = sim_time(s);
	if (!ok)
		snprintf(r.failure, sizeof r.failure, "%.240s", sim_error(s)->message);
	struct slope_run u = {0};
	measure_upper(s, 1, INFINITY, &u);
	r.toe_runout = u.toe_runout;
	sim_destroy(&s);
	case_destroy(&c);
	return r;
}

static void print_sand(double k, const struct sand_run *r)
{
	printf("INFO sand slope 001 k=%g m/s: %s to t = %.2f s; excess p at A peak %.1f Pa at %.2f s, last %.1f Pa; "
	       "toe run-out %.3f m; %.1f s of wall time%s%s\n", k, r->ok ? "ran" : "FAILED", r->end_time, r->peak,
	       r->peak_time, r->final, r->toe_runout, r->seconds, r->ok ? "" : ": ", r->failure);
}

static void sand_slope(int long_run)
{
	if (!long_run) {
		struct sand_run r = run_sand(1e-4, SAND_SHORT_END);
		print_sand(1e-4, &r);
		/* Fig. 14: positive excess (contractive), rising to its peak by about 1.25 s */
		CHECK_KNOWN_FAILURE(r.ok && r.peak > 0 && r.peak_time < SAND_SHORT_END - 0.1,
				    "sand_slope_001_excess_at_A_peaks_positive", "peak %.1f Pa at %.2f s (%s)", r.peak,
				    r.peak_time, r.ok ? "ran" : r.failure);
		return;
	}
	static const double ks[3] = {1e-2, 1e-4, 1e-6};
	struct sand_run r[3];
	for (int i = 0; i < 3; i++) {
		r[i] = run_sand(ks[i], 50.0);
		print_sand(ks[i], &r[i]);
	}
	CHECK_KNOWN_FAILURE(r[0].ok && r[1].ok && r[2].ok && r[0].peak < r[1].peak && r[1].peak < r[2].peak &&
			    r[1].peak > 0, "sand_slope_001_excess_at_A_rises_as_k_falls",
			    "peaks %.1f, %.1f, %.1f Pa at k = 1e-2, 1e-4, 1e-6", r[0].peak, r[1].peak, r[2].peak);
	CHECK_KNOWN_FAILURE(r[0].ok && r[1].ok && r[2].ok && r[0].toe_runout < r[1].toe_runout &&
			    r[1].toe_runout < r[2].toe_runout, "sand_slope_001_runout_grows_as_k_falls",
			    "toe run-out %.3f, %.3f, %.3f m", r[0].toe_runout, r[1].toe_runout, r[2].toe_runout);
}

/* ---- c. footing near the slope ---- */

struct footing_slope_run {
	int ok;
	double q01, q05, d_end, t_end;
	char failure[256];
};

/* lambda < 0: level ground. The footing (body 2) spans [13 - lambda - 1, 13 - lambda]; level
 * ground takes the upper layer (body 1) to the grid's right side and centres the footing. */
static struct footing_slope_run run_footing_slope(double lambda)
{
	struct footing_slope_run r = {0};
	struct case_spec *c = test_case_load(CASES "footing_slope_001.json");
	struct sim *s = NULL;
	if (!c)
		return r;
	struct case_body *upper = &c->bodies[1], *footing = &c->bodies[2];
	struct ground gr = {13.0, 6.0, 1.0};
	const double right = lambda < 0 ? 13.5 : 13.0 - lambda;
	if (lambda < 0) {
		upper->polygon[1][0] = c->grid.extent[0], upper->polygon[2][0] = c->grid.extent[0];
		upper->max[0] = c->grid.extent[0];
		gr.x_c = INFINITY;
	}
	footing->min[0] = right - 1.0, footing->max[0] = right;
	c->gravity.ramp_time = 0.0, c->gravity.elastic_loading = 0;
	if (!(s = build(c, "the footing near the slope"))) {
		case_destroy(&c);
		return r;
	}
	set_geostatic(s, &gr, 0);
	const double x[2] = {right - 0.5, 6.125};
	const idx_t q0 = nearest_point(s, x);
	const double rate = -c->loads[0].traction[1] / c->loads[0].time_function.ramp_time;
	int ok = 1;
	double d_prev = 0, q_prev = 0;
	while (ok && !sim_done(s) && r.d_end < 0.5) {
		ok = !sim_step(s);
		const double d = s->soil.x0[2 * q0 + 1] - s->soil.x[2 * q0 + 1], q = rate * sim_time(s);
		if (!r.q01 && d >= 0.1)
			r.q01 = q_prev + (q - q_prev) * (0.1 - d_prev) / (d - d_prev);
		if (!r.q05 && d >= 0.5)
			r.q05 = q_prev + (q - q_prev) * (0.5 - d_prev) / (d - d_prev);
		d_prev = d, q_prev = q, r.d_end = d;
	}
	r.ok = ok, r.t_end = sim_time(s);
	if (!ok)
		snprintf(r.failure, sizeof r.failure, "%.240s", sim_error(s)->message);
	sim_destroy(&s);
	case_destroy(&c);
	return r;
}

static void footing_slope(void)
{
	static const double lambdas[6] = {0, 1, 2, 4, 6, -1};
	struct footing_slope_run r[6];
	int rising = 1;
	for (int i = 0; i < 6; i++) {
		r[i] = run_footing_slope(lambdas[i]);
		printf("INFO footing near slope 001 lambda=%s: %s to t = %.2f s, d/B %.3f; q at d = 0.1 B %.1f kPa, at "
		       "0.5 B %.1f kPa%s%s\n", i == 5 ? "inf" : (const char *[]){"0", "1", "2", "4", "6"}[i],
		       r[i].ok ? "ran" : "FAILED", r[i].t_end, r[i].d_end, 1e-3 * r[i].q01, 1e-3 * r[i].q05,
		       r[i].ok ? "" : ": ", r[i].failure);
		rising = rising && r[i].q05 > 0 && (i == 0 || r[i].q05 >= r[i - 1].q05);
	}
	CHECK_KNOWN_FAILURE(rising, "footing_slope_001_capacity_rises_with_lambda",
			    "q at d = 0.5 B: %.1f, %.1f, %.1f, %.1f, %.1f, %.1f kPa", 1e-3 * r[0].q05, 1e-3 * r[1].q05,
			    1e-3 * r[2].q05, 1e-3 * r[3].q05, 1e-3 * r[4].q05, 1e-3 * r[5].q05);
	CHECK_KNOWN_FAILURE(r[4].q05 > 0 && r[5].q05 > 0 && fabs(r[4].q05 / r[5].q05 - 1) <= LEVEL_TOLERANCE,
			    "footing_slope_001_lambda6_within_5pct_of_level", "%.1f against %.1f kPa", 1e-3 * r[4].q05,
			    1e-3 * r[5].q05);
}

/* With an argument ("clay", "sand" or "footing") only that part runs, for looking at one example. */
int main(int argc, char **argv)
{
	const char *env = getenv("PORO_VERIFY_LONG"), *only = argc > 1 ? argv[1] : NULL;
	const int long_run = env && *env && strcmp(env, "0") != 0;
	if (!only || !strcmp(only, "clay"))
		clay_slope();
	if (!only || !strcmp(only, "sand"))
		sand_slope(long_run);
	if ((long_run && !only) || (only && !strcmp(only, "footing")))
		footing_slope();
	HARNESS_EXIT();
}
