/*
 * principal_update.c - kinematics of the Mohr-Coulomb family: small or finite strain around the
 * principal-space return of principal_return.c (principal_return.h).
 *
 * Finite strain (000 Eqs. 69-76): Be_trial = dF Be^t dF^T (Eq. 70; Be_zz scaled by dF_zz^2), its
 * eigen-decomposition Be_trial = P diag(l) P^T (Eq. 73: in plane by sym2_eigen, z out of plane),
 * trial logarithmic elastic strains e = 1/2 ln l (Eq. 74), trial Kirchhoff stresses
 * tau = lambda tr(e) 1 + 2 mu e. The return acts on the principal values; the returned elastic
 * strains e' = D^-1 tau' rebuild Be = P diag(exp(2 e')) P^T (the exponential-map update: the
 * eigenvectors stay those of the trial state) and sigma = tau / J (Eq. 76).
 * Small strain: sigma_trial = sigma^t + D d eps with d eps = sym(dF - I), d eps_zz = dF_zz - 1, the
 * eigen-decomposition of sigma_trial, the return, and sigma rebuilt on the same eigenvectors.
 * An elastic step keeps the trial state as computed (Be_trial, sigma_trial), so loading and
 * unloading within the elastic range returns to the starting state up to rounding.
 *
 * Sorting: the two in-plane principal values come ordered from sym2_eigen; the z value is slotted
 * in by comparison, and `pos` remembers where each went so the return's results and its 3x3
 * tangent go back to their directions.
 *
 * Tangent (material.h layout, tensor shear): for an isotropic function s(e) of the trial elastic
 * strain with in-plane eigenvectors n1 = (c, s), n2 = (-s, c),
 *     T = sum_AB D_AB M_A (x) P_B + g S (x) Q,   g = (s_1 - s_2) / (e_1 - e_2),
 * where M_A = n_A n_A and P_A its strain functional (the xy entry doubled for tensor shear), and
 * S, Q the in-plane spin pair n1 n2 + n2 n1 and n1 . de . n2. When e_1 and e_2 coincide
 * (SPIN_LIMIT) g takes its limit D_11 - D_12.
 */
#include "principal_return.h"

#include <math.h>
#include <string.h>

#define SPIN_LIMIT 1e-10   /* relative gap of the in-plane trial eigenvalues below which g is a limit */

/* e = D^-1 s for the isotropic elastic law (principal values). */
static void elastic_strain(const struct material *m, const double s[3], double e[3])
{
	double tr = s[0] + s[1] + s[2];
	double k = m->lambda / (3.0 * m->lambda + 2.0 * m->mu);
	for (int a = 0; a < 3; a++)
		e[a] = (s[a] - k * tr) / (2.0 * m->mu);
}

/* Symmetric 2x2 (xx, yy, xy) with eigenvalues a, b on the directions of angle theta. */
static void rebuild(double a, double b, double c, double s, double out[3])
{
	out[0] = c * c * a + s * s * b;
	out[1] = s * s * a + c * c * b;
	out[2] = c * s * (a - b);
}

/* pos[slot] = sorted position of the slot (0, 1 in plane, ordered; 2 = z). */
static void sort_slots(const double v[3], int pos[3])
{
	if (v[2] > v[0]) {
		pos[2] = 0, pos[0] = 1, pos[1] = 2;
	} else if (v[2] > v[1]) {
		pos[0] = 0, pos[2] = 1, pos[1] = 2;
	} else {
		pos[0] = 0, pos[1] = 1, pos[2] = 2;
	}
}

/* The 4x4 tangent from the principal one Ds (slot order), the spin factor g and the angle. */
static void assemble_tangent(const double Ds[3][3], double g, double c, double s, double *T)
{
	double M[3][4] = { { c * c, s * s, c * s, 0 }, { s * s, c * c, -c * s, 0 }, { 0, 0, 0, 1 } };
	double P[3][4] = { { c * c, s * s, 2 * c * s, 0 }, { s * s, c * c, -2 * c * s, 0 }, { 0, 0, 0, 1 } };
	double S[4] = { -2 * c * s, 2 * c * s, c * c - s * s, 0 }, Q[4] = { -c * s, c * s, c * c - s * s, 0 };
	for (int i = 0; i < 4; i++)
		for (int j = 0; j < 4; j++) {
			double t = g * S[i] * Q[j];
			for (int A = 0; A < 3; A++)
				for (int B = 0; B < 3; B++)
					t += Ds[A][B] * M[A][i] * P[B][j];
			T[4 * i + j] = t;
		}
}

/* The trial state: principal trial stresses st and strains et (slot order), the angle, and for
 * finite strain Be_trial; gap = e_1 - e_2 computed without cancellation. */
struct trial {
	double st[3], et[3], gap;
	double c, s;
	double sigma[4];         /* small strain: sigma_trial */
	double Be[4];            /* finite strain: Be_trial */
};

static void small_trial(const struct material *m, const struct stress_update *u, struct trial *t)
{
	const double *f = u->dF;
	double dzz = u->dF_zz != 0.0 ? u->dF_zz - 1.0 : 0.0;
	double dxx = f[0] - 1.0, dyy = f[3] - 1.0, dxy = 0.5 * (f[1] + f[2]);
	double lt = m->lambda * (dxx + dyy + dzz);
	t->sigma[0] = u->stress[0] + lt + 2.0 * m->mu * dxx;
	t->sigma[1] = u->stress[1] + lt + 2.0 * m->mu * dyy;
	t->sigma[2] = u->stress[2] + 2.0 * m->mu * dxy;
	t->sigma[3] = u->stress[3] + lt + 2.0 * m->mu * dzz;
	double l[2], theta;
	sym2_eigen(t->sigma[0], t->sigma[1], t->sigma[2], l, &theta);
	t->st[0] = l[0], t->st[1] = l[1], t->st[2] = t->sigma[3];
	elastic_strain(m, t->st, t->et);
	t->gap = (l[0] - l[1]) / (2.0 * m->mu);
	t->c = cos(theta), t->s = sin(theta);
}

/* Be_trial = dF Be^t dF^T (Eq. 70), Be_zz scaled by dF_zz^2. */
static void trial_Be(const struct stress_update *u, double out[4])
{
	const double *f = u->dF, *Be = u->Be;
	double fzz = u->dF_zz != 0.0 ? u->dF_zz : 1.0;
	double a0 = f[0] * Be[0] + f[1] * Be[2], a1 = f[0] * Be[2] + f[1] * Be[1];
	double b0 = f[2] * Be[0] + f[3] * Be[2], b1 = f[2] * Be[2] + f[3] * Be[1];
	out[0] = a0 * f[0] + a1 * f[1];
	out[1] = b0 * f[2] + b1 * f[3];
	out[2] = a0 * f[2] + a1 * f[3];
	out[3] = fzz * Be[3] * fzz;
}

static enum poro_status finite_trial(const struct material *m, const struct stress_update *u, struct trial *t,
				     struct poro_error *err)
{
	trial_Be(u, t->Be);
	double l[2], theta;
	sym2_eigen(t->Be[0], t->Be[1], t->Be[2], l, &theta);
	if (!(l[1] > 0.0) || !(t->Be[3] > 0.0) || !(u->J > 0.0))
		return poro_error_set(err, PORO_ESOLVER, "mohr-coulomb: non-positive stretch (%.3g, %.3g, %.3g), "
				      "J = %.3g", l[0], l[1], t->Be[3], u->J);
	t->et[0] = 0.5 * log(l[0]), t->et[1] = 0.5 * log(l[1]), t->et[2] = 0.5 * log(t->Be[3]);
	double lt = m->lambda * (t->et[0] + t->et[1] + t->et[2]);
	for (int a = 0; a < 3; a++)
		t->st[a] = lt + 2.0 * m->mu * t->et[a];
	t->gap = 0.5 * log1p((l[0] - l[1]) / l[1]);
	t->c = cos(theta), t->s = sin(theta);
	return PORO_OK;
}

enum poro_status principal_update(const struct material *m, plastic_law_fn law, struct stress_update *u,
				  struct poro_error *err)
{
	struct trial t = {0};
	int finite = m->strain == STRAIN_FINITE;
	if (!finite)
		small_trial(m, u, &t);
	else if (finite_trial(m, u, &t, err))
		return PORO_ESOLVER;
	int pos[3];
	sort_slots(t.st, pos);
	struct principal_return pr = { .eps_d = u->state[STATE_DEVIATORIC_PLASTIC_STRAIN], .elastic_only = u->elastic_only };
	for (int a = 0; a < 3; a++)
		pr.s[pos[a]] = t.st[a];
	enum poro_status st = principal_return_map(m, law, &pr, u->tangent != NULL, err);
	if (st)
		return st;
	double s[3], in_plane[3];      /* returned principal stresses, slot order */
	for (int a = 0; a < 3; a++)
		s[a] = pr.regime == RETURN_ELASTIC ? t.st[a] : pr.s[pos[a]];
	if (!finite && pr.regime == RETURN_ELASTIC) {
		memcpy(u->stress, t.sigma, sizeof t.sigma);
	} else if (!finite) {
		rebuild(s[0], s[1], t.c, t.s, in_plane);
		u->stress[0] = in_plane[0], u->stress[1] = in_plane[1], u->stress[2] = in_plane[2];
		u->stress[3] = s[2];
	} else {
		if (pr.regime == RETURN_ELASTIC) {
			memcpy(u->Be, t.Be, sizeof t.Be);
		} else {
			double e[3];
			elastic_strain(m, s, e);
			rebuild(exp(2.0 * e[0]), exp(2.0 * e[1]), t.c, t.s, in_plane);
			u->Be[0] = in_plane[0], u->Be[1] = in_plane[1], u->Be[2] = in_plane[2];
			u->Be[3] = exp(2.0 * e[2]);
		}
		double invJ = 1.0 / u->J;
		rebuild(s[0] * invJ, s[1] * invJ, t.c, t.s, in_plane);
		u->stress[0] = in_plane[0], u->stress[1] = in_plane[1], u->stress[2] = in_plane[2];
		u->stress[3] = s[2] * invJ;
	}
	u->state[STATE_DEVIATORIC_PLASTIC_STRAIN] = pr.eps_d;
	*u->plastic_strain = pr.eps_d;
	if (u->tangent) {
		double Ds[3][3];
		for (int a = 0; a < 3; a++)
			for (int b = 0; b < 3; b++)
				Ds[a][b] = pr.D[pos[a]][pos[b]];
		double scale = fabs(t.et[0]) + fabs(t.et[1]) + 1.0;
		double g = fabs(t.gap) > SPIN_LIMIT * scale ? (s[0] - s[1]) / t.gap : Ds[0][0] - Ds[0][1];
		assemble_tangent(Ds, g, t.c, t.s, u->tangent);
	}
	return PORO_OK;
}

/* ---- spectral kinematics for models with their own principal return (principal_return.h) ---- */

enum poro_status spectral_trial(const struct stress_update *u, int finite, struct spectral_trial *t,
				const char *model, struct poro_error *err)
{
	double l[2], theta;
	if (finite) {
		trial_Be(u, t->Be);
		sym2_eigen(t->Be[0], t->Be[1], t->Be[2], l, &theta);
		if (!(l[1] > 0.0) || !(t->Be[3] > 0.0) || !(u->J > 0.0))
			return poro_error_set(err, PORO_ESOLVER, "%s: non-positive stretch (%.3g, %.3g, %.3g), "
					      "J = %.3g", model, l[0], l[1], t->Be[3], u->J);
		t->e[0] = 0.5 * log(l[0]), t->e[1] = 0.5 * log(l[1]), t->e[2] = 0.5 * log(t->Be[3]);
		t->gap = 0.5 * log1p((l[0] - l[1]) / l[1]);
	} else {
		/* eps^e_trial = 1/2 ln Be^t + sym(dF - I); Be^t holds exp(2 eps^e) */
		const double *f = u->dF, *Be = u->Be;
		double dzz = u->dF_zz != 0.0 ? u->dF_zz - 1.0 : 0.0;
		if (!(Be[0] > 0.0) || !(Be[1] > 0.0) || !(Be[3] > 0.0) || !(u->J > 0.0))
			return poro_error_set(err, PORO_ESOLVER, "%s: elastic strain record not positive definite", model);
		double lb[2], tb, e[4];
		sym2_eigen(Be[0], Be[1], Be[2], lb, &tb);
		if (!(lb[1] > 0.0))
			return poro_error_set(err, PORO_ESOLVER, "%s: elastic strain record not positive definite", model);
		rebuild(0.5 * log(lb[0]), 0.5 * log(lb[1]), cos(tb), sin(tb), e);
		e[0] += f[0] - 1.0, e[1] += f[3] - 1.0, e[2] += 0.5 * (f[1] + f[2]);
		e[3] = 0.5 * log(Be[3]) + dzz;
		sym2_eigen(e[0], e[1], e[2], l, &theta);
		t->e[0] = l[0], t->e[1] = l[1], t->e[2] = e[3];
		t->gap = l[0] - l[1];
		double c = cos(theta), s = sin(theta), in_plane[3];
		rebuild(exp(2.0 * l[0]), exp(2.0 * l[1]), c, s, in_plane);
		t->Be[0] = in_plane[0], t->Be[1] = in_plane[1], t->Be[2] = in_plane[2], t->Be[3] = exp(2.0 * e[3]);
	}
	t->c = cos(theta), t->s = sin(theta);
	return PORO_OK;
}

void spectral_finish(struct stress_update *u, int finite, const struct spectral_trial *t, const double s[3],
		     const double e[3], int elastic, const double Ds[3][3])
{
	double in_plane[3];
	if (elastic) {
		memcpy(u->Be, t->Be, sizeof t->Be);
	} else {
		rebuild(exp(2.0 * e[0]), exp(2.0 * e[1]), t->c, t->s, in_plane);
		u->Be[0] = in_plane[0], u->Be[1] = in_plane[1], u->Be[2] = in_plane[2];
		u->Be[3] = exp(2.0 * e[2]);
	}
	double invJ = finite ? 1.0 / u->J : 1.0;
	rebuild(s[0] * invJ, s[1] * invJ, t->c, t->s, in_plane);
	u->stress[0] = in_plane[0], u->stress[1] = in_plane[1], u->stress[2] = in_plane[2];
	u->stress[3] = s[2] * invJ;
	if (u->tangent && Ds) {
		double scale = fabs(t->e[0]) + fabs(t->e[1]) + 1.0;
		double g = fabs(t->gap) > SPIN_LIMIT * scale ? (s[0] - s[1]) / t->gap : Ds[0][0] - Ds[0][1];
		assemble_tangent(Ds, g, t->c, t->s, u->tangent);
	}
}
