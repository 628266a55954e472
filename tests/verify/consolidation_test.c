/*
 * consolidation_test.c - 000 §5.1 against Terzaghi's closed form.
 *
 *  a. the Table 1 column, double and single point: RMS pore-pressure error over the points that
 *     carry pore pressure, divided by q, at most 2% at Tv = 0.1, 0.2, 0.5, 1.0; and it falls when
 *     the cell size is halved. Each point is compared at the soil's reference height there
 *     (column.h): the theory is written in that coordinate, and the 1 mm settlement alone would
 *     otherwise add about 0.1% of q, more than the discretisation error;
 *  b. the same column drained at top and bottom against Terzaghi with drainage length H/2;
 *  c. k = 1e-9 m/s at the same dt: 2,000 steps, pore pressure within [0, 1.05 q], no NaN, with
 *     the case's weak free-surface condition (free_surface.c); the same formulation meets a at
 *     k = 1e-3 m/s, and the paper's own overshoots (reported and checked to be seen);
 *  e. soil and water mass conserved to 1e-12 relative at every step, and the grid masses
 *     equal the point masses (partition of unity of the transfer);
 *  and the weak free-surface condition on the Table 1 columns (requirement a with the k = 1e-9
 *  case's formulation); the second-difference pressure stabilisation on the k = 1e-9 column with
 *  the consistent projection: the node-to-node pressure pattern gone, the column not drained by
 *  it; and the
 *  interpolated free-surface condition (free_surface.c): the Terzaghi errors with it, and the
 *  k = 1e-9 column's interior held at q for 2,000 steps.
 * Each figure is printed on an INFO line before the check that asserts it.
 */
#include <string.h>

#include "../harness.h"
#include "analytic.h"
#include "column.h"
#include "case.h"
#include "poro.h"

#define CASES "tests/cases/"
#define G 9.81
#define MASS_TOL 1e-12

static int consistent_projection;   /* run columns with formulation.pressure_projection "consistent" */
static int gimp_shape;              /* with formulation.shape "gimp" */
static int interpolated_surface;    /* and with formulation.free_surface "interpolated" */
static int weak_surface;            /* with the formulation of terzaghi_low_permeability.json */

struct column {
	double H, q, k, rho_w, mv, dt;
	int drained_both;      /* drained at the bottom too: drainage length H/2 */
};

static struct column column_of(const struct case_spec *c)
{
	const struct case_material *m = &c->materials[0];
	double nu = m->poisson_ratio, E = m->youngs_modulus;
	struct column col = {
		.H = c->bodies[0].max[1] - c->bodies[0].min[1],
		.q = -c->loads[0].traction[1],
		.k = c->bodies[0].hydraulic_conductivity,
		.rho_w = c->fluid.density,
		.mv = (1 + nu) * (1 - 2 * nu) / ((1 - nu) * E),     /* 000 Eq. 86 */
		.dt = c->time.dt,
		.drained_both = c->boundaries[FACE_BOTTOM].drainage == DRAINAGE_DRAINED,
	};
	return col;
}

/* RMS of (numerical - Terzaghi) over the pressure points, divided by q. */
static double terzaghi_rms(const struct sim *s, const struct column *col, double Tv)
{
	idx_t n = sim_pressure_point_count(s);
	double *p = malloc(sizeof(double) * n), *x = malloc(sizeof(double) * 2 * n);
	sim_pore_pressure(s, p, x);
	double sum = 0.0;
	for (idx_t i = 0; i < n; i++) {
		/* compared at the soil's reference height: Terzaghi's theory is in that coordinate */
		double y = soil_reference_height(s, x[2 * i + 1], col->H), z, Hd;
		if (col->drained_both) {
			Hd = col->H / 2, z = fmin(col->H - y, y);
		} else {
			Hd = col->H, z = col->H - y;
		}
		double e = p[i] - terzaghi_pressure(z, Hd, Tv, col->q);
		sum += e * e;
	}
	free(p);
	free(x);
	return sqrt(sum / n) / col->q;
}

/* Steps s to time t, checking mass conservation after every step. Returns 0 on solver failure. */
static int advance(struct sim *s, double t, double dt, double ms0, double mw0, double *mass_drift, double *grid_err)
{
	long target = lround(t / dt);
	while (sim_steps_taken(s) < target) {
		if (sim_step(s)) {
			printf("INFO solver failed: %s\n", sim_error(s)->message);
			return 0;
		}
		double ds = fabs(sim_soil_mass(s) - ms0) / ms0;
		/* double point: water points in the grid plus those that drained out */
		double dw = sim_is_double_point(s) ? fabs(sim_water_mass(s) + sim_water_outflow_mass(s) - mw0) / mw0 : 0.0;
		*mass_drift = fmax(*mass_drift, fmax(ds, dw));
		double gs, gw, ps, pw;
		sim_grid_masses(s, &gs, &gw, &ps, &pw);
		*grid_err = fmax(*grid_err, fmax(fabs(gs - ps) / ps, fabs(gw - pw) / pw));
	}
	return 1;
}

/* The formulation terzaghi_low_permeability.json runs with (requirement c): the consistent
 * projection with drag in the correction, the second-difference stabilisation and the weak
 * free-surface condition (free_surface.c). */
static void use_low_permeability_formulation(struct case_spec *c)
{
	c->formulation.pressure_projection = PROJECTION_CONSISTENT;
	c->formulation.drag_in_correction = 1;
	c->formulation.pressure_stabilisation = PRESSURE_STABILISATION_SECOND_DIFFERENCE;
	c->formulation.free_surface = FREE_SURFACE_WEAK;
}

/* Runs a column case to each Tv; rms[i] gets the normalised RMS error there. Returns 0 on failure. */
static int run_column(const char *file, double cell_size, double dt, const char *phases, const double *Tv, int nTv,
		      double *rms, double *mass_drift, double *grid_err)
{
	struct case_spec *c = NULL;
	struct poro_error err = {0};
	if (case_load_file(file, &c, &err)) {
		printf("INFO cannot load %s: %s\n", file, err.message);
		return 0;
	}
	if (cell_size > 0)
		c->grid.cell_size = cell_size;
	if (dt > 0)
		c->time.dt = dt;
	if (consistent_projection)
		c->formulation.pressure_projection = PROJECTION_CONSISTENT;
	if (gimp_shape)
		c->formulation.shape = SHAPE_GIMP;
	if (interpolated_surface)
		c->formulation.free_surface = FREE_SURFACE_INTERPOLATED;
	if (weak_surface)
		use_low_permeability_formulation(c);
	if (phases)
		c->formulation.phases = !strcmp(phases, "single_point") ? PHASES_SINGLE_POINT : PHASES_DOUBLE_POINT;
	struct sim *s = NULL;
	int ok = !sim_create(&s, c, &err);
	struct column col = column_of(c);
	double Hd = col.drained_both ? col.H / 2 : col.H;
	double ms0 = ok ? sim_soil_mass(s) : 0, mw0 = ok ? sim_water_mass(s) : 0;
	*mass_drift = *grid_err = 0.0;
	for (int i = 0; ok && i < nTv; i++) {
		double t = time_for_factor(col.k, Tv[i], col.rho_w, G, col.mv, Hd);
		ok = advance(s, t, col.dt, ms0, mw0, mass_drift, grid_err);
		if (ok)
			rms[i] = terzaghi_rms(s, &col, Tv[i]);
	}
	sim_destroy(&s);
	case_destroy(&c);
	return ok;
}

static void check_terzaghi(const char *label, const char *file, const char *phases)
{
	const double Tv[4] = {0.1, 0.2, 0.5, 1.0};
	double rms[4] = {0}, fine[4] = {0}, drift, grid_err, drift_fine, grid_fine;
	char name[160];
	int ok = run_column(file, 0, 0, phases, Tv, 4, rms, &drift, &grid_err);
	snprintf(name, sizeof name, "terzaghi_%s_runs", label);
	CHECK(ok, name, "run failed");
	for (int i = 0; i < 4; i++) {
		printf("INFO terzaghi %s h=0.025 Tv=%.1f rms/q=%.5f\n", label, Tv[i], rms[i]);
		snprintf(name, sizeof name, "terzaghi_%s_rms_below_2pct_Tv%.1f", label, Tv[i]);
		CHECK(ok && rms[i] <= 0.02, name, "rms/q = %.5f", rms[i]);
	}
	snprintf(name, sizeof name, "terzaghi_%s_mass_conserved", label);
	printf("INFO terzaghi %s max relative mass drift %.3e, grid-vs-point mass %.3e\n", label, drift, grid_err);
	CHECK(ok && drift <= MASS_TOL && grid_err <= MASS_TOL, name, "drift %.3e grid %.3e", drift, grid_err);

	/* the soil predictor is explicit: its stable step shrinks with h, so halve dt with h. The
	 * comparison uses Tv = 0.1 and 0.2, where the pressure gradients are steepest and the
	 * discretisation error largest; running on to Tv = 1 at h/2 would cost 8 times the coarse
	 * run for the least informative part. */
	ok = run_column(file, 0.0125, 0.5e-4, phases, Tv, 2, fine, &drift_fine, &grid_fine);
	double coarse_mean = 0, fine_mean = 0;
	for (int i = 0; i < 2; i++) {
		printf("INFO terzaghi %s h=0.0125 Tv=%.1f rms/q=%.5f\n", label, Tv[i], fine[i]);
		coarse_mean += rms[i] / 2, fine_mean += fine[i] / 2;
	}
	snprintf(name, sizeof name, "terzaghi_%s_error_falls_with_h", label);
	CHECK(ok && fine_mean < coarse_mean, name, "mean rms/q at Tv 0.1-0.2 %.5f (h) vs %.5f (h/2)", coarse_mean, fine_mean);
}

static void check_double_drained(void)
{
	const double Tv[4] = {0.1, 0.2, 0.5, 1.0};
	double rms[4] = {0}, drift, grid_err;
	int ok = run_column(CASES "terzaghi_double_drained.json", 0, 0, NULL, Tv, 4, rms, &drift, &grid_err);
	for (int i = 0; i < 4; i++) {
		char name[128];
		printf("INFO terzaghi drained top and bottom Tv=%.1f rms/q=%.5f\n", Tv[i], rms[i]);
		snprintf(name, sizeof name, "terzaghi_double_drained_rms_below_2pct_Tv%.1f", Tv[i]);
		CHECK(ok && rms[i] <= 0.02, name, "rms/q = %.5f", rms[i]);
	}
}

/* The k = 1e-9 column for 2,000 steps: *pmin, *pmax the extreme point pressures over q, *dt the
 * step. With `paper` the paper's own formulation (Laplacian, Eq. 65 without drag, p = 0 on the
 * nodes next to the surface) replaces the case's. Returns 0 on failure. */
static int run_low_permeability(int paper, double *pmin, double *pmax, double *dt)
{
	struct case_spec *c = NULL;
	struct poro_error err = {0};
	struct sim *s = NULL;
	int ok = !case_load_file(CASES "terzaghi_low_permeability.json", &c, &err);
	if (ok && paper) {
		c->formulation.pressure_projection = PROJECTION_LAPLACIAN;
		c->formulation.drag_in_correction = 0;
		c->formulation.pressure_stabilisation = PRESSURE_STABILISATION_NONE;
		c->formulation.free_surface = FREE_SURFACE_NODES;
	}
	ok = ok && !sim_create(&s, c, &err);
	const double q = ok ? -c->loads[0].traction[1] : 1;
	*pmin = INFINITY, *pmax = -INFINITY, *dt = ok ? c->time.dt : 0;
	long steps = 0;
	idx_t n = ok ? sim_pressure_point_count(s) : 0;
	double *p = malloc(sizeof *p * (size_t)(n + 1));
	while (ok && steps < 2000) {
		ok = !sim_step(s) && p;
		steps++;
		if (!ok)
			break;
		sim_pore_pressure(s, p, NULL);
		for (idx_t i = 0; i < n; i++) {
			if (!isfinite(p[i]))
				ok = 0;
			*pmin = fmin(*pmin, p[i] / q), *pmax = fmax(*pmax, p[i] / q);
		}
	}
	if (!ok)
		printf("INFO k=1e-9 column failed after %ld steps: %s\n", steps, s ? sim_error(s)->message : err.message);
	free(p);
	sim_destroy(&s);
	case_destroy(&c);
	return ok;
}

/* Requirement c on the case as written. The paper's formulation runs the same 2,000 steps but
 * overshoots from the first step (the pressure force sees only part of the drop to zero at the
 * nodes next to the surface; docs/numerics.md, "Free surface"): checked to be seen, so that the
 * bound above is the weak condition's doing. The same formulation at k = 1e-3 m/s and the same
 * dt meets requirement a (check_weak_surface). */
#define PAPER_OVERSHOOT_MIN 1.2   /* q (measured 1.39) */
static void check_low_permeability(void)
{
	double pmin = 0, pmax = 0, dt = 0, paper_min = 0, paper_max = 0, paper_dt = 0;
	int ok = run_low_permeability(0, &pmin, &pmax, &dt);
	int paper_ok = run_low_permeability(1, &paper_min, &paper_max, &paper_dt);
	printf("INFO k=1e-9 dt=%.1e: 2000 steps, pore pressure in [%.4f, %.4f] q; the paper's formulation "
	       "(Laplacian, nodal surface) [%.4f, %.4f] q\n", dt, pmin, pmax, paper_min, paper_max);
	CHECK(ok, "low_permeability_runs_2000_steps", "see the INFO line");
	CHECK(ok && pmin >= 0, "low_permeability_pressure_non_negative", "minimum %.4f q", pmin);
	CHECK(ok && pmax <= 1.05, "low_permeability_pressure_at_most_1.05q", "maximum %.4f q", pmax);
	CHECK(paper_ok && paper_min >= 0, "low_permeability_paper_formulation_runs_2000_steps",
	      "minimum %.4f q", paper_min);
	CHECK(paper_ok && paper_max >= PAPER_OVERSHOOT_MIN, "low_permeability_paper_formulation_overshoot_seen",
	      "maximum %.4f q (the measure must see it)", paper_max);
}

/* Requirement a with the low-permeability case's formulation (use_low_permeability_formulation):
 * the Table 1 columns, double and single point, at k = 1e-3 m/s and the dt of the k = 1e-9 case,
 * within 2% and better at h/2. */
static void check_weak_surface(void)
{
	const double Tv[4] = {0.1, 0.2, 0.5, 1.0};
	const char *files[2] = {CASES "terzaghi.json", CASES "terzaghi_single_point.json"};
	const char *labels[2] = {"double_point", "single_point"};
	weak_surface = 1;
	for (int f = 0; f < 2; f++) {
		double rms[4] = {0}, fine[2] = {0}, drift, grid_err, worst = 0, coarse_mean = 0, fine_mean = 0;
		int ok = run_column(files[f], 0, 0, NULL, Tv, 4, rms, &drift, &grid_err) &&
			 run_column(files[f], 0.0125, 0.5e-4, NULL, Tv, 2, fine, &drift, &grid_err);
		for (int i = 0; i < 4; i++) {
			printf("INFO terzaghi %s weak free surface Tv=%.1f rms/q=%.5f (h)\n", labels[f], Tv[i], rms[i]);
			worst = fmax(worst, rms[i]);
		}
		for (int i = 0; i < 2; i++) {
			printf("INFO terzaghi %s weak free surface Tv=%.1f rms/q=%.5f (h/2)\n", labels[f], Tv[i], fine[i]);
			coarse_mean += rms[i] / 2, fine_mean += fine[i] / 2;
		}
		char name[128];
		snprintf(name, sizeof name, "terzaghi_%s_weak_surface_rms_below_2pct", labels[f]);
		CHECK(ok && worst <= 0.02, name, "worst rms/q %.5f", worst);
		snprintf(name, sizeof name, "terzaghi_%s_weak_surface_error_falls_with_h", labels[f]);
		CHECK(ok && fine_mean < coarse_mean, name, "mean rms/q at Tv 0.1-0.2 %.5f (h) vs %.5f (h/2)",
		      coarse_mean, fine_mean);
	}
	weak_surface = 0;
}

/* The k = 1e-9 column under the consistent projection with drag in the correction, with or
 * without the second-difference stabilisation and the interpolated free surface. Returns 1 and
 * the case and simulation, or 0 with err set. */
static int create_low_permeability_consistent(int stabilised, int interpolated, struct case_spec **c,
					      struct sim **s, struct poro_error *err)
{
	if (case_load_file(CASES "terzaghi_low_permeability.json", c, err))
		return 0;
	(*c)->formulation.pressure_projection = PROJECTION_CONSISTENT;
	(*c)->formulation.drag_in_correction = 1;
	(*c)->formulation.pressure_stabilisation = stabilised ? PRESSURE_STABILISATION_SECOND_DIFFERENCE
							      : PRESSURE_STABILISATION_NONE;
	(*c)->formulation.free_surface = interpolated ? FREE_SURFACE_INTERPOLATED : FREE_SURFACE_NODES;
	return !sim_create(s, *c, err);
}

/* The k = 1e-9 column with the consistent projection and drag in the correction, 2,000 steps:
 * *wiggle = the largest second difference of the row means of the pore pressure between point
 * rows below the top STABILISATION_MARGIN_CELLS cells (a smooth profile gives about 0, the
 * node-to-node mode +-A gives about 2A), *stress = the soil's mean sigma'_yy, both over q. */
/* The penalty spares the nodes within support - 1 = 2 of the drained top node, and a point's
 * quadratic B-splines reach about 1.5 cells: rows in the top 4 cells still see spared nodes. */
#define STABILISATION_MARGIN_CELLS 4
static int run_low_permeability_consistent(int stabilised, double *wiggle, double *stress)
{
	struct case_spec *c = NULL;
	struct poro_error err = {0};
	struct sim *s = NULL;
	int ok = create_low_permeability_consistent(stabilised, 0, &c, &s, &err);
	for (long k = 0; ok && k < 2000; k++)
		ok = !sim_step(s);
	if (!ok) {
		printf("INFO k=1e-9 consistent column failed: %s\n", s ? sim_error(s)->message : err.message);
		sim_destroy(&s);
		case_destroy(&c);
		return 0;
	}
	const double q = -c->loads[0].traction[1], h = c->grid.cell_size;
	const double spacing = h / c->bodies[0].particles_per_cell, top = c->bodies[0].max[1];
	const int rows = (int)lround((top - c->bodies[0].min[1]) / spacing);
	idx_t n = sim_pressure_point_count(s);
	double *p = malloc(sizeof *p * (size_t)n), *xy = malloc(sizeof *xy * 2 * (size_t)n);
	double *sum = calloc((size_t)rows, sizeof *sum), *count = calloc((size_t)rows, sizeof *count);
	ok = p && xy && sum && count;
	if (ok)
		sim_pore_pressure(s, p, xy);
	for (idx_t i = 0; ok && i < n; i++) {
		int r = (int)floor((xy[2 * i + 1] - c->bodies[0].min[1]) / spacing);
		if (r >= 0 && r < rows)
			sum[r] += p[i], count[r]++;
	}
	*wiggle = 0;
	const int last = rows - 1 - (int)lround(STABILISATION_MARGIN_CELLS * h / spacing);
	for (int r = 1; ok && r < last; r++)
		if (count[r - 1] && count[r] && count[r + 1])
			*wiggle = fmax(*wiggle, fabs(sum[r - 1] / count[r - 1] - 2 * sum[r] / count[r] +
						     sum[r + 1] / count[r + 1]) / q);
	const struct particles *soil = sim_soil(s);
	double syy = 0;
	for (idx_t i = 0; i < soil->n; i++)
		syy += soil->stress[4 * i + 1];
	*stress = syy / (double)soil->n / q;
	free(p), free(xy), free(sum), free(count);
	sim_destroy(&s);
	case_destroy(&c);
	return ok;
}

/* The second-difference pressure stabilisation (pressure_stabilisation.c) on the k = 1e-9 column:
 * the node-to-node pattern the consistent projection leaves is gone below the drained top, and
 * the column does not consolidate faster for it (the penalty lets no water through a pressure
 * that is smooth along the grid lines). */
#define WIGGLE_WITHOUT_MIN 0.1           /* q: the pattern is there without (measured 0.25) */
#define WIGGLE_WITH_MAX 0.01             /* q: and gone with (measured 0.0008) */
#define LEAK_MAX 0.002                   /* q: change of the mean sigma'_yy (measured 0.0002) */
static void check_pressure_stabilisation(void)
{
	double wiggle_off = 0, wiggle_on = 0, stress_off = 0, stress_on = 0;
	int ok = run_low_permeability_consistent(0, &wiggle_off, &stress_off) &&
		 run_low_permeability_consistent(1, &wiggle_on, &stress_on);
	printf("INFO k=1e-9 consistent projection with drag, 2,000 steps: largest second difference of the pore "
	       "pressure between point rows %.4f q without, %.4f q with the second-difference stabilisation; mean "
	       "soil sigma'_yy %.4f q without, %.4f q with\n", wiggle_off, wiggle_on, stress_off, stress_on);
	CHECK(ok && wiggle_off > WIGGLE_WITHOUT_MIN, "low_permeability_consistent_shows_2h_pressure_pattern",
	      "second difference %.4f q (the measure must see the pattern)", wiggle_off);
	CHECK(ok && wiggle_on < WIGGLE_WITH_MAX, "pressure_stabilisation_removes_2h_pressure_pattern",
	      "second difference %.4f q", wiggle_on);
	CHECK(ok && fabs(stress_on - stress_off) < LEAK_MAX, "pressure_stabilisation_does_not_drain_the_column",
	      "mean sigma'_yy %.4f q with, %.4f q without", stress_on, stress_off);
}

/* uGIMP (shape.h) on the Table 1 columns, double and single point: within 2% RMS of q at every
 * Tv. Its gradient weights at the walls used to be the derivative of the clipped weights, which
 * put a quarter of a wall's reaction on the node next to it, and the single-point column inverted
 * a corner point at step 45 (docs/numerics.md, "Shape functions at the grid edges"). */
static void check_gimp(void)
{
	const double Tv[4] = {0.1, 0.2, 0.5, 1.0};
	const char *files[2] = {CASES "terzaghi.json", CASES "terzaghi_single_point.json"};
	const char *labels[2] = {"double_point", "single_point"};
	gimp_shape = 1;
	for (int f = 0; f < 2; f++) {
		double rms[4] = {0}, drift, grid_err, worst = 0;
		const int ok = run_column(files[f], 0, 0, NULL, Tv, 4, rms, &drift, &grid_err);
		for (int i = 0; i < 4; i++) {
			printf("INFO terzaghi %s gimp Tv=%.1f rms/q=%.5f\n", labels[f], Tv[i], rms[i]);
			worst = fmax(worst, rms[i]);
		}
		char name[96];
		snprintf(name, sizeof name, "terzaghi_%s_gimp_rms_below_2pct", labels[f]);
		CHECK(ok && worst <= 0.02, name, "worst rms/q %.5f", worst);
	}
	gimp_shape = 0;
}

/* The consistent projection on the single-point column, with the nodal or the interpolated
 * free-surface condition: errors and their fall with h. */
static void check_consistent_projection(int interpolated)
{
	const double Tv[4] = {0.1, 0.2, 0.5, 1.0};
	const char *label = interpolated ? "consistent projection, interpolated free surface" : "consistent projection";
	const char *tag = interpolated ? "terzaghi_consistent_interpolated_surface" : "terzaghi_consistent_projection";
	double rms[4] = {0}, fine[4] = {0}, drift, grid_err;
	consistent_projection = 1, interpolated_surface = interpolated;
	int ok = run_column(CASES "terzaghi_single_point.json", 0, 0, NULL, Tv, 4, rms, &drift, &grid_err) &&
		 run_column(CASES "terzaghi_single_point.json", 0.0125, 0.5e-4, NULL, Tv, 2, fine, &drift, &grid_err);
	consistent_projection = interpolated_surface = 0;
	double worst = 0, coarse_mean = 0, fine_mean = 0;
	for (int i = 0; i < 4; i++) {
		printf("INFO terzaghi single_point %s Tv=%.1f rms/q=%.5f (h)\n", label, Tv[i], rms[i]);
		worst = fmax(worst, rms[i]);
	}
	for (int i = 0; i < 2; i++) {
		printf("INFO terzaghi single_point %s Tv=%.1f rms/q=%.5f (h/2)\n", label, Tv[i], fine[i]);
		coarse_mean += rms[i] / 2, fine_mean += fine[i] / 2;
	}
	char name[128];
	snprintf(name, sizeof name, "%s_rms_below_2pct", tag);
	CHECK(ok && worst <= 0.02, name, "worst rms/q %.5f", worst);
	snprintf(name, sizeof name, "%s_error_falls_with_h", tag);
	CHECK(ok && fine_mean < coarse_mean, name, "mean rms/q at Tv 0.1-0.2 %.5f (h) vs %.5f (h/2)", coarse_mean,
	      fine_mean);
}

/* The k = 1e-9 column under the consistent projection with drag, the second-difference
 * stabilisation and the interpolated free-surface condition (free_surface.c), 2,000 steps: the
 * mean pressure of the middle half of the column from the second step on (the first is the
 * sudden load's, within 3%: free_surface_test), and the range over all points. The middle stays
 * at q; within three cells of the surface the pressure still swings (up to about 1.46 q), which
 * requirement c's bound on every point does not allow (the case uses the weak condition). */
#define LOW_K_INTERIOR_TOLERANCE 0.01   /* q (measured 0.997-1.003) */
static void check_low_permeability_interpolated(void)
{
	struct case_spec *c = NULL;
	struct poro_error err = {0};
	struct sim *s = NULL;
	int ok = create_low_permeability_consistent(1, 1, &c, &s, &err);
	const double q = ok ? -c->loads[0].traction[1] : 1, H = ok ? c->bodies[0].max[1] : 1;
	double mid_min = INFINITY, mid_max = -INFINITY, pmin = INFINITY, pmax = -INFINITY;
	idx_t n = ok ? sim_pressure_point_count(s) : 0;
	double *p = malloc(sizeof *p * (size_t)(n + 1)), *xy = malloc(sizeof *xy * 2 * (size_t)(n + 1));
	for (long k = 0; ok && k < 2000; k++) {
		ok = !sim_step(s) && p && xy;
		if (!ok)
			break;
		sim_pore_pressure(s, p, xy);
		double sum = 0;
		idx_t count = 0;
		for (idx_t i = 0; i < n; i++) {
			if (!isfinite(p[i]))
				ok = 0;
			pmin = fmin(pmin, p[i]), pmax = fmax(pmax, p[i]);
			if (xy[2 * i + 1] > 0.25 * H && xy[2 * i + 1] < 0.75 * H)
				sum += p[i], count++;
		}
		if (k > 0)
			mid_min = fmin(mid_min, sum / count / q), mid_max = fmax(mid_max, sum / count / q);
	}
	printf("INFO k=1e-9 consistent projection with drag, stabilisation and the interpolated free surface, 2,000 "
	       "steps: mean pore pressure of the middle half %.4f-%.4f q (steps 2-2000); all points %.4f-%.4f q\n",
	       mid_min, mid_max, pmin / q, pmax / q);
	if (!ok)
		printf("INFO the run failed: %s\n", s ? sim_error(s)->message : err.message);
	CHECK(ok && fabs(mid_min - 1) <= LOW_K_INTERIOR_TOLERANCE && fabs(mid_max - 1) <= LOW_K_INTERIOR_TOLERANCE,
	      "low_permeability_interpolated_surface_interior_at_q", "%.4f-%.4f q", mid_min, mid_max);
	CHECK(ok && pmin >= 0, "low_permeability_interpolated_surface_pressure_non_negative", "minimum %.4f q",
	      pmin / q);
	free(p), free(xy);
	sim_destroy(&s);
	case_destroy(&c);
}

/* With an argument, runs only the named group (double_point, single_point, drained, low_k,
 * weak_surface, consistent, stabilisation, free_surface). */
int main(int argc, char **argv)
{
	const char *only = argc > 1 ? argv[1] : NULL;
#define WANT(group) (!only || !strcmp(only, group))
	if (WANT("double_point"))
		check_terzaghi("double_point", CASES "terzaghi.json", NULL);
	if (WANT("single_point"))
		check_terzaghi("single_point", CASES "terzaghi_single_point.json", NULL);
	if (WANT("drained"))
		check_double_drained();
	if (WANT("low_k"))
		check_low_permeability();
	if (WANT("weak_surface"))
		check_weak_surface();
	if (WANT("consistent"))
		check_consistent_projection(0);
	if (WANT("free_surface")) {
		check_consistent_projection(1);
		check_low_permeability_interpolated();
	}
	if (WANT("stabilisation"))
		check_pressure_stabilisation();
	if (WANT("gimp"))
		check_gimp();
	HARNESS_EXIT();
}
