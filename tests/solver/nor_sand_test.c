/*
 * nor_sand_test.c - the Nor-Sand model (material_nor_sand.c with the spectral kinematics of
 * principal_update.c), finite and small strain, and its element cases in tests/cases/.
 *
 * Oracles:
 *   - the yield function, written out here from Borja and Andrade's formula, of the returned
 *     stress and image pressure (0 to YIELD_TOLERANCE relative to p + q);
 *   - the consistent tangent against central differences of the update (FD_STEP on the trial
 *     elastic strain) at random plastic states, with and without the dilatancy cut-off ramp;
 *   - objectivity: dF = R U and dF = U give the same Cauchy invariants (finite strain);
 *   - an elastic step and its inverse return the stress;
 *   - the backward-Euler hardening equation, with 000 Eq. 92 written out here, holds after steps
 *     below, inside and beyond the cut-off, and the state it uses switches where Eq. 92 says;
 *   - the gas-like state of Eqs. 93-94 on both sides of v_crit, and the restart from Be = I;
 *   - 000 Eq. 113 for the initial image pressure, and material_reset_reference (App. B.4);
 *   - initial_yield_surface "through_stress": the surface through the loaded stress, which a zero
 *     step then keeps, where the default tip returns it;
 *   - the element cases: App. B.3's undrained tests reach the critical state (q/p within
 *     CS_RATIO_TOLERANCE of M, |psi| <= CS_PSI_TOLERANCE), drained tests keep dq = 3 dp and
 *     dilate (dense) or contract (loose).
 */
#include "../harness.h"
#include "element.h"
#include "material.h"
#include "principal_values.h"

#define FD_STEP 1e-8
#define TANGENT_TOLERANCE 1e-6
#define YIELD_TOLERANCE 1e-10
#define CS_RATIO_TOLERANCE 0.02
#define CS_PSI_TOLERANCE 0.01
#define SAMPLES 200

/* High-entropy parameters (non-associated: Nbar != N). */
static struct material make(enum material_strain strain)
{
	struct case_material spec = {
		.model = MODEL_NOR_SAND, .strain = strain, .shear_modulus = 23.71e6, .swelling_index = 0.00237,
		.compression_index = 0.0213, .reference_specific_volume = 1.893, .critical_state_reference_pressure = 1e3,
		.critical_stress_ratio = 1.137, .yield_function_constant = 0.213, .plastic_potential_constant = 0.137,
		.hardening_coefficient = 87.3, .dilatancy_multiplier = -2.31, .initial_specific_volume = 1.713,
		.overconsolidation_ratio = 1, .initial_reference_pressure = 2e3, .dilatancy_cutoff_start = 1.0,
		.dilatancy_cutoff_end = 1.5, .gas_volume_ratio = 1.6,
	};
	struct material m;
	material_init(&m, &spec);
	return m;
}

/* 000 Table 5 (Hostun sand), finite strain, with psi from ln(p / 1 Pa) as in the landslide cases. */
static struct material table5_landslide(void)
{
	struct case_material spec = {
		.model = MODEL_NOR_SAND, .strain = STRAIN_FINITE, .shear_modulus = 40e6, .swelling_index = 0.002,
		.compression_index = 0.02, .reference_specific_volume = 1.892, .critical_state_reference_pressure = 1,
		.critical_stress_ratio = 1.0, .yield_function_constant = 0.1, .plastic_potential_constant = 0.1,
		.hardening_coefficient = 100, .dilatancy_multiplier = -2.0, .initial_specific_volume = 1.70,
		.overconsolidation_ratio = 1, .initial_reference_pressure = 2e3, .dilatancy_cutoff_start = 1.0,
		.dilatancy_cutoff_end = 1.5, .gas_volume_ratio = 1.6,
	};
	struct material m;
	material_init(&m, &spec);
	return m;
}

/* F of Borja and Andrade (compression-positive p, pi). */
static double yield_value(const struct material *m, double p, double q, double pi)
{
	const struct nor_sand_parameters *n = &m->ns;
	double eta = n->N == 0 ? n->M * (1 + log(pi / p))
			       : n->M / n->N * (1 - (1 - n->N) * pow(p / pi, n->N / (1 - n->N)));
	return q - eta * p;
}

/* p, q of a (xx, yy, xy, zz) stress, tension positive -> compression positive p. */
static void invariants(const double s[4], double *p, double *q)
{
	double m = (s[0] + s[1] + s[3]) / 3, a = s[0] - m, b = s[1] - m, c = s[3] - m;
	*p = -m;
	*q = sqrt(1.5 * (a * a + b * b + c * c + 2 * s[2] * s[2]));
}

static void sym2_apply_exp2(const double a[3], double out[3])
{
	double l[2], th;
	sym2_eigen(a[0], a[1], a[2], l, &th);
	double c = cos(th), s = sin(th), f0 = exp(2 * l[0]), f1 = exp(2 * l[1]);
	out[0] = c * c * f0 + s * s * f1;
	out[1] = s * s * f0 + c * c * f1;
	out[2] = c * s * (f0 - f1);
}

/* A point state: reference p0, eps_v0^e = 0, image pressure pi, E_d^p = Ed, psi_cut. */
struct start {
	double p0, pi, Ed, psi_cut, v0;
};

static void set_state(const struct material *m, const struct start *st, double *state)
{
	memset(state, 0, sizeof(double) * STATE_MAX);
	state[NOR_SAND_DEVIATORIC_PLASTIC_STRAIN] = st->Ed;
	state[NOR_SAND_IMAGE_PRESSURE] = st->pi;
	state[NOR_SAND_INITIAL_SPECIFIC_VOLUME] = st->v0 > 0 ? st->v0 : m->ns.v0;
	state[NOR_SAND_REFERENCE_PRESSURE] = st->p0;
	state[NOR_SAND_REFERENCE_STRAIN] = 0;
	state[NOR_SAND_CUTOFF_STATE] = st->psi_cut;
}

/* One update from the trial elastic strain eps (Be^t = exp(2 eps), dF = I, J = 1). */
static enum poro_status update_from_trial(const struct material *m, const struct start *st, const double eps[4],
					  double stress[4], double *state, double *tangent)
{
	static const double I[4] = { 1, 0, 0, 1 };
	double Be[4], b[3], plastic = 0;
	sym2_apply_exp2(eps, b);
	Be[0] = b[0], Be[1] = b[1], Be[2] = b[2], Be[3] = exp(2 * eps[3]);
	set_state(m, st, state);
	memset(stress, 0, 4 * sizeof *stress);
	struct poro_error err = {0};
	struct stress_update u = { .dF = I, .J = 1.0, .stress = stress, .Be = Be, .state = state,
				   .plastic_strain = &plastic, .tangent = tangent };
	enum poro_status s = material_update(m, &u, &err);
	if (s)
		printf("INFO update failed: %s\n", err.message);
	return s;
}

static void random_start(struct start *st, double *eps)
{
	st->p0 = rnd(60e3, 180e3);
	st->pi = st->p0 * rnd(0.25, 0.9);
	st->Ed = rnd(0, 1) < 0.3 ? rnd(1.0, 1.45) : rnd(0, 0.9);
	st->psi_cut = rnd(-0.2, 0.2);
	st->v0 = 0;
	double v = rnd(-3e-3, 1e-3);
	eps[0] = v / 3 + rnd(-1e-3, 1e-3);
	eps[1] = v / 3 + rnd(-1e-3, 1e-3);
	eps[2] = rnd(-1e-3, 1e-3);
	eps[3] = v / 3 + rnd(-1e-3, 1e-3);
}

/* 1 when the step from st with eps was plastic with a smooth return (q > 0). */
static int plastic_smooth(const struct start *st, const double *state, const double stress[4])
{
	double p, q;
	invariants(stress, &p, &q);
	return state[NOR_SAND_DEVIATORIC_PLASTIC_STRAIN] > st->Ed && q > 1e-6 * p;
}

static void check_yield_and_tangent(const char *tag, const struct material *m)
{
	double worst_f = 0, worst_t = 0;
	int plastic = 0, tangents = 0, failed = 0, ramp = 0;
	for (int i = 0; i < 20000 && tangents < SAMPLES; i++) {
		struct start st;
		double eps[4], stress[4], state[STATE_MAX], T[16], Tfd[16];
		random_start(&st, eps);
		if (update_from_trial(m, &st, eps, stress, state, T)) {
			failed++;
			continue;
		}
		if (!plastic_smooth(&st, state, stress))
			continue;
		double p, q;
		invariants(stress, &p, &q);
		worst_f = fmax(worst_f, fabs(yield_value(m, p, q, state[NOR_SAND_IMAGE_PRESSURE])) / (p + q));
		plastic++;
		/* central differences, only when both neighbours are smooth plastic returns on the same
		 * side of the cut-off's kinks */
		double Ed = state[NOR_SAND_DEVIATORIC_PLASTIC_STRAIN];
		if ((st.Ed - 1.0) * (Ed - 1.0) <= 0 || (st.Ed - 1.5) * (Ed - 1.5) <= 0 || fabs(Ed - 1.0) < 1e-5)
			continue;
		int ok = 1;
		for (int j = 0; j < 4 && ok; j++) {
			double ep[4], em[4], sp[4], sm[4], zp[STATE_MAX], zm[STATE_MAX];
			memcpy(ep, eps, sizeof ep), memcpy(em, eps, sizeof em);
			ep[j] += FD_STEP, em[j] -= FD_STEP;
			ok = !update_from_trial(m, &st, ep, sp, zp, NULL) && !update_from_trial(m, &st, em, sm, zm, NULL) &&
			     plastic_smooth(&st, zp, sp) && plastic_smooth(&st, zm, sm);
			for (int k = 0; k < 4; k++)
				Tfd[4 * k + j] = (sp[k] - sm[k]) / (2 * FD_STEP);
		}
		if (!ok)
			continue;
		double big = 0, diff = 0;
		for (int k = 0; k < 16; k++) {
			big = fmax(big, fabs(Tfd[k]));
			diff = fmax(diff, fabs(T[k] - Tfd[k]));
		}
		worst_t = fmax(worst_t, diff / big);
		tangents++;
		ramp += Ed > 1.0;
	}
	char name[96];
	printf("INFO nor_sand_%s: %d plastic steps, largest |F| / (p + q) %.3g; %d tangents (%d in the cut-off ramp), "
	       "largest |T - T_fd| / max|T_fd| %.3g (step %g)\n", tag, plastic, worst_f, tangents, ramp, worst_t, FD_STEP);
	snprintf(name, sizeof name, "nor_sand_%s_on_yield_surface", tag);
	CHECK(plastic >= SAMPLES && !failed && worst_f <= YIELD_TOLERANCE, name, "%d plastic, %d failed, |F| %.3g",
	      plastic, failed, worst_f);
	snprintf(name, sizeof name, "nor_sand_%s_tangent_matches_finite_differences", tag);
	CHECK(tangents >= SAMPLES && ramp >= 20 && worst_t <= TANGENT_TOLERANCE, name, "%d tangents, %d ramp, error %.3g",
	      tangents, ramp, worst_t);
}

/* One step dF (J = det dF dF_zz) from the state returned from trial eps0. */
static enum poro_status step_from(const struct material *m, const struct start *st, const double eps0[4],
				  const double dF[4], double dF_zz, double stress[4], double *state)
{
	double Be[4], b[3], plastic = 0;
	static const double I[4] = { 1, 0, 0, 1 };
	sym2_apply_exp2(eps0, b);
	Be[0] = b[0], Be[1] = b[1], Be[2] = b[2], Be[3] = exp(2 * eps0[3]);
	set_state(m, st, state);
	memset(stress, 0, 4 * sizeof *stress);
	struct poro_error err = {0};
	struct stress_update u = { .dF = I, .J = 1.0, .stress = stress, .Be = Be, .state = state,
				   .plastic_strain = &plastic };
	enum poro_status s = material_update(m, &u, &err);
	u.dF = dF, u.dF_zz = dF_zz, u.J = (dF[0] * dF[3] - dF[1] * dF[2]) * dF_zz;
	return s ? s : material_update(m, &u, &err);
}

static void check_objectivity(const struct material *m)
{
	double worst = 0;
	int plastic = 0, split = 0;
	for (int i = 0; i < 300; i++) {
		struct start st;
		double eps0[4], U[4], RU[4], a = rnd(-3.1, 3.1), c = cos(a), s = sin(a), su[4], sr[4];
		double zu[STATE_MAX], zr[STATE_MAX];
		random_start(&st, eps0);
		U[0] = 1 + rnd(-0.02, 0.02), U[3] = 1 + rnd(-0.02, 0.02), U[1] = U[2] = rnd(-0.01, 0.01);
		RU[0] = c * U[0] - s * U[2], RU[1] = c * U[1] - s * U[3];
		RU[2] = s * U[0] + c * U[2], RU[3] = s * U[1] + c * U[3];
		double zz = 1 + rnd(-0.01, 0.01);
		if (step_from(m, &st, eps0, U, zz, su, zu) || step_from(m, &st, eps0, RU, zz, sr, zr))
			continue;
		double pu[3], pr[3];
		sorted_principal(su, pu), sorted_principal(sr, pr);
		double scale = fabs(pu[0]) + fabs(pu[2]);
		/* a trial that compresses p by up to e^10 in a step can have a smooth return and a tip
		 * return both; which one Newton finds may differ in the last bit of the invariants, so
		 * pairs that end on different branches are counted, not compared */
		if ((fabs(pu[2] - pu[0]) <= 1e-12 * scale) != (fabs(pr[2] - pr[0]) <= 1e-12 * scale)) {
			split++;
			continue;
		}
		for (int k = 0; k < 3; k++)
			worst = fmax(worst, fabs(pu[k] - pr[k]) / scale);
		for (int k = 0; k < STATE_MAX; k++)
			worst = fmax(worst, fabs(zu[k] - zr[k]) / fmax(fabs(zu[k]), 1.0));
		plastic += zu[0] > st.Ed;
	}
	printf("INFO nor_sand_finite_rotation_objective: %d plastic of 300 rotated steps (%d ending on the "
	       "smooth surface in one orientation and at the tip in the other), largest relative difference "
	       "of principal stresses and state %.3g\n", plastic, split, worst);
	CHECK(plastic > 100 && split <= 10 && worst <= 1e-10, "nor_sand_finite_rotation_objective",
	      "%d plastic, %d split, difference %.3g", plastic, split, worst);
}

static void check_reversible(const char *tag, const struct material *m)
{
	static const double I[4] = { 1, 0, 0, 1 };
	double worst = 0;
	int elastic = 0;
	int finite = material_is_finite_strain(m);
	for (int i = 0; i < 200; i++) {
		struct start st;
		double eps0[4], stress[4], state[STATE_MAX], Be[4], b[3], plastic = 0;
		random_start(&st, eps0);
		st.pi = 3 * st.p0;       /* well inside */
		for (int k = 0; k < 4; k++)
			eps0[k] *= 0.05;
		sym2_apply_exp2(eps0, b);
		Be[0] = b[0], Be[1] = b[1], Be[2] = b[2], Be[3] = exp(2 * eps0[3]);
		set_state(m, &st, state);
		double dF[4], inv[4], zz = 1 + rnd(-1e-5, 1e-5);
		dF[0] = 1 + rnd(-1e-5, 1e-5), dF[3] = 1 + rnd(-1e-5, 1e-5), dF[1] = rnd(-1e-5, 1e-5), dF[2] = rnd(-1e-5, 1e-5);
		double det = dF[0] * dF[3] - dF[1] * dF[2];
		if (finite) {
			inv[0] = dF[3] / det, inv[3] = dF[0] / det, inv[1] = -dF[1] / det, inv[2] = -dF[2] / det;
		} else {
			for (int k = 0; k < 4; k++)
				inv[k] = I[k] - (dF[k] - I[k]);
		}
		struct poro_error err = {0};
		struct stress_update u = { .dF = I, .J = 1.0, .stress = stress, .Be = Be, .state = state,
					   .plastic_strain = &plastic };
		material_update(m, &u, &err);
		double start[4];
		memcpy(start, stress, sizeof start);
		u.dF = dF, u.dF_zz = zz, u.J = det * zz;
		material_update(m, &u, &err);
		u.dF = inv, u.dF_zz = finite ? 1 / zz : 2 - zz, u.J = 1.0;
		material_update(m, &u, &err);
		double scale = fabs(start[0]) + fabs(start[1]) + fabs(start[3]);
		for (int k = 0; k < 4; k++)
			worst = fmax(worst, fabs(stress[k] - start[k]) / scale);
		elastic += state[NOR_SAND_DEVIATORIC_PLASTIC_STRAIN] == st.Ed;
	}
	char name[96];
	snprintf(name, sizeof name, "nor_sand_%s_elastic_step_reversible", tag);
	printf("INFO %s: 200 load-unload pairs, largest relative difference %.3g\n", name, worst);
	CHECK(elastic == 200 && worst <= 1e-12, name, "%d elastic, difference %.3g", elastic, worst);
}

/* 000 Eq. 92 written out: psi_i after the step from the state the step started with. */
static double eq92(const struct material *m, double Ed, double v, double pi, double psi_cut)
{
	const struct nor_sand_parameters *n = &m->ns;
	if (Ed <= n->cutoff_start)
		return v - n->v_c0 + n->lambda * log(pi / n->p_ref);
	if (Ed >= n->cutoff_end)
		return 0;
	return (1 - (Ed - n->cutoff_start) / (n->cutoff_end - n->cutoff_start)) * psi_cut;
}

/* Residual of pi = pi_n + h dl (pi* - pi) with psi_i from eq92, relative to pi_n. */
static double hardening_residual(const struct material *m, const struct start *st, const double *state,
				 const double stress[4])
{
	const struct nor_sand_parameters *n = &m->ns;
	double p, q, pi = state[NOR_SAND_IMAGE_PRESSURE], Ed = state[NOR_SAND_DEVIATORIC_PLASTIC_STRAIN];
	invariants(stress, &p, &q);
	double psi = eq92(m, Ed, state[NOR_SAND_SPECIFIC_VOLUME], pi, st->psi_cut);
	double g = pow(1 - n->N * n->alpha * psi / n->M, (n->N - 1) / n->N);
	return fabs(pi - st->pi - n->h * (Ed - st->Ed) * (p * g - pi)) / st->pi;
}

/* One plastic step from E_d^p = Ed0 with a trial of deviatoric size dev: the hardening equation
 * with Eq. 92 holds, and the result depends on psi_cut and on v as the zone says. */
static void check_cutoff_zone(const struct material *m, const char *zone, double Ed0, double dev, int uses_cut,
			      int uses_v)
{
	double eps[4] = { -1.1e-3 + dev, -1.1e-3 - 0.37 * dev, 0.21 * dev, -1.1e-3 - 0.63 * dev };
	struct start a = { .p0 = 97.3e3, .pi = 61.7e3, .Ed = Ed0, .psi_cut = 0.0734, .v0 = 0 }, b = a, c = a;
	double sa[4], sb[4], sc[4], za[STATE_MAX], zb[STATE_MAX], zc[STATE_MAX];
	b.psi_cut = -0.0417;
	c.v0 = m->ns.v0 + 0.0123;
	update_from_trial(m, &a, eps, sa, za, NULL);
	update_from_trial(m, &b, eps, sb, zb, NULL);
	update_from_trial(m, &c, eps, sc, zc, NULL);
	double res = fmax(hardening_residual(m, &a, za, sa), fmax(hardening_residual(m, &b, zb, sb),
								 hardening_residual(m, &c, zc, sc)));
	int cut = fabs(zb[NOR_SAND_IMAGE_PRESSURE] - za[NOR_SAND_IMAGE_PRESSURE]) > 1e-9 * a.pi;
	int vol = fabs(zc[NOR_SAND_IMAGE_PRESSURE] - za[NOR_SAND_IMAGE_PRESSURE]) > 1e-9 * a.pi;
	double Ed = za[NOR_SAND_DEVIATORIC_PLASTIC_STRAIN];
	char name[96];
	snprintf(name, sizeof name, "nor_sand_cutoff_eq92_%s", zone);
	printf("INFO %s: E_d^p %.6g -> %.6g, hardening residual %.3g, depends on psi_cut %d, on v %d\n", name, Ed0, Ed,
	       res, cut, vol);
	CHECK(Ed > Ed0 && res <= 1e-10 && cut == uses_cut && vol == uses_v, name,
	      "E_d %.6g, residual %.3g, psi_cut %d (want %d), v %d (want %d)", Ed, res, cut, uses_cut, vol, uses_v);
}

static void check_cutoff(const struct material *m)
{
	/* the trial's deviatoric size sets the multiplier: about 1e-3 here */
	check_cutoff_zone(m, "below_start", 1.0 - 0.0213, 1.2e-3, 0, 1);
	check_cutoff_zone(m, "above_start", 1.0 + 0.0213, 1.2e-3, 1, 0);
	check_cutoff_zone(m, "below_end", 1.5 - 0.0213, 1.2e-3, 1, 0);
	check_cutoff_zone(m, "above_end", 1.5 + 0.0213, 1.2e-3, 0, 0);
	/* the cut-off state follows psi_i while E_d^p stays at or below the start, then freezes */
	struct start a = { .p0 = 97.3e3, .pi = 61.7e3, .Ed = 0.5, .psi_cut = 0.0734 };
	double eps[4] = { 1.3e-4, -2.4e-3, 3.1e-4, -1.7e-3 }, s[4], z[STATE_MAX];
	update_from_trial(m, &a, eps, s, z, NULL);
	double follow = fabs(z[NOR_SAND_CUTOFF_STATE] - eq92(m, z[0], z[NOR_SAND_SPECIFIC_VOLUME],
							    z[NOR_SAND_IMAGE_PRESSURE], 0));
	a.Ed = 1.2;
	update_from_trial(m, &a, eps, s, z, NULL);
	CHECK(follow <= 1e-14 && z[NOR_SAND_CUTOFF_STATE] == 0.0734, "nor_sand_cutoff_state_recorded_then_frozen",
	      "follow %.3g, frozen %.17g", follow, z[NOR_SAND_CUTOFF_STATE]);
}

/* 000 Eqs. 93-94 on both sides of v_crit = gas_ratio v0, and the restart from Be = I. */
static void check_gas(const struct material *m)
{
	static const double I[4] = { 1, 0, 0, 1 };
	const struct nor_sand_parameters *n = &m->ns;
	int ok = 1;
	double last_solid = 0;
	for (int side = 0; side < 2; side++) {
		double J = n->gas_ratio * (side ? 1 + 1e-9 : 1 - 1e-9), state[STATE_MAX], stress[4], plastic = 0, T[16];
		double Be[4] = { 1.0021, 0.9987, 0.0013, 1.0009 };
		struct start st = { .p0 = 50e3, .pi = 4.1e6, .Ed = 0.3, .psi_cut = 0.05 };
		set_state(m, &st, state);
		memset(stress, 0, sizeof stress);
		struct poro_error err = {0};
		struct stress_update u = { .dF = I, .J = J, .stress = stress, .Be = Be, .state = state,
					   .plastic_strain = &plastic, .tangent = T };
		material_update(m, &u, &err);
		double norm = fabs(stress[0]) + fabs(stress[1]) + fabs(stress[2]) + fabs(stress[3]), tn = 0;
		for (int k = 0; k < 16; k++)
			tn += fabs(T[k]);
		if (side) {
			ok &= norm == 0 && tn == 0 && Be[0] == 1 && Be[1] == 1 && Be[2] == 0 && Be[3] == 1 &&
			      state[NOR_SAND_IMAGE_PRESSURE] == 4.1e6 && state[0] == 0.3;
			/* back below v_crit: the stress restarts from Be = I, p = p0 exp(-(ev - ev0) / kappa) with
			 * ev = ln det dF (finite strain) */
			double dF[4] = { 0.9987, 0.0011, -0.0007, 0.9979 }, zz = 0.9991;
			double det = (dF[0] * dF[3] - dF[1] * dF[2]) * zz;
			u.dF = dF, u.dF_zz = zz, u.J = n->gas_ratio * 0.97, u.tangent = NULL;
			material_update(m, &u, &err);
			double p, q;
			invariants(stress, &p, &q);
			double want = 50e3 * exp(-log(det) / n->kappa) / u.J;
			ok &= rel_diff(p, want, 1) <= 1e-12;
			printf("INFO nor_sand_gas_like_eq93: above v_crit |sigma| = %g, |T| = %g, Be = I; restart p %.10g Pa "
			       "(closed form %.10g); just below v_crit |sigma| = %.6g Pa\n", norm, tn, p, want, last_solid);
		} else {
			last_solid = norm;
			ok &= norm > 1e3;
		}
	}
	CHECK(ok, "nor_sand_gas_like_eq93_both_sides", "see INFO");
}

/* 000 Eq. 96: the specific volume comes from J_v when the scheme gives one, the stress from the
 * point's own J. Three updates of one plastic step: (J, no J_v), (J, J_v = J) and (J', J_v = J).
 * The first two must agree bit for bit; the third has the same Kirchhoff stress and state
 * (the same v), so its Cauchy stress is the first one's times J / J'. And a J_v beyond
 * v_crit makes the point gas-like whatever its J (Eq. 93 tests v). */
static void check_specific_volume_from_J_v(const struct material *m)
{
	const double dF[4] = { 1.004, 0.012, -0.003, 0.991 }, zz = 0.999;
	const double J = 1.07, J2 = 0.93;
	double stress[3][4], state[3][STATE_MAX], Be[3][4], plastic[3];
	const double J_v[3] = { 0.0, J, J }, Jp[3] = { J, J, J2 };
	for (int k = 0; k < 3; k++) {
		struct start st = { .p0 = 80e3, .pi = 95e3, .Ed = 0.2, .psi_cut = -0.05 };
		set_state(m, &st, state[k]);
		const double Be0[4] = { 0.9993, 0.9981, 0.0004, 0.9990 };
		memcpy(Be[k], Be0, sizeof Be0);
		for (int c = 0; c < 4; c++)   /* sigma^t with tau^t at the reference: p0 */
			stress[k][c] = c == 2 ? 0.0 : -80e3;
		plastic[k] = 0.2;
		struct poro_error err = {0};
		struct stress_update u = { .dF = dF, .dF_zz = zz, .J = Jp[k], .J_v = J_v[k], .stress = stress[k],
					   .Be = Be[k], .state = state[k], .plastic_strain = &plastic[k] };
		if (material_update(m, &u, &err) != PORO_OK)
			printf("INFO update %d failed: %s\n", k, err.message);
	}
	int same = memcmp(stress[0], stress[1], sizeof stress[0]) == 0 && memcmp(state[0], state[1], sizeof state[0]) == 0;
	double worst = 0;
	for (int c = 0; c < 4; c++)
		worst = fmax(worst, fabs(stress[2][c] * J2 - stress[0][c] * J) / (fabs(stress[0][c] * J) + 1.0));
	int v_same = state[2][NOR_SAND_SPECIFIC_VOLUME] == state[0][NOR_SAND_SPECIFIC_VOLUME] &&
		     state[2][NOR_SAND_DEVIATORIC_PLASTIC_STRAIN] == state[0][NOR_SAND_DEVIATORIC_PLASTIC_STRAIN];
	/* gas-like by J_v alone */
	double gstress[4] = { -80e3, -80e3, 0, -80e3 }, gstate[STATE_MAX], gBe[4] = { 0.9993, 0.9981, 0.0004, 0.9990 };
	double gplastic = 0.2;
	struct start st = { .p0 = 80e3, .pi = 95e3, .Ed = 0.2, .psi_cut = -0.05 };
	set_state(m, &st, gstate);
	struct poro_error err = {0};
	struct stress_update g = { .dF = dF, .dF_zz = zz, .J = 1.0, .J_v = m->ns.gas_ratio * (1 + 1e-9),
				   .stress = gstress, .Be = gBe, .state = gstate, .plastic_strain = &gplastic };
	material_update(m, &g, &err);
	int gas = gstress[0] == 0 && gstress[1] == 0 && gstress[2] == 0 && gstress[3] == 0;
	printf("INFO nor_sand_specific_volume_from_J_v: J_v = J same bits %d; J' = %.2f: v the same %d, "
	       "sigma J' against sigma J %.2g relative; J = 1, J_v just past v_crit: stress-free %d; "
	       "v after the step %.6f (J_v v0 %.6f)\n", same, J2, v_same, worst, gas,
	       state[2][NOR_SAND_SPECIFIC_VOLUME], J * m->ns.v0);
	CHECK(same && v_same && worst <= 1e-13 && gas && state[2][NOR_SAND_SPECIFIC_VOLUME] == J * m->ns.v0 &&
	      plastic[0] > 0.2, "nor_sand_specific_volume_from_J_v", "see INFO");
}

/* 000 Eq. 113 and material_reset_reference (App. B.4). */
static void check_initialisation(void)
{
	struct material m = make(STRAIN_FINITE);
	double stress[4] = { -123.4e3, -123.4e3, 0, -123.4e3 }, Be[4], state[STATE_MAX];
	int ok = 1;
	for (int k = 0; k < 3; k++) {
		double N = k == 0 ? 0.0 : k == 1 ? 0.213 : 0.5, ocr = k == 2 ? 1.37 : 1.0;
		m.ns.N = N, m.ns.ocr = ocr;
		nor_sand_init_state(&m, stress, Be, state);
		double want = ocr * (N == 0 ? 123.4e3 / exp(1) : 123.4e3 * pow(1 - N, (1 - N) / N));
		ok &= rel_diff(state[NOR_SAND_IMAGE_PRESSURE], want, 1) <= 1e-14;
		if (ocr == 1)   /* the isotropic start lies on the tip of the surface */
			ok &= fabs(yield_value(&m, 123.4e3, 0, state[NOR_SAND_IMAGE_PRESSURE])) <= 1e-10 * 123.4e3;
	}
	m = make(STRAIN_FINITE);
	/* elastic loading from a stress-free point, then the reset: p0, eps_v0^e and pi follow Eqs.
	 * 111-113, and a zero step leaves the stress unchanged (an isotropic load: Eq. 113 places the
	 * tip of the surface at p0, so a point with q > 0 would lie outside it) */
	static const double I[4] = { 1, 0, 0, 1 };
	double zero[4] = { 0, 0, 0, 0 }, plastic = 0;
	nor_sand_init_state(&m, zero, Be, state);
	state[NOR_SAND_IMAGE_PRESSURE] = 1e9;      /* elastic only, as in the gravity loading */
	double dF[4] = { 0.99713, 0.0, 0.0, 0.99713 }, zz = 0.99713;
	double J = (dF[0] * dF[3] - dF[1] * dF[2]) * zz;
	struct poro_error err = {0};
	struct stress_update u = { .dF = dF, .dF_zz = zz, .J = J, .stress = zero, .Be = Be, .state = state,
				   .plastic_strain = &plastic };
	material_update(&m, &u, &err);
	double before[4], p, q;
	memcpy(before, zero, sizeof before);
	invariants(zero, &p, &q);
	material_reset_reference(&m, zero, Be, J, state);
	double ev = 0.5 * log((Be[0] * Be[1] - Be[2] * Be[2]) * Be[3]);
	ok &= rel_diff(state[NOR_SAND_REFERENCE_PRESSURE], J * p, 1) <= 1e-14;
	ok &= fabs(state[NOR_SAND_REFERENCE_STRAIN] - ev) <= 1e-16;
	ok &= rel_diff(state[NOR_SAND_IMAGE_PRESSURE], J * p * pow(1 - 0.213, (1 - 0.213) / 0.213), 1) <= 1e-14;
	u.dF = I, u.dF_zz = 1;
	material_update(&m, &u, &err);
	double diff = 0;
	for (int k = 0; k < 4; k++)
		diff = fmax(diff, fabs(zero[k] - before[k]) / p);
	ok &= diff <= 1e-12;
	printf("INFO nor_sand_initialisation: gravity-loaded p %.6g Pa, eps_v0^e %.6g, stress change after reset %.3g\n",
	       p, ev, diff);
	CHECK(ok, "nor_sand_initialisation_eq113_and_reset", "see INFO");
}

/* initial_yield_surface "through_stress" against the default "tip", on what 000 App. B.4's elastic
 * gravity loading leaves in the landslide slopes: Table 5's G = 40 MPa against K = p / kappa = 1 MPa
 * at p0 = 2 kPa carries a vertical load almost wholly in shear (q/p 1.67 on average at the end of the
 * ramp). After the reset the surface passes through that stress (F = 0 to YIELD_TOLERANCE) and a zero
 * step keeps it (to 1e-12 of p, no plastic strain); with the tip the same zero step returns the point
 * to q/p below 0.1. Points given an initial stress are treated alike; one with a stress ratio beyond
 * M / N, which no surface reaches, gets a finite image pressure and stays outside, for its first
 * plastic step to return. A reset of a tensile stress, which the elastic law never gives, takes the
 * stress-free point's p0 instead of a logarithm of a negative pressure. */
static void check_initial_surface_through_stress(void)
{
	static const double I[4] = { 1, 0, 0, 1 };
	double eta_kept = 0, eta_tip = 0, kept_change = 0, F_reset = 0, F_init = 0;
	int ok = 1;
	for (int through = 1; through >= 0; through--) {
		struct material m = table5_landslide();
		m.ns.through_stress = through;
		double stress[4] = { 0, 0, 0, 0 }, Be[4], state[STATE_MAX], plastic = 0;
		nor_sand_init_state(&m, stress, Be, state);
		double dF[4] = { 1.0, 0.0, 0.0, 0.9999 };   /* one-dimensional compression, plane strain */
		struct poro_error err = {0};
		struct stress_update u = { .dF = dF, .J = 0.9999, .stress = stress, .Be = Be, .state = state,
					   .plastic_strain = &plastic, .elastic_only = 1 };
		ok &= material_update(&m, &u, &err) == PORO_OK;
		double p, q, before[4];
		invariants(stress, &p, &q);
		memcpy(before, stress, sizeof before);
		material_reset_reference(&m, stress, Be, u.J, state);
		if (through)
			F_reset = yield_value(&m, u.J * p, u.J * q, state[NOR_SAND_IMAGE_PRESSURE]) / (u.J * (p + q));
		u.dF = I, u.elastic_only = 0;   /* the first step with plasticity, no motion (J stays) */
		ok &= material_update(&m, &u, &err) == PORO_OK;
		double p1, q1, change = 0;
		invariants(stress, &p1, &q1);
		for (int k = 0; k < 4; k++)
			change = fmax(change, fabs(stress[k] - before[k]) / p);
		if (through) {
			eta_kept = q1 / p1, kept_change = change;
			ok &= change <= 1e-12 && plastic == 0.0 && q / p > m.ns.M;
		} else {
			eta_tip = q1 / p1;
			ok &= eta_tip < 0.1;
		}
	}
	/* an initial stress beyond M / N = 10, and one within it, set directly */
	struct material m = table5_landslide();
	m.ns.through_stress = 1;
	double far[4] = { 9.5e3, -30e3, 0, 9.5e3 }, near[4] = { -2e3, -6e3, 0, -2e3 }, Be[4], state[STATE_MAX], p, q;
	nor_sand_init_state(&m, near, Be, state);
	invariants(near, &p, &q);
	F_init = yield_value(&m, p, q, state[NOR_SAND_IMAGE_PRESSURE]) / (p + q);
	nor_sand_init_state(&m, far, Be, state);
	invariants(far, &p, &q);
	const int far_outside = isfinite(state[NOR_SAND_IMAGE_PRESSURE]) && q / p > m.ns.M / m.ns.N &&
				yield_value(&m, p, q, state[NOR_SAND_IMAGE_PRESSURE]) > 0;
	double tensile[4] = { 1e3, 1e3, 0, 1e3 }, Be_unit[4] = { 1, 1, 0, 1 };
	material_reset_reference(&m, tensile, Be_unit, 1.0, state);
	const int tensile_finite = state[NOR_SAND_REFERENCE_PRESSURE] == m.ns.p_start &&
				   isfinite(state[NOR_SAND_IMAGE_PRESSURE]) && isfinite(state[NOR_SAND_CUTOFF_STATE]) &&
				   isfinite(state[NOR_SAND_STATE_PARAMETER]);
	ok &= fabs(F_reset) <= YIELD_TOLERANCE && fabs(F_init) <= YIELD_TOLERANCE && far_outside && tensile_finite;
	printf("INFO nor_sand_initial_surface: after the reset F / (p + q) %.2g; first plastic step: stress change "
	       "%.2g of p and q/p %.3f (through_stress), q/p %.3f (tip); initial stress F / (p + q) %.2g; "
	       "reset of a tensile stress finite: %s\n",
	       F_reset, kept_change, eta_kept, eta_tip, F_init, tensile_finite ? "yes" : "no");
	CHECK(ok, "nor_sand_initial_surface_through_stress_keeps_the_loaded_stress", "see INFO");
}

/* A trial at p_tr = p0 exp(-ev / kappa) with a shear q_tr = 3 G es far beyond the surface, from image
 * pressure pi_n: the return ends at q = 0 with the image pressure solving Eq. 92's backward Euler
 * hardening R2 = pi - pi_n - h es (g(psi_i) p - pi) = 0, at the tip p = c_N pi when that is at most
 * p_tr, else at p = p_tr (the tension cut-off). Both trials are the ones that stopped landslide
 * runs: a liquefied point (tip) and a point pulled apart (cut-off). */
static void check_far_shear(const struct material *m, const char *name, double p_tr, double q_tr, double pi_n,
			    double v, double Ed, int want_tip)
{
	const struct nor_sand_parameters *n = &m->ns;
	struct start st = { .p0 = 1.173e3, .pi = pi_n, .Ed = Ed, .psi_cut = 0.01, .v0 = v };
	double ev = n->kappa * log(st.p0 / p_tr), es = q_tr / (3 * m->mu), d = es * sqrt(0.75);
	double eps[4] = { ev / 3 + d, ev / 3 - d, 0, ev / 3 }, s[4], z[STATE_MAX], p, q;
	int failed = update_from_trial(m, &st, eps, s, z, NULL) != PORO_OK;
	invariants(s, &p, &q);
	double pi = z[NOR_SAND_IMAGE_PRESSURE], cN = pow(1 - n->N, -(1 - n->N) / n->N);
	double psi = Ed + es >= n->cutoff_end ? 0 : v - n->v_c0 + n->lambda * log(pi / n->p_ref);
	double g = pow(1 - n->N * n->alpha * psi / n->M, (n->N - 1) / n->N);
	double R2 = (pi - pi_n - n->h * es * (g * p - pi)) / pi_n;
	double want_p = want_tip ? cN * pi : p_tr;
	printf("INFO %s: trial p %.4g Pa q %.4g Pa, image pressure %.4g -> %.6g Pa, p %.6g Pa (%s %.6g), q %.3g Pa, "
	       "R2 %.2g\n", name, p_tr, q_tr, pi_n, pi, p, want_tip ? "tip" : "trial", want_p, q, R2);
	CHECK(!failed && rel_diff(p, want_p, 1) <= 1e-10 && q <= 1e-9 * q_tr && fabs(R2) <= 1e-12 && p <= p_tr * (1 + 1e-12) &&
	      fabs(z[NOR_SAND_DEVIATORIC_PLASTIC_STRAIN] - (st.Ed + es)) <= 1e-14, name,
	      "failed %d, p %.6g want %.6g, q %.3g, R2 %.3g", failed, p, want_p, q, R2);
}

/* A hydrostatic trial beyond the tip returns to it: q = 0, p = pi (1 - N)^(-(1 - N)/N), pi unchanged
 * (no deviatoric plastic strain, so no hardening). */
static void check_tip(const struct material *m)
{
	struct start st = { .p0 = 81.3e3, .pi = 30.7e3, .Ed = 0.213, .psi_cut = 0.01 };
	double eps[4] = { -1.37e-3, -1.37e-3, 0, -1.37e-3 }, s[4], z[STATE_MAX], p, q;
	update_from_trial(m, &st, eps, s, z, NULL);
	invariants(s, &p, &q);
	double N = m->ns.N, want = 30.7e3 * pow(1 - N, -(1 - N) / N);
	printf("INFO nor_sand_tip_return: p %.12g Pa (closed form %.12g), q %.3g Pa\n", p, want, q);
	CHECK(rel_diff(p, want, 1) <= 1e-12 && q <= 1e-9 * p && rel_diff(z[NOR_SAND_IMAGE_PRESSURE], 30.7e3, 1) <= 1e-12 &&
	      fabs(z[0] - 0.213) <= 1e-15, "nor_sand_tip_return_closed_form", "p %.12g, want %.12g, q %.3g", p, want, q);
}

static int run_case(const char *path, struct element_case *c, struct element_result *r)
{
	struct poro_error err = {0};
	if (element_case_load_file(path, c, &err) || element_run(c, r, &err)) {
		printf("INFO %s failed: %s\n", path, err.message);
		return 0;
	}
	return 1;
}

static void check_undrained(int p0_kpa)
{
	char path[128], name[96];
	snprintf(path, sizeof path, "tests/cases/norsand_undrained_p%d.json", p0_kpa);
	snprintf(name, sizeof name, "nor_sand_undrained_p%d_reaches_critical_state", p0_kpa);
	struct element_case c;
	struct element_result r;
	if (!run_case(path, &c, &r)) {
		CHECK(0, name, "run failed");
		return;
	}
	const struct element_row *w = &r.row[r.rows - 1];
	double peak = 0, dv = 0, M = c.material.critical_stress_ratio;
	for (int i = 0; i < r.rows; i++) {
		peak = fmax(peak, r.row[i].q);
		dv = fmax(dv, fabs(r.row[i].volumetric_strain));
	}
	double ratio = w->q / w->p, psi = w->outputs[3];
	printf("INFO %s: peak q %.4g kPa; at axial strain %g: p %.4g Pa, q %.4g Pa, q/p %.5f (M %g), psi %.5f, "
	       "psi_i %.5f, v %.6g, |ln J| <= %.2g\n", name, peak / 1e3, w->axial_strain, w->p, w->q, ratio, M, psi,
	       w->outputs[2] - c.material.reference_specific_volume +
		       c.material.compression_index * log(w->outputs[1] / c.material.critical_state_reference_pressure),
	       w->outputs[2], dv);
	CHECK(fabs(ratio - M) <= CS_RATIO_TOLERANCE * M && fabs(psi) <= CS_PSI_TOLERANCE && dv <= 1e-10, name,
	      "q/p %.5f, psi %.5f, ln J %.3g", ratio, psi, dv);
	element_result_release(&r);
}

static void check_drained(const char *kind, int dilates)
{
	char path[128], name[96];
	snprintf(path, sizeof path, "tests/cases/norsand_drained_%s.json", kind);
	snprintf(name, sizeof name, "nor_sand_drained_%s_dq_3dp_and_%s", kind, dilates ? "dilates" : "contracts");
	struct element_case c;
	struct element_result r;
	if (!run_case(path, &c, &r)) {
		CHECK(0, name, "run failed");
		return;
	}
	double drift = 0, pc = c.confining_pressure;
	for (int i = 1; i < r.rows; i++)
		drift = fmax(drift, fabs((r.row[i].q - r.row[0].q) - 3 * (r.row[i].p - r.row[0].p)) / pc);
	const struct element_row *w = &r.row[r.rows - 1];
	printf("INFO %s: |dq - 3 dp| / p_c <= %.3g; final volumetric strain %.5f, q/p %.4f, psi %.4f\n", name, drift,
	       w->volumetric_strain, w->q / w->p, w->outputs[3]);
	int sign = dilates ? w->volumetric_strain > 0 : w->volumetric_strain < 0;
	CHECK(drift <= 1e-8 && sign, name, "drift %.3g, volumetric strain %.5f", drift, w->volumetric_strain);
	element_result_release(&r);
}

int main(void)
{
	struct material fin = make(STRAIN_FINITE), sml = make(STRAIN_SMALL);
	check_yield_and_tangent("finite", &fin);
	check_yield_and_tangent("small", &sml);
	check_objectivity(&fin);
	check_reversible("finite", &fin);
	check_reversible("small", &sml);
	check_cutoff(&fin);
	check_tip(&fin);
	struct material landslide = table5_landslide();
	check_far_shear(&landslide, "nor_sand_liquefied_point_returns_to_tip", 22.77, 540.2e3, 0.1293, 1.7756, 0.371, 1);
	check_far_shear(&landslide, "nor_sand_point_pulled_apart_keeps_trial_pressure", 4.902e-4, 828.8e3, 267.7, 2.5406, 1.613, 0);
	check_gas(&fin);
	check_specific_volume_from_J_v(&fin);
	check_initialisation();
	check_initial_surface_through_stress();
	check_undrained(100);
	check_undrained(200);
	check_undrained(300);
	check_drained("dense", 1);
	check_drained("loose", 0);
	HARNESS_EXIT();
}
