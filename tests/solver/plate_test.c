/*
 * plate_test.c - rigid smooth plates on grid faces (solver/schemes/semi_implicit/plate.c).
 *
 * Under a plate on a laterally confined column every horizontal section carries the same force,
 * so the column consolidates as under a uniform load: the oracle is Terzaghi's closed form
 * (solver/verify/analytic.h) with the drainage at the bottom and the plate impermeable on top.
 * tests/cases/terzaghi.json is run with its top traction q replaced by a plate of force q times
 * the column's width on the grid's top face (brought down to the column's top) and its bottom
 * drained:
 *  - pore pressure RMS within 2% of q at Tv = 0.1 and 0.2, double and single point, the drainage
 *    length the column's height measured from the drained bottom;
 *  - every node of the top face with soil moves with one vertical velocity, the plate's, soil and
 *    water alike, and the mean vertical stress of the column equals q within 1% from Tv = 0.1;
 *  - the plate's settlement (the time integral of its velocity) is Terzaghi's, q m_v H U(Tv), within
 *    3% at Tv = 0.1 and 0.2 (updated from the last step's pressure instead of with it, the plate's
 *    velocity grew twentyfold a step).
 */
#include <string.h>

#include "../harness.h"
#include "analytic.h"
#include "../verify/column.h"
#include "case.h"
#include "poro.h"
#include "semi_implicit.h"

#define G_ACC 9.81
#define RMS_TOLERANCE 0.02
#define BALANCE_TOLERANCE 0.01
#define SETTLEMENT_TOLERANCE 0.03

static struct case_spec *plate_column(const char *phases, double *q)
{
	struct case_spec *c = NULL;
	struct poro_error err = {0};
	if (case_load_file("tests/cases/terzaghi.json", &c, &err)) {
		printf("INFO cannot load the Terzaghi case: %s\n", err.message);
		return NULL;
	}
	*q = -c->loads[0].traction[1];
	c->load_count = 0;
	c->grid.extent[1] = c->bodies[0].max[1];   /* the grid's top is the column's */
	c->boundaries[FACE_TOP].soil = c->boundaries[FACE_TOP].water = CONSTRAINT_PLATE;
	c->boundaries[FACE_TOP].plate.force = *q * (c->bodies[0].max[0] - c->bodies[0].min[0]);
	c->boundaries[FACE_BOTTOM].drainage = DRAINAGE_DRAINED;
	c->boundaries[FACE_BOTTOM].water = CONSTRAINT_FREE;   /* the water leaves through it */
	c->formulation.phases = !strcmp(phases, "single_point") ? PHASES_SINGLE_POINT : PHASES_DOUBLE_POINT;
	return c;
}

/* Largest |v_y - V| over the top face's nodes with soil (soil and water), m/s. */
static double face_spread(const struct sim *s)
{
	struct semi_implicit *si = semi_implicit_of(s);
	const struct grid *g = &s->grid;
	double worst = 0.0;
	for (idx_t i = 0; i < g->nodes[0]; i++) {
		idx_t I = grid_node(g, i, g->cells[1]);
		if (s->f.mass_s[I] > 0.0)
			worst = fmax(worst, fabs(s->f.v_s[2 * I + 1] - si->plate_velocity[FACE_TOP]));
		if (s->f.mass_w[I] > 0.0)
			worst = fmax(worst, fabs(s->f.v_w[2 * I + 1] - si->plate_velocity[FACE_TOP]));
	}
	return worst;
}

static double terzaghi_rms_from_bottom(const struct sim *s, double H, double Tv, double q)
{
	idx_t n = sim_pressure_point_count(s);
	double *p = malloc(sizeof(double) * (size_t)n), *x = malloc(sizeof(double) * 2 * (size_t)n), sum = 0.0;
	sim_pore_pressure(s, p, x);
	for (idx_t i = 0; i < n; i++) {
		double z = soil_reference_height(s, x[2 * i + 1], H);   /* from the drained bottom */
		double e = p[i] - terzaghi_pressure(z, H, Tv, q);
		sum += e * e;
	}
	free(p);
	free(x);
	return sqrt(sum / n) / q;
}

static void check_column(const char *phases)
{
	const double Tv[2] = {0.1, 0.2};
	double q = 0.0, spread = 0.0, balance = 0.0, settlement = 0.0, rms[2] = {0}, settle_err[2] = {0};
	char name[128];
	struct case_spec *c = plate_column(phases, &q);
	struct sim *s = NULL;
	struct poro_error err = {0};
	int ok = c && !sim_create(&s, c, &err);
	const struct case_material *m = ok ? &c->materials[0] : NULL;
	const double H = ok ? c->bodies[0].max[1] : 1, k = ok ? c->bodies[0].hydraulic_conductivity : 0;
	const double mv = ok ? (1 + m->poisson_ratio) * (1 - 2 * m->poisson_ratio) / ((1 - m->poisson_ratio) * m->youngs_modulus) : 1;
	const double rho_w = ok ? c->fluid.density : 1;
	for (int i = 0; ok && i < 2; i++) {
		long target = lround(time_for_factor(k, Tv[i], rho_w, G_ACC, mv, H) / c->time.dt);
		while (ok && sim_steps_taken(s) < target) {
			ok = !sim_step(s);
			spread = fmax(spread, face_spread(s));
			settlement -= c->time.dt * semi_implicit_of(s)->plate_velocity[FACE_TOP];
		}
		if (ok) {
			rms[i] = terzaghi_rms_from_bottom(s, H, Tv[i], q);
			const double expected = q * mv * H * consolidation_degree(Tv[i]);
			settle_err[i] = fabs(settlement - expected) / expected;
			balance = fmax(balance, fabs(mean_total_vertical_compression(s) / q - 1));
		}
	}
	if (!ok)
		printf("INFO plate column %s failed: %s\n", phases, s ? sim_error(s)->message : err.message);
	printf("INFO plate column %s: Terzaghi rms/q %.5f at Tv 0.1, %.5f at Tv 0.2; settlement %.2f%%, %.2f%% from "
	       "Terzaghi's; face nodes within %.1e m/s of the plate; mean vertical stress within %.2e of q\n", phases,
	       rms[0], rms[1], 100 * settle_err[0], 100 * settle_err[1], spread, balance);
	snprintf(name, sizeof name, "plate_column_%s_runs", phases);
	CHECK(ok, name, "see the INFO line");
	for (int i = 0; i < 2; i++) {
		snprintf(name, sizeof name, "plate_column_%s_terzaghi_rms_below_2pct_Tv%.1f", phases, Tv[i]);
		CHECK(ok && rms[i] <= RMS_TOLERANCE, name, "rms/q %.5f", rms[i]);
	}
	snprintf(name, sizeof name, "plate_column_%s_face_moves_as_one", phases);
	CHECK(ok && spread == 0.0, name, "%.3e m/s", spread);
	snprintf(name, sizeof name, "plate_column_%s_carries_the_force", phases);
	CHECK(ok && balance <= BALANCE_TOLERANCE, name, "%.3e", balance);
	for (int i = 0; i < 2; i++) {
		snprintf(name, sizeof name, "plate_column_%s_settles_as_terzaghi_Tv%.1f", phases, Tv[i]);
		CHECK(ok && settle_err[i] <= SETTLEMENT_TOLERANCE, name, "%.2f%%", 100 * settle_err[i]);
	}
	sim_destroy(&s);
	case_destroy(&c);
}

int main(void)
{
	check_column("double_point");
	check_column("single_point");
	return harness_failed_count ? 1 : 0;
}
