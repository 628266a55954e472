/*
 * mandel_test.c - Mandel's problem against its closed form (solver/verify/analytic.h).
 *
 * The closed form is checked first, against facts it must meet and against an independent
 * solution of the same equations. Under a rigid smooth plate the vertical strain eps(t) is uniform;
 * the free drained sides leave sigma_xx = 0 everywhere (it is uniform in x by equilibrium and zero
 * at x = a), so the effective stress sigma'_xx = p (compression positive) and, with lambda and G
 * the drained Lame constants, the volumetric strain is e = (p + 2 G eps) / (lambda + 2 G). Darcy
 * flow with incompressible constituents gives de/dt = kappa p_xx, so
 *     p_t = c p_xx - 2 G eps_t,   c = kappa (lambda + 2 G),
 * and the plate's force F on the half width a fixes eps:
 *     eps = (2 G int_0^a p dx - F (lambda + 2 G)) / (4 G (lambda + G) a)   (eps < 0 in compression).
 * At t = 0+ no water has moved (e = 0, p = -2 G eps), and the force balance gives p0 = F / (2 a),
 * B (1 + nu_u) F / (3 a) with B = 1, nu_u = 1/2: the instantaneous pressure of Abousleiman et
 * al. (1996), Eq. 23. The checks:
 *  a. p(x, 0+) = p0 across the layer (the series at Tv = 1e-4), and the roots satisfy their equation;
 *  b. the series against an explicit finite-difference solution of the equations above (400
 *     intervals), at Tv = 0.01 to 1: the same solution to 1e-3 p0, the Mandel-Cryer rise included;
 *  c. the quarter model of tests/cases/mandel.json (rigid smooth plate on top, the centre lines
 *     slip walls, the side x = a the grid's face, drained and free), single and double point,
 *     against the series for its ramped force (the step response averaged over the ramp; the
 *     ramp keeps the layer's elastic ringing small, docs/numerics.md): the pressure at the centre
 *     and the profile p(x) (point pressures averaged over one cell wide bins), within 5% of p0 at
 *     Tv = 0.01, 0.05, 0.1, 0.2, 0.5, 1; and the plate's force balance: the layer's mean total
 *     vertical stress equals F / a within 2%;
 *  d. the same with the drained side inside the grid (a free surface on a grid line): with APIC
 *     as c; with the paper's pure FLIP the pressure next to the side drifts from Tv ~ 0.5 (0.27 p0
 *     at Tv = 1), reported as XFAIL while it lasts (docs/numerics.md, "Mandel's problem").
 * With PORO_VERIFY_LONG=1 the model also runs at half the cell size.
 * MANDEL_CASE=file runs that case instead, printing its errors (for measuring other set-ups).
 */
#include "../harness.h"
#include "analytic.h"
#include "column.h"
#include "case.h"
#include "poro.h"

#define CASE_FILE "tests/cases/mandel.json"
#define G_ACC 9.81
#define NU_U 0.5          /* undrained Poisson ratio with incompressible constituents */
#define TOLERANCE 0.05    /* p0 */
#define BINS_MAX 256
#define BALANCE_TOLERANCE 0.02   /* of F / a: the plate's force carried by the layer */

static const double check_Tv[] = {0.01, 0.05, 0.1, 0.2, 0.5, 1.0};
#define CHECK_TV (int)(sizeof check_Tv / sizeof *check_Tv)

/* The layer as a case states it: half width a (the body's width), drained constants, force. */
struct layer {
	double a, nu, G, lambda, k, rho_w, F, p0, c;
	double Tv_ramp;   /* the force's ramp, as a time factor (0: applied at once) */
};

static struct layer layer_of(const struct case_spec *c)
{
	const struct case_material *m = &c->materials[0];
	struct layer L = {.a = c->bodies[0].max[0] - c->bodies[0].min[0], .nu = m->poisson_ratio,
			  .k = c->bodies[0].hydraulic_conductivity, .rho_w = c->fluid.density};
	L.G = m->youngs_modulus / (2 * (1 + L.nu));
	L.lambda = m->youngs_modulus * L.nu / ((1 + L.nu) * (1 - 2 * L.nu));
	L.c = L.k / (L.rho_w * G_ACC) * (L.lambda + 2 * L.G);
	for (int l = 0; l < c->load_count; l++)
		if (c->loads[l].time_function.kind == TIME_RAMP)
			L.Tv_ramp = c->loads[l].time_function.ramp_time * L.c / (L.a * L.a);
	for (int f = 0; f < FACE_COUNT; f++)
		if (c->boundaries[f].soil == CONSTRAINT_PLATE) {
			L.F = c->boundaries[f].plate.force;
			if (c->boundaries[f].plate.time_function.kind == TIME_RAMP)
				L.Tv_ramp = c->boundaries[f].plate.time_function.ramp_time * L.c / (L.a * L.a);
		}
	for (int l = 0; l < c->load_count; l++)   /* a traction stands for a flexible plate */
		L.F += -c->loads[l].traction[1] * (c->loads[l].to - c->loads[l].from);
	L.p0 = mandel_initial_pressure(L.F, L.a, 1.0, NU_U);
	return L;
}

/* Explicit finite differences of p_t = c p_xx - 2 G eps_t with eps from the force balance (file
 * comment), in units a = c = 1, lambda and G from nu; p / p0 at the centre and at x = a / 2 at
 * each Tv. The strain's step is solved with the flow's: p += s uniformly, eps -= s / (2 G). */
static void mandel_finite_difference(double nu, const double *Tv, int nTv, double *centre, double *half)
{
	enum { N = 400 };
	const double G = 1.0 / (2 * (1 + nu)), lambda = nu / ((1 + nu) * (1 - 2 * nu)), F = 1.0, h = 1.0 / N;
	const double K = 4 * G * (lambda + G), dt = 0.2 * h * h, p0 = F / 2;
	double p[N + 1], pn[N + 1], weight = 0.5 * h + (N - 1) * h, eps;
	for (int i = 0; i < N; i++)
		p[i] = p0;
	p[N] = 0;
	eps = (2 * G * p0 * weight - F * (lambda + 2 * G)) / K;
	double t = 0;
	for (int it = 0; it < nTv;) {
		double integral = 0;
		for (int i = 0; i < N; i++) {
			double lap = i == 0 ? 2 * (p[1] - p[0]) / (h * h) : (p[i + 1] - 2 * p[i] + p[i - 1]) / (h * h);
			pn[i] = p[i] + dt * lap;
			integral += (i == 0 ? 0.5 : 1.0) * h * pn[i];
		}
		double s = -2 * G * ((2 * G * integral - F * (lambda + 2 * G)) / K - eps) / (1 + 4 * G * G * weight / K);
		for (int i = 0; i < N; i++)
			p[i] = pn[i] + s;
		eps -= s / (2 * G);
		t += dt;
		if (t >= Tv[it] - 0.5 * dt) {
			centre[it] = p[0] / p0, half[it] = p[N / 2] / p0;
			it++;
		}
	}
}

static void check_closed_form(void)
{
	const double nu = 0.2, r = (1 - nu) / (NU_U - nu);
	double alpha[MANDEL_ROOTS], worst_root = 0, worst_p0 = 0;
	mandel_roots(r, alpha, MANDEL_ROOTS);
	for (int n = 0; n < MANDEL_ROOTS; n++)
		worst_root = fmax(worst_root, fabs(sin(alpha[n]) - r * alpha[n] * cos(alpha[n])) / alpha[n]);
	for (int i = 0; i < 20; i++)
		worst_p0 = fmax(worst_p0, fabs(mandel_pressure_ratio(0.045 * i, 1.0, 1e-4, nu, NU_U) - 1));
	printf("INFO mandel closed form nu=%.1f: first roots %.6f %.6f %.6f, |sin a - r a cos a| / a <= %.1e; "
	       "|p(x, Tv=1e-4) / p0 - 1| <= %.2e for x / a <= 0.855\n", nu, alpha[0], alpha[1], alpha[2], worst_root,
	       worst_p0);
	CHECK(worst_root < 1e-9, "mandel_roots_satisfy_tan_a_eq_r_a", "%.2e", worst_root);
	CHECK(worst_p0 < 5e-3, "mandel_series_starts_at_p0", "%.2e", worst_p0);
	double centre[CHECK_TV], half[CHECK_TV], worst = 0;
	mandel_finite_difference(nu, check_Tv, CHECK_TV, centre, half);
	for (int i = 0; i < CHECK_TV; i++) {
		double sc = mandel_pressure_ratio(0, 1, check_Tv[i], nu, NU_U), sh = mandel_pressure_ratio(0.5, 1, check_Tv[i], nu, NU_U);
		printf("INFO mandel Tv=%.2f p/p0 at the centre: series %.5f, finite differences %.5f; at a/2: %.5f, %.5f\n",
		       check_Tv[i], sc, centre[i], sh, half[i]);
		worst = fmax(worst, fmax(fabs(sc - centre[i]), fabs(sh - half[i])));
	}
	CHECK(worst < 1e-3, "mandel_series_matches_finite_differences", "largest difference %.2e p0", worst);
	double peak = 0;
	for (int i = 1; i <= 100; i++)
		peak = fmax(peak, mandel_pressure_ratio(0, 1, 0.002 * i, nu, NU_U));
	printf("INFO mandel nu=%.1f: the centre's peak p/p0 = %.4f (Mandel-Cryer)\n", nu, peak);
	CHECK(peak > 1.05, "mandel_cryer_rise_in_the_series", "peak %.4f", peak);
}

/* Pressure error at one Tv: the centre bin's and the largest bin's |mean p - series| / p0. */
struct profile_error {
	double centre, worst, centre_value, worst_x;
};

static struct profile_error profile_error(const struct sim *s, const struct layer *L, double h, double Tv)
{
	idx_t n = sim_pressure_point_count(s);
	double *p = malloc(sizeof(double) * (size_t)n), *x = malloc(sizeof(double) * 2 * (size_t)n);
	double sum[BINS_MAX] = {0}, sum_x[BINS_MAX] = {0};
	int count[BINS_MAX] = {0};
	struct profile_error e = {0};
	sim_pore_pressure(s, p, x);
	for (idx_t i = 0; i < n; i++) {
		int b = (int)floor(x[2 * i] / h);
		if (b < 0 || b >= BINS_MAX || x[2 * i] > L->a)
			continue;
		sum[b] += p[i], sum_x[b] += x[2 * i], count[b]++;
	}
	for (int b = 0; b < BINS_MAX; b++) {
		if (!count[b])
			continue;
		double xm = sum_x[b] / count[b], pm = sum[b] / count[b];   /* compression positive */
		double err = fabs(pm - L->p0 * mandel_pressure_ratio_ramped(xm, L->a, Tv, L->Tv_ramp, L->nu, NU_U)) / L->p0;
		if (b == 0)
			e.centre = err, e.centre_value = pm / L->p0;
		if (err > e.worst)
			e.worst = err, e.worst_x = xm;
	}
	free(p);
	free(x);
	return e;
}

/* How a run departs from tests/cases/mandel.json: the drained side inside the grid (a free
 * surface, the grid 4 cells wider) and the point velocity update. */
struct variant {
	int single_point, side_inside;
	enum velocity_update velocity_update;
	double h;   /* cell size, 0: the case's; dt is scaled with it */
};

/* Runs the case to each Tv; e[i] the errors, *balance the largest departure of the vertical
 * stress ratio from 1 after the ramp. Returns 0 on failure. */
static int run_mandel(const char *file, const char *label, const struct variant *v, struct profile_error *e,
		      double *balance)
{
	struct case_spec *c = NULL;
	struct poro_error err = {0};
	struct sim *s = NULL;
	if (case_load_file(file, &c, &err)) {
		printf("INFO cannot load %s: %s\n", file, err.message);
		return 0;
	}
	if (v) {
		c->formulation.phases = v->single_point ? PHASES_SINGLE_POINT : PHASES_DOUBLE_POINT;
		c->formulation.velocity_update = v->velocity_update;
		if (v->side_inside) {
			c->grid.extent[0] += 4 * c->grid.cell_size;
			c->boundaries[FACE_RIGHT].soil = c->boundaries[FACE_RIGHT].water = CONSTRAINT_FREE;
			c->boundaries[FACE_RIGHT].drainage = DRAINAGE_IMPERMEABLE;
		}
		if (v->h > 0) {
			c->time.dt *= v->h / c->grid.cell_size;
			c->grid.cell_size = v->h;
		}
	}
	struct layer L = layer_of(c);
	int ok = !sim_create(&s, c, &err);
	double t0 = harness_wall_seconds();
	*balance = 0.0;
	for (int i = 0; ok && i < CHECK_TV; i++) {
		long target = lround(check_Tv[i] * L.a * L.a / L.c / c->time.dt);
		while (ok && sim_steps_taken(s) < target)
			ok = !sim_step(s);
		if (!ok)
			break;
		e[i] = profile_error(s, &L, c->grid.cell_size, check_Tv[i]);
		if (check_Tv[i] > L.Tv_ramp)   /* every horizontal section carries F / a */
			*balance = fmax(*balance, fabs(mean_total_vertical_compression(s) * L.a / L.F - 1));
		printf("INFO mandel %s h=%.4g Tv=%.2f: centre p/p0 %.4f (series %.4f), error %.4f p0; profile's largest "
		       "error %.4f p0 at x/a = %.3f\n", label, c->grid.cell_size, check_Tv[i], e[i].centre_value,
		       mandel_pressure_ratio_ramped(0, L.a, check_Tv[i], L.Tv_ramp, L.nu, NU_U), e[i].centre, e[i].worst, e[i].worst_x / L.a);
	}
	if (!ok)
		printf("INFO mandel %s failed: %s\n", label, s ? sim_error(s)->message : err.message);
	printf("INFO mandel %s: %ld steps in %.2f s\n", label, s ? sim_steps_taken(s) : 0L, harness_wall_seconds() - t0);
	sim_destroy(&s);
	case_destroy(&c);
	return ok;
}

/* The checks of c on one variant; expected_to_fail: a known failure, reported as XFAIL while it lasts. */
static void check_model(const char *label, const struct variant *v, int expected_to_fail, const char *why)
{
	struct profile_error e[CHECK_TV] = {{0}};
	char name[160];
	double balance = 0.0, worst = 0.0;
	int ok = run_mandel(CASE_FILE, label, v, e, &balance);
	snprintf(name, sizeof name, "mandel_%s_runs", label);
	CHECK(ok, name, "see the INFO lines");
	for (int i = 0; i < CHECK_TV; i++)
		worst = fmax(worst, fmax(e[i].centre, e[i].worst));
	if (expected_to_fail && !(ok && worst <= TOLERANCE)) {
		printf("XFAIL mandel_%s_within_5pct: largest error %.4f p0 (%s)\n", label, worst, why);
		return;
	}
	for (int i = 0; i < CHECK_TV; i++) {
		snprintf(name, sizeof name, "mandel_%s_centre_within_5pct_Tv%.2f", label, check_Tv[i]);
		CHECK(ok && e[i].centre <= TOLERANCE, name, "%.4f p0", e[i].centre);
		snprintf(name, sizeof name, "mandel_%s_profile_within_5pct_Tv%.2f", label, check_Tv[i]);
		CHECK(ok && e[i].worst <= TOLERANCE, name, "%.4f p0 at x = %.3f m", e[i].worst, e[i].worst_x);
	}
	printf("INFO mandel %s: mean vertical stress / (F / a) within %.2e of 1 after the ramp\n", label, balance);
	snprintf(name, sizeof name, "mandel_%s_plate_force_balanced", label);
	CHECK(ok && balance <= BALANCE_TOLERANCE, name, "%.2e", balance);
}

int main(void)
{
	const char *other = getenv("MANDEL_CASE");
	if (other) {
		struct profile_error e[CHECK_TV];
		double balance;
		run_mandel(other, other, NULL, e, &balance);
		return 0;
	}
	check_closed_form();
	const struct variant dp = {0, 0, VELOCITY_UPDATE_FLIP, 0}, sp = {1, 0, VELOCITY_UPDATE_FLIP, 0};
	check_model("double_point", &dp, 0, NULL);
	check_model("single_point", &sp, 0, NULL);
	/* the drained side as a free surface inside the grid (docs/numerics.md, "Mandel's problem") */
	const struct variant inside_flip = {0, 1, VELOCITY_UPDATE_FLIP, 0}, inside_apic = {0, 1, VELOCITY_UPDATE_APIC, 0};
	check_model("side_in_grid_apic", &inside_apic, 0, NULL);
	check_model("side_in_grid_flip", &inside_flip, 1,
		    "pure FLIP: a point-to-point mode of the points next to the free side grows from Tv 0.5");
	if (getenv("PORO_VERIFY_LONG")) {
		const struct variant dp_fine = {0, 0, VELOCITY_UPDATE_FLIP, 0.03125},
				     sp_fine = {1, 0, VELOCITY_UPDATE_FLIP, 0.03125};
		check_model("double_point_fine", &dp_fine, 0, NULL);
		check_model("single_point_fine", &sp_fine, 0, NULL);
	}
	return harness_failed_count ? 1 : 0;
}
