/*
 * column_family_test.c - Terzaghi consolidation on a family of columns (000 §5.1 generalised):
 * the loaded top on a grid line and a twentieth, a quarter, a half and three quarters of a cell
 * below one, heights 0.7-1.3 m, Young's moduli 3-30 MPa, Poisson's ratios 0 and 0.3,
 * conductivities 1e-4 to 1e-3 m/s, drained at the top or at top and bottom, single and double
 * point, each with the options a case gets when it names only geometry, materials, loads and time
 * (the formulation of tests/cases/terzaghi.json: the paper's Laplacian and p = 0 on the nodes
 * next to the surface).
 *
 * Each member checks, against Terzaghi's closed form (analytic.h) at Tv = 0.05, 0.1 and 0.2, where
 * its drained skin is at most SKIN_RATIO_MAX of the diffusion length (below; reported as XFAIL
 * at earlier Tv when it misses):
 *  - the RMS pore-pressure error over the pressure points, over q, at most 2% (each point at the
 *    soil's reference height there, column.h);
 *  - the settlement of the top row of soil points within 2% of terzaghi_settlement() at their
 *    reference height;
 * and that the points fill the column to its top: their volumes sum to width x H (a column whose
 * top lay between two rows of seeds used to be seeded short, docs/numerics.md, "Columns whose top
 * cuts a cell"). Members whose top fills its cell to a half or three quarters stopped within 35
 * steps before (an inverted point under the top row).
 *
 * The nodal condition resolves the drained face to a node: a top cell filled to f < 0.9 of it is
 * not counted full (free_surface.c), and p = 0 sits on its lower nodes, a skin f h thick inside
 * the column. The errors it adds scale with f h / (Hd sqrt(Tv)), the skin's share of the
 * diffusion length.
 *
 * The comparison holds where consolidation is slow against the column's inertia. Drained at the
 * base, the whole column can move into the drain, and with k = 1e-3 m/s a 0.7 m column reaches
 * Tv = 0.1 within 120 steps of the sudden load, while its skeleton is still ringing: the
 * inertial check runs that column twice, as given (it departs from Terzaghi) and with its
 * densities and conductivity a tenth (the same consolidation coefficient and drag, a tenth of the
 * inertia; dt follows the faster skeleton wave), which meets Terzaghi.
 */
#include <string.h>

#include "../harness.h"
#include "analytic.h"
#include "column.h"
#include "case.h"
#include "poro.h"

#define BASE_CASE "tests/cases/terzaghi.json"
#define G 9.81
#define CELL 0.025
#define WIDTH_CELLS 4
#define RMS_TOL 0.02
#define SETTLEMENT_TOL 0.02
/* Times at which a drained skin (skin_ratio) is more than this share of the diffusion length are
 * reported, not asserted (docs/numerics.md, "Columns whose top cuts a cell"). */
#define SKIN_RATIO_MAX 0.06
/* dt at most this fraction of the time a skeleton wave takes to cross a cell (the soil predictor
 * is explicit; the Table 1 column runs at 0.27), and at most the Table 1 column's 1e-4 s */
#define CFL_FRACTION 0.3
#define DT_MAX 1e-4

struct member {
	double cells;     /* cells from the base up to the grid line at or above the top */
	double offset;    /* how far the top lies below that grid line, in cells */
	double E, nu, k;  /* Pa, -, m/s */
	int drained_both; /* drained at the bottom too (drainage length H/2) */
	int single_point;
};

static const struct member members[] = {
	{ 28, 0.00, 1.0e7, 0.0, 1.0e-3, 0, 0 },
	{ 40, 0.25, 1.0e7, 0.0, 1.0e-3, 0, 1 }, /* the reported columns: top 0.99375 and 0.9875 m */
	{ 40, 0.50, 1.0e7, 0.0, 1.0e-3, 0, 0 },
	{ 28, 0.50, 3.0e6, 0.3, 1.0e-3, 0, 1 },
	{ 28, 0.75, 3.0e7, 0.0, 5.0e-4, 0, 0 },
	{ 52, 0.05, 1.0e7, 0.3, 1.0e-3, 0, 1 },
	{ 52, 0.25, 1.0e7, 0.0, 1.0e-3, 0, 0 },
	{ 40, 0.75, 1.0e7, 0.3, 3.0e-4, 0, 1 },
	{ 52, 0.50, 1.0e7, 0.0, 1.0e-4, 1, 1 },
	{ 28, 0.25, 3.0e6, 0.3, 1.0e-4, 1, 0 },
	{ 28, 0.75, 1.0e7, 0.3, 1.0e-4, 1, 0 },
	{ 40, 0.00, 3.0e7, 0.0, 3.0e-4, 1, 1 },
};
#define MEMBER_COUNT (int)(sizeof members / sizeof members[0])

static const double Tv_checks[] = { 0.05, 0.1, 0.2 };
#define TV_COUNT (int)(sizeof Tv_checks / sizeof Tv_checks[0])

struct column {
	double H, width, q, k, rho_w, mv, Hd;
	int drained_both;
};

/* 000 Eq. 86 */
static double compressibility(double E, double nu)
{
	return (1 + nu) * (1 - 2 * nu) / ((1 - nu) * E);
}

/* The base case changed into member m, its densities and conductivity scaled by `inertia` (the
 * drag n^2 rho_w g / k and c_v stay as they are). NULL (with a message) when it cannot be loaded. */
static struct case_spec *member_case(const struct member *m, double inertia, struct column *col)
{
	struct case_spec *c = NULL;
	struct poro_error err = { 0 };
	if (case_load_file(BASE_CASE, &c, &err)) {
		printf("INFO cannot load %s: %s\n", BASE_CASE, err.message);
		return NULL;
	}
	const double H = (m->cells - m->offset) * CELL;
	c->grid.cell_size = CELL;
	c->grid.extent[0] = WIDTH_CELLS * CELL;
	c->grid.extent[1] = (m->cells + 2) * CELL;
	c->bodies[0].max[0] = WIDTH_CELLS * CELL;
	c->bodies[0].max[1] = H;
	c->bodies[0].hydraulic_conductivity = m->k * inertia;
	c->materials[0].density *= inertia;
	c->fluid.density *= inertia;
	c->materials[0].youngs_modulus = m->E;
	c->materials[0].poisson_ratio = m->nu;
	c->formulation.phases = m->single_point ? PHASES_SINGLE_POINT : PHASES_DOUBLE_POINT;
	if (m->drained_both) {
		c->boundaries[FACE_BOTTOM].water = CONSTRAINT_FREE;
		c->boundaries[FACE_BOTTOM].drainage = DRAINAGE_DRAINED;
	}
	const double n = c->bodies[0].porosity, mv = compressibility(m->E, m->nu);
	const double rho = (1 - n) * c->materials[0].density + n * c->fluid.density;
	c->time.dt = fmin(DT_MAX, CFL_FRACTION * CELL * sqrt(rho * mv)); /* wave speed sqrt(1 / (m_v rho)) */
	*col = (struct column){
		.H = H,
		.width = WIDTH_CELLS * CELL,
		.q = -c->loads[0].traction[1],
		.k = m->k * inertia,
		.rho_w = c->fluid.density,
		.mv = mv,
		.Hd = m->drained_both ? H / 2 : H,
		.drained_both = m->drained_both,
	};
	return c;
}

/* A top cell filled to f < 0.9 is not counted full under the nodal condition with the Laplacian
 * (free_surface.c), so its lower nodes hold p = 0, f h inside the column: the drained face lies
 * that much low. Its share of the diffusion length Hd sqrt(Tv) at Tv; 0 for a top that fills its
 * cell to 0.9 or more. */
static double skin_ratio(const struct member *m, const struct column *col, double Tv)
{
	const double fill = 1 - m->offset;
	return fill < 0.9 ? fill * CELL / (col->Hd * sqrt(Tv)) : 0.0;
}

/* RMS of (numerical - Terzaghi) over the pressure points, over q. */
static double pressure_rms(const struct sim *s, const struct column *col, double Tv)
{
	idx_t n = sim_pressure_point_count(s);
	double *p = malloc(sizeof(double) * n), *x = malloc(sizeof(double) * 2 * n), sum = 0.0;
	sim_pore_pressure(s, p, x);
	for (idx_t i = 0; i < n; i++) {
		double y = soil_reference_height(s, x[2 * i + 1], col->H);
		double z = col->drained_both ? fmin(col->H - y, y) : col->H - y;
		double e = p[i] - terzaghi_pressure(z, col->Hd, Tv, col->q);
		sum += e * e;
	}
	free(p), free(x);
	return sqrt(sum / n) / col->q;
}

/* Relative error of the top row's mean settlement against Terzaghi at its reference height. */
static double settlement_error(const struct sim *s, const struct column *col, double Tv)
{
	const struct particles *p = sim_soil(s);
	double top = -INFINITY, u = 0.0;
	int count = 0;
	for (idx_t q = 0; q < p->n; q++)
		top = fmax(top, p->x0[2 * q + 1]);
	for (idx_t q = 0; q < p->n; q++)
		if (p->x0[2 * q + 1] == top)
			u += p->x0[2 * q + 1] - p->x[2 * q + 1], count++;
	double closed = terzaghi_settlement(top, col->H, Tv, col->q, col->mv, col->drained_both);
	return (u / count - closed) / closed;
}

static double volume_sum(const struct sim *s)
{
	const struct particles *p = sim_soil(s);
	double v = 0.0;
	for (idx_t q = 0; q < p->n; q++)
		v += p->volume0[q];
	return v;
}

static void check_member(int i)
{
	const struct member *m = &members[i];
	struct column col;
	char label[160], name[220];
	snprintf(label, sizeof label, "column_family_H%.5f_E%.0e_nu%.1f_k%.0e_%s_%s", (m->cells - m->offset) * CELL,
		 m->E, m->nu, m->k, m->drained_both ? "drained_both" : "drained_top",
		 m->single_point ? "single_point" : "double_point");
	struct case_spec *c = member_case(m, 1.0, &col);
	struct sim *s = NULL;
	struct poro_error err = { 0 };
	int ok = c && !sim_create(&s, c, &err);
	if (c && !ok)
		printf("INFO %s: %s\n", label, err.message);
	double t0 = harness_wall_seconds();
	if (ok) {
		double filled = volume_sum(s) / (col.width * col.H) - 1;
		snprintf(name, sizeof name, "%s_seeded_to_its_top", label);
		CHECK(fabs(filled) <= 1e-12, name, "point volumes over width x H - 1 = %.3e", filled);
	}
	double worst_rms = 0, worst_settlement = 0;
	int asserted = 0;
	for (int j = 0; ok && j < TV_COUNT; j++) {
		long target = lround(time_for_factor(col.k, Tv_checks[j], col.rho_w, G, col.mv, col.Hd) / c->time.dt);
		while (ok && sim_steps_taken(s) < target)
			if (sim_step(s)) {
				printf("INFO %s failed: %s\n", label, sim_error(s)->message);
				ok = 0;
			}
		if (!ok)
			break;
		double Tv = time_factor(col.k, sim_time(s), col.rho_w, G, col.mv, col.Hd);
		double rms = pressure_rms(s, &col, Tv), se = settlement_error(s, &col, Tv),
		       skin = skin_ratio(m, &col, Tv);
		printf("INFO %s top %.2f cell below a grid line, Tv=%.3f: rms/q=%.5f settlement error %+.3f%%, drained "
		       "skin %.3f of the diffusion length\n",
		       label, m->offset, Tv, rms, 100 * se, skin);
		if (skin > SKIN_RATIO_MAX) {
			if (rms > RMS_TOL || fabs(se) > SETTLEMENT_TOL)
				printf("XFAIL %s_Tv%.2f_within_2pct: rms/q %.5f, settlement error %.3f%%: the nodal condition "
				       "holds p = 0 on the lower nodes of the top cell, filled to %.2f, a skin %.3f of the "
				       "diffusion length (docs/numerics.md, \"Columns whose top cuts a cell\")\n",
				       label, Tv, rms, 100 * se, 1 - m->offset, skin);
			continue;
		}
		asserted++;
		worst_rms = fmax(worst_rms, rms), worst_settlement = fmax(worst_settlement, fabs(se));
	}
	printf("INFO %s: %ld steps of %.2e s in %.2f s\n", label, s ? sim_steps_taken(s) : 0L, c ? c->time.dt : 0,
	       harness_wall_seconds() - t0);
	snprintf(name, sizeof name, "%s_runs", label);
	CHECK(ok, name, "run failed");
	if (asserted) {
		snprintf(name, sizeof name, "%s_rms_below_2pct", label);
		CHECK(ok && worst_rms <= RMS_TOL, name, "worst rms/q = %.5f", worst_rms);
		snprintf(name, sizeof name, "%s_settlement_within_2pct", label);
		CHECK(ok && worst_settlement <= SETTLEMENT_TOL, name, "worst settlement error %.3f%%",
		      100 * worst_settlement);
	}
	sim_destroy(&s);
	case_destroy(&c);
}

/* The 0.7 m column drained at both ends with k = 1e-3 m/s at Tv = 0.1, with its inertia as given
 * and a tenth of it (file comment): rms/q, or -1 when the run failed. */
static double inertial_rms(double inertia)
{
	const struct member m = { 28, 0.0, 1.0e7, 0.0, 1.0e-3, 1, 1 };
	struct column col;
	struct case_spec *c = member_case(&m, inertia, &col);
	if (!c)
		return -1;
	struct sim *s = NULL;
	struct poro_error err = { 0 };
	double rms = -1;
	if (!sim_create(&s, c, &err)) {
		long target = lround(time_for_factor(col.k, 0.1, col.rho_w, G, col.mv, col.Hd) / c->time.dt);
		int ok = 1;
		while (ok && sim_steps_taken(s) < target)
			ok = !sim_step(s);
		if (ok)
			rms = pressure_rms(s, &col, time_factor(col.k, sim_time(s), col.rho_w, G, col.mv, col.Hd));
	}
	sim_destroy(&s);
	case_destroy(&c);
	return rms;
}

static void check_inertia(void)
{
	double heavy = inertial_rms(1.0), light = inertial_rms(0.1);
	printf("INFO 0.7 m column drained at both ends, k = 1e-3 m/s, Tv 0.1: rms/q %.5f as given, %.5f with a "
	       "tenth of its inertia\n",
	       heavy, light);
	CHECK(light >= 0 && light <= RMS_TOL, "column_family_quasi_static_meets_terzaghi", "rms/q %.5f", light);
	CHECK(heavy > 2 * RMS_TOL, "column_family_inertia_seen_when_consolidation_is_fast", "rms/q %.5f", heavy);
}

/* With an argument, runs only member N (0-based) or the inertial check ("inertia"). */
int main(int argc, char **argv)
{
	const char *only = argc > 1 ? argv[1] : NULL;
	for (int i = 0; i < MEMBER_COUNT; i++)
		if (!only || (strcmp(only, "inertia") && atoi(only) == i))
			check_member(i);
	if (!only || !strcmp(only, "inertia"))
		check_inertia();
	HARNESS_EXIT();
}
