/*
 * material_check.h - checks every plastic model's test runs (tests/solver/<model>_test.c):
 * stress on the yield surface after plastic steps, consistent tangent against central finite
 * differences in each return regime, objectivity under a rigid rotation, reversibility of an
 * elastic step. Included by one test program each; uses harness.h's CHECK and rnd().
 *
 * A "trial elastic strain" eps (xx, yy, xy, zz; tensor shear) stands for the state entering a
 * step: small strain, sigma^t = D eps and dF = I; finite strain, Be^t = exp(2 eps), dF = I and
 * J = 1 (so sigma = tau). The update's tangent is then d sigma / d eps or d tau / d eps, the
 * quantity material.h documents, and central differences perturb eps itself.
 */
#ifndef PORO_TEST_MATERIAL_CHECK_H
#define PORO_TEST_MATERIAL_CHECK_H

#include "../harness.h"
#include "material.h"
#include "principal_values.h"
#include "principal_return.h"

#define FD_STEP 1e-8             /* central-difference step on a strain component (strains ~1e-3) */
#define TANGENT_TOLERANCE 1e-6   /* relative to the largest entry of the tangent (or mu if zero) */
#define YIELD_CHECK_TOLERANCE 1e-10
#define SAMPLES_PER_REGIME 25
#define SAMPLE_TRIES 200000

static const char *const regime_names[] = { "elastic", "plane", "edge_12", "edge_23", "apex" };

/* Symmetric 2x2 (xx, yy, xy) function f applied through the eigen-decomposition. */
static void sym2_apply(const double a[3], double (*f)(double), double out[3])
{
	double l[2], th;
	sym2_eigen(a[0], a[1], a[2], l, &th);
	double c = cos(th), s = sin(th), f0 = f(l[0]), f1 = f(l[1]);
	out[0] = c * c * f0 + s * s * f1;
	out[1] = s * s * f0 + c * c * f1;
	out[2] = c * s * (f0 - f1);
}

static double exp2x(double x) { return exp(2.0 * x); }

/* One update from the trial elastic strain eps with deviatoric plastic strain *eps_d (updated). */
static enum poro_status update_from_trial(const struct material *m, const double eps[4], double *eps_d,
					  double stress[4], double *tangent)
{
	static const double I[4] = { 1, 0, 0, 1 };
	double Be[4] = { 1, 1, 0, 1 }, state[STATE_MAX] = {0}, plastic = 0;
	struct poro_error err = {0};
	state[STATE_DEVIATORIC_PLASTIC_STRAIN] = *eps_d;
	if (material_is_finite_strain(m)) {
		double b[3];
		sym2_apply(eps, exp2x, b);
		Be[0] = b[0], Be[1] = b[1], Be[2] = b[2], Be[3] = exp(2.0 * eps[3]);
	} else {
		double tr = eps[0] + eps[1] + eps[3];
		stress[0] = m->lambda * tr + 2 * m->mu * eps[0];
		stress[1] = m->lambda * tr + 2 * m->mu * eps[1];
		stress[2] = 2 * m->mu * eps[2];
		stress[3] = m->lambda * tr + 2 * m->mu * eps[3];
	}
	struct stress_update u = { .dF = I, .J = 1.0, .stress = stress, .Be = Be, .state = state,
				   .plastic_strain = &plastic, .tangent = tangent };
	enum poro_status st = material_update(m, &u, &err);
	if (st)
		printf("INFO update failed: %s\n", err.message);
	*eps_d = state[STATE_DEVIATORIC_PLASTIC_STRAIN];
	return st;
}

/* Regime of the return from the trial elastic strain eps (a reference computation of the trial). */
static enum principal_regime regime_of(const struct material *m, plastic_law_fn law, const double eps[4],
				       double eps_d)
{
	double l[2], th, e[3];
	sym2_eigen(eps[0], eps[1], eps[2], l, &th);
	e[0] = l[0], e[1] = l[1], e[2] = eps[3];
	double tr = e[0] + e[1] + e[2], s[3];
	for (int a = 0; a < 3; a++)
		s[a] = m->lambda * tr + 2 * m->mu * e[a];
	struct principal_return pr = { .eps_d = eps_d };
	/* sort descending */
	for (int a = 0; a < 3; a++)
		pr.s[a] = s[a];
	for (int a = 0; a < 3; a++)
		for (int b = a + 1; b < 3; b++)
			if (pr.s[b] > pr.s[a]) {
				double t = pr.s[a]; pr.s[a] = pr.s[b]; pr.s[b] = t;
			}
	struct poro_error err = {0};
	if (principal_return_map(m, law, &pr, 0, &err))
		return RETURN_ELASTIC;
	return pr.regime;
}

/* A random trial elastic strain: volumetric part in [vlo, vhi], deviatoric up to dev. */
static void random_trial(double vlo, double vhi, double dev, double eps[4])
{
	double v = rnd(vlo, vhi);
	eps[0] = v / 3 + rnd(-dev, dev);
	eps[1] = v / 3 + rnd(-dev, dev);
	eps[2] = rnd(-dev, dev);
	eps[3] = v / 3 + rnd(-dev, dev);
}

/* Largest |Phi| / scale over plastic trial states from random_trial(vlo, vhi, dev), with the
 * deviatoric plastic strain before the step drawn from [0, eps_d_max]. */
static void check_yield_surface(const char *name, const struct material *m, plastic_law_fn law, double vlo,
				double vhi, double dev, double eps_d_max)
{
	double worst = 0;
	int plastic = 0, failed = 0;
	for (int i = 0; i < 2000; i++) {
		double eps[4], stress[4], eps_d0 = rnd(0, eps_d_max), eps_d = eps_d0;
		random_trial(vlo, vhi, dev, eps);
		if (regime_of(m, law, eps, eps_d0) == RETURN_ELASTIC)
			continue;
		failed += update_from_trial(m, eps, &eps_d, stress, NULL) != PORO_OK;
		double s[3];
		struct plastic_law lw;
		sorted_principal(stress, s);
		law(m, eps_d, &lw);
		double scale = fabs(s[0]) + fabs(s[2]) + 2 * lw.c * m->cos_phi;
		double e = fabs(principal_yield(m, s, lw.c)) / scale;
		worst = e > worst ? e : worst;
		plastic++;
	}
	printf("INFO %s: %d plastic steps, largest |Phi| / scale %.3g\n", name, plastic, worst);
	CHECK(plastic > 500 && !failed && worst <= YIELD_CHECK_TOLERANCE, name,
	      "%d plastic steps, %d failed, |Phi| / scale %.3g", plastic, failed, worst);
}

/* Central-difference tangent at eps; returns 0 if a perturbed state changed regime. */
static int fd_tangent(const struct material *m, plastic_law_fn law, const double eps[4], double eps_d,
		      enum principal_regime regime, double *T)
{
	for (int j = 0; j < 4; j++) {
		double ep[4], em[4], sp[4], sm[4], dp = eps_d, dm = eps_d;
		memcpy(ep, eps, sizeof ep);
		memcpy(em, eps, sizeof em);
		ep[j] += FD_STEP, em[j] -= FD_STEP;
		if (regime_of(m, law, ep, eps_d) != regime || regime_of(m, law, em, eps_d) != regime)
			return 0;
		update_from_trial(m, ep, &dp, sp, NULL);
		update_from_trial(m, em, &dm, sm, NULL);
		for (int i = 0; i < 4; i++)
			T[4 * i + j] = (sp[i] - sm[i]) / (2 * FD_STEP);
	}
	return 1;
}

/* For each regime in `regimes` (bit mask of 1 << regime), SAMPLES_PER_REGIME random states whose
 * consistent tangent must match the central-difference one. kink: a deviatoric plastic strain the
 * law has a kink at (0 for none); samples whose step crosses it are skipped. */
static void check_tangent(const char *name, const struct material *m, plastic_law_fn law, unsigned regimes,
			  double vlo, double vhi, double dev, double eps_d_max, double kink)
{
	double worst[5] = {0};
	int count[5] = {0};
	for (int i = 0; i < SAMPLE_TRIES; i++) {
		double eps[4], eps_d0 = rnd(0, eps_d_max), eps_d = eps_d0, stress[4], T[16], Tfd[16];
		random_trial(vlo, vhi, dev, eps);
		enum principal_regime r = regime_of(m, law, eps, eps_d0);
		if (!(regimes & (1u << r)) || count[r] >= SAMPLES_PER_REGIME)
			continue;
		if (update_from_trial(m, eps, &eps_d, stress, T))
			continue;
		if (kink > 0 && (eps_d0 - kink) * (eps_d - kink) <= 0 && r != RETURN_ELASTIC)
			continue;
		if (kink > 0 && fabs(eps_d - kink) < 1e-6 * kink)
			continue;
		if (!fd_tangent(m, law, eps, eps_d0, r, Tfd))
			continue;
		double big = 0, diff = 0;
		for (int k = 0; k < 16; k++) {
			big = fmax(big, fabs(Tfd[k]));
			diff = fmax(diff, fabs(T[k] - Tfd[k]));
		}
		double e = diff / fmax(big, m->mu);
		worst[r] = fmax(worst[r], e);
		count[r]++;
	}
	for (int r = 0; r < 5; r++) {
		if (!(regimes & (1u << r)))
			continue;
		char check[160];
		snprintf(check, sizeof check, "%s_%s", name, regime_names[r]);
		printf("INFO %s: %d states, largest |T - T_fd| / max|T_fd| %.3g (step %g)\n", check, count[r],
		       worst[r], FD_STEP);
		CHECK(count[r] >= SAMPLES_PER_REGIME && worst[r] <= TANGENT_TOLERANCE, check,
		      "%d states, error %.3g", count[r], worst[r]);
	}
}

/* One step dF from the state (stress, Be, eps_d) given by the trial strain eps0 after its return. */
static enum poro_status step_from(const struct material *m, const double eps0[4], const double dF[4], double dF_zz,
				  double stress[4], double *eps_d_out)
{
	static const double I[4] = { 1, 0, 0, 1 };
	double Be[4] = { 1, 1, 0, 1 }, state[STATE_MAX] = {0}, plastic = 0, J = 1;
	struct poro_error err = {0};
	if (material_is_finite_strain(m)) {
		double b[3];
		sym2_apply(eps0, exp2x, b);
		Be[0] = b[0], Be[1] = b[1], Be[2] = b[2], Be[3] = exp(2.0 * eps0[3]);
	} else {
		double tr = eps0[0] + eps0[1] + eps0[3];
		stress[0] = m->lambda * tr + 2 * m->mu * eps0[0];
		stress[1] = m->lambda * tr + 2 * m->mu * eps0[1];
		stress[2] = 2 * m->mu * eps0[2];
		stress[3] = m->lambda * tr + 2 * m->mu * eps0[3];
	}
	struct stress_update u = { .dF = I, .J = 1.0, .stress = stress, .Be = Be, .state = state,
				   .plastic_strain = &plastic };
	enum poro_status st = material_update(m, &u, &err);          /* return the start state */
	J = (dF[0] * dF[3] - dF[1] * dF[2]) * dF_zz;
	u.dF = dF, u.dF_zz = dF_zz, u.J = J;
	if (!st)
		st = material_update(m, &u, &err);
	*eps_d_out = state[STATE_DEVIATORIC_PLASTIC_STRAIN];
	return st;
}

/* Finite strain: dF = R U against dF = U from the same plastic state: the Cauchy stresses'
 * principal values agree, and sigma(RU) = R sigma(U) R^T. */
static void check_objectivity(const char *name, const struct material *m, double vlo, double vhi, double dev)
{
	double worst = 0;
	int plastic = 0;
	for (int i = 0; i < 200; i++) {
		double eps0[4], U[4], RU[4], a = rnd(-3.1, 3.1), c = cos(a), s = sin(a), su[4], sr[4], du, dr;
		random_trial(vlo, vhi, dev, eps0);
		U[0] = 1 + rnd(-0.02, 0.02), U[3] = 1 + rnd(-0.02, 0.02), U[1] = U[2] = rnd(-0.01, 0.01);
		RU[0] = c * U[0] - s * U[2], RU[1] = c * U[1] - s * U[3];
		RU[2] = s * U[0] + c * U[2], RU[3] = s * U[1] + c * U[3];
		double zz = 1 + rnd(-0.01, 0.01);
		if (step_from(m, eps0, U, zz, su, &du) || step_from(m, eps0, RU, zz, sr, &dr))
			continue;
		double pu[3], pr[3], rot[4];
		sorted_principal(su, pu);
		sorted_principal(sr, pr);
		/* R sigma R^T */
		double xx = su[0], yy = su[1], xy = su[2];
		rot[0] = c * c * xx - 2 * c * s * xy + s * s * yy;
		rot[1] = s * s * xx + 2 * c * s * xy + c * c * yy;
		rot[2] = c * s * (xx - yy) + (c * c - s * s) * xy;
		rot[3] = su[3];
		double scale = fabs(pu[0]) + fabs(pu[2]);
		for (int k = 0; k < 3; k++)
			worst = fmax(worst, fabs(pu[k] - pr[k]) / scale);
		for (int k = 0; k < 4; k++)
			worst = fmax(worst, fabs(rot[k] - sr[k]) / scale);
		worst = fmax(worst, fabs(du - dr) / fmax(du, 1e-300));
		plastic += du > 0;
	}
	printf("INFO %s: %d plastic of 200 rotated steps, largest relative difference %.3g\n", name, plastic, worst);
	CHECK(plastic > 50 && worst <= 1e-10, name, "%d plastic, difference %.3g", plastic, worst);
}

/* An elastic step dF and its inverse return the stress to where it started. */
static void check_reversible(const char *name, const struct material *m, plastic_law_fn law)
{
	static const double I[4] = { 1, 0, 0, 1 };
	double worst = 0;
	int elastic = 0;
	for (int i = 0; i < 200; i++) {
		double eps0[4], stress[4], Be[4] = { 1, 1, 0, 1 }, state[STATE_MAX] = {0}, plastic = 0;
		random_trial(-2e-3, -1e-3, 1e-5, eps0);
		double dF[4], inv[4], zz = 1 + rnd(-1e-5, 1e-5);
		dF[0] = 1 + rnd(-1e-5, 1e-5), dF[3] = 1 + rnd(-1e-5, 1e-5), dF[1] = rnd(-1e-5, 1e-5), dF[2] = rnd(-1e-5, 1e-5);
		double det = dF[0] * dF[3] - dF[1] * dF[2];
		if (material_is_finite_strain(m)) {
			inv[0] = dF[3] / det, inv[3] = dF[0] / det, inv[1] = -dF[1] / det, inv[2] = -dF[2] / det;
			double b[3];
			sym2_apply(eps0, exp2x, b);
			Be[0] = b[0], Be[1] = b[1], Be[2] = b[2], Be[3] = exp(2.0 * eps0[3]);
		} else {
			for (int k = 0; k < 4; k++)
				inv[k] = I[k] - (dF[k] - I[k]);
			double tr = eps0[0] + eps0[1] + eps0[3];
			stress[0] = m->lambda * tr + 2 * m->mu * eps0[0];
			stress[1] = m->lambda * tr + 2 * m->mu * eps0[1];
			stress[2] = 2 * m->mu * eps0[2];
			stress[3] = m->lambda * tr + 2 * m->mu * eps0[3];
		}
		struct poro_error err = {0};
		struct stress_update u = { .dF = I, .J = 1.0, .stress = stress, .Be = Be, .state = state,
					   .plastic_strain = &plastic };
		material_update(m, &u, &err);
		double start[4];
		memcpy(start, stress, sizeof start);
		u.dF = dF, u.dF_zz = zz, u.J = det * zz;
		material_update(m, &u, &err);
		u.dF = inv, u.dF_zz = material_is_finite_strain(m) ? 1 / zz : 2 - zz, u.J = 1.0;
		material_update(m, &u, &err);
		double scale = fabs(start[0]) + fabs(start[1]) + fabs(start[3]);
		for (int k = 0; k < 4; k++)
			worst = fmax(worst, fabs(stress[k] - start[k]) / scale);
		elastic += plastic == 0;
	}
	(void)law;
	printf("INFO %s: 200 load-unload pairs, largest relative difference %.3g\n", name, worst);
	CHECK(elastic == 200 && worst <= 1e-12, name, "%d elastic, difference %.3g", elastic, worst);
}

#endif
