/*
 * principal_return.c - Mohr-Coulomb-family return mapping in principal stress space
 * (principal_return.h; de Souza Neto, Peric and Owen 2008, §8.2.2, Boxes 8.4-8.5).
 *
 * Symbols (the book's, tension positive): s the principal stresses sorted s[0] >= s[1] >= s[2];
 * a_k the gradient of the yield function of plane k, N_k that of the plastic potential;
 * dgamma_k the plastic multipliers; D the isotropic elastic matrix lambda 1 1^T + 2 mu I acting
 * on principal elastic strains; eps_d the deviatoric plastic strain. Plane k = (i, j) is
 *     Phi_k = (s_i - s_j) + (s_i + s_j) sin(phi) - 2 c cos(phi),
 *     N_k: +(1 + sin psi) at i, -(1 - sin psi) at j;
 * the main plane is (0, 2); the edge s0 = s1 adds (1, 2), the edge s1 = s2 adds (0, 1).
 *
 * One return solves, for the m active planes, the m + 1 equations
 *     R_k = Phi_k(s_trial - D sum_l dgamma_l N_l(eps_d), c(eps_d)) = 0,
 *     R_eps = eps_d - eps_d^n - sqrt(2/3) |dev sum_l dgamma_l N_l(eps_d)| = 0,
 * first with eps_d frozen at eps_d^n (linear in dgamma: Box 8.5's closed forms), then by Newton's
 * method on all unknowns until |R_k| <= RETURN_TOLERANCE times the stress scale and |R_eps| <=
 * RETURN_TOLERANCE eps_d. Without hardening the first solve already satisfies both.
 *
 * The consistent tangent differentiates the converged equations: with x = (dgamma, eps_d),
 * dx / de_trial = -(dR/dx)^-1 dR/de_trial, dR_k/de_trial = a_k^T D, dR_eps/de_trial = 0, and
 *     d s / d e_trial = D - D [N_1 .. N_m, sum_l dgamma_l dN_l/d eps_d] dx / de_trial.
 */
#include "principal_return.h"

#include <math.h>
#include <string.h>

#define RETURN_TOLERANCE 1e-12       /* Newton: relative residual of the return (see above) */
#define RETURN_ITERATIONS_MAX 50     /* a piecewise-linear softening law needs 2-3, Eq. 17 4-6 */
#define YIELD_TOLERANCE 1e-12        /* a trial with Phi <= this times the stress scale is elastic */

static const double SQRT_2_3 = 0.81649658092772603273;  /* sqrt(2/3) */

double principal_yield(const struct material *m, const double s[3], double c)
{
	return (s[0] - s[2]) + (s[0] + s[2]) * m->sin_phi - 2.0 * c * m->cos_phi;
}

/* v <- D v for the isotropic elastic matrix. */
static void elastic_times(const struct material *m, const double v[3], double out[3])
{
	double lt = m->lambda * (v[0] + v[1] + v[2]);
	for (int a = 0; a < 3; a++)
		out[a] = lt + 2.0 * m->mu * v[a];
}

/* Gradient of the plane (i, j) with sine sn: +(1 + sn) at i, -(1 - sn) at j. */
static void plane_vector(const int plane[2], double sn, double v[3])
{
	v[0] = v[1] = v[2] = 0.0;
	v[plane[0]] = 1.0 + sn;
	v[plane[1]] = -(1.0 - sn);
}

/* Solves A x = b in place (b becomes x) for n <= 3 by Gaussian elimination with partial
 * pivoting. Returns 0 when A is singular. */
static int solve_small(int n, double A[3][3], double b[3])
{
	for (int k = 0; k < n; k++) {
		int p = k;
		for (int i = k + 1; i < n; i++)
			if (fabs(A[i][k]) > fabs(A[p][k]))
				p = i;
		if (A[p][k] == 0.0)
			return 0;
		if (p != k) {
			for (int j = 0; j < n; j++) {
				double t = A[k][j]; A[k][j] = A[p][j]; A[p][j] = t;
			}
			double t = b[k]; b[k] = b[p]; b[p] = t;
		}
		for (int i = k + 1; i < n; i++) {
			double f = A[i][k] / A[k][k];
			for (int j = k; j < n; j++)
				A[i][j] -= f * A[k][j];
			b[i] -= f * b[k];
		}
	}
	for (int k = n - 1; k >= 0; k--) {
		for (int j = k + 1; j < n; j++)
			b[k] -= A[k][j] * b[j];
		b[k] /= A[k][k];
	}
	return 1;
}

/* One return's equations for the planes[0..m-1] at x = (dgamma_0 .. dgamma_{m-1}, eps_d):
 * residual R[m+1], Jacobian J = dR/dx, stresses s, and the flow columns NG (N_k, then
 * sum dgamma dN/d eps_d) for the tangent. */
struct system {
	const struct material *m;
	plastic_law_fn law;
	int planes;              /* m, active planes: 1 or 2 */
	const int (*plane)[2];   /* [planes] */
	double s_trial[3], eps_n, scale;
};

static void evaluate(const struct system *sys, const double *x, double R[3], double J[3][3], double s[3],
		     double NG[3][3])
{
	const struct material *m = sys->m;
	int n = sys->planes;
	struct plastic_law law;
	sys->law(m, x[n], &law);
	double N[2][3], dN[3], ep[3] = {0, 0, 0}, G[3] = {0, 0, 0}, DN[3][3], DG[3];
	for (int k = 0; k < n; k++) {
		plane_vector(sys->plane[k], law.sin_psi, N[k]);
		dN[0] = dN[1] = dN[2] = 0.0;
		dN[sys->plane[k][0]] = dN[sys->plane[k][1]] = law.dsin_psi;
		for (int a = 0; a < 3; a++) {
			ep[a] += x[k] * N[k][a];
			G[a] += x[k] * dN[a];
		}
		elastic_times(m, N[k], DN[k]);
	}
	elastic_times(m, G, DG);
	double Dep[3];
	elastic_times(m, ep, Dep);
	for (int a = 0; a < 3; a++)
		s[a] = sys->s_trial[a] - Dep[a];
	double mean = (ep[0] + ep[1] + ep[2]) / 3.0, d[3], nd = 0.0;
	for (int a = 0; a < 3; a++) {
		d[a] = ep[a] - mean;
		nd += d[a] * d[a];
	}
	nd = sqrt(nd);
	for (int k = 0; k < n; k++) {
		double av[3];
		plane_vector(sys->plane[k], m->sin_phi, av);
		R[k] = av[0] * s[0] + av[1] * s[1] + av[2] * s[2] - 2.0 * law.c * m->cos_phi;
		for (int l = 0; l < n; l++)
			J[k][l] = -(av[0] * DN[l][0] + av[1] * DN[l][1] + av[2] * DN[l][2]);
		J[k][n] = -(av[0] * DG[0] + av[1] * DG[1] + av[2] * DG[2]) - 2.0 * m->cos_phi * law.dc;
	}
	R[n] = x[n] - sys->eps_n - SQRT_2_3 * nd;
	/* d|d|/dx = d . (dx of ep) / |d| (d is deviatoric, so dev of the derivative is not needed) */
	double inv = nd > 0.0 ? SQRT_2_3 / nd : 0.0;
	for (int l = 0; l < n; l++)
		J[n][l] = -inv * (d[0] * N[l][0] + d[1] * N[l][1] + d[2] * N[l][2]);
	J[n][n] = 1.0 - inv * (d[0] * G[0] + d[1] * G[1] + d[2] * G[2]);
	if (NG) {
		for (int a = 0; a < 3; a++) {
			for (int k = 0; k < n; k++)
				NG[a][k] = N[k][a];
			NG[a][n] = G[a];
		}
	}
}

static int converged(const struct system *sys, const double *x, const double R[3])
{
	for (int k = 0; k < sys->planes; k++)
		if (!(fabs(R[k]) <= RETURN_TOLERANCE * sys->scale))
			return 0;
	return fabs(R[sys->planes]) <= RETURN_TOLERANCE * fabs(x[sys->planes]);
}

/* Solves the return to the planes of sys; x[planes + 1] gets (dgamma, eps_d), s the stresses.
 * Returns PORO_OK, or PORO_ESOLVER if Newton fails. */
static enum poro_status solve_return(const struct system *sys, double x[3], double s[3], int *iterations,
				     struct poro_error *err)
{
	int n = sys->planes;
	double R[3], J[3][3];
	/* First solve, eps_d frozen at eps_d^n: the dgamma block is linear. */
	x[0] = x[1] = 0.0;
	x[n] = sys->eps_n;
	evaluate(sys, x, R, J, s, NULL);
	double b[3] = { -R[0], -R[1], 0.0 };
	if (!solve_small(n, J, b))
		return poro_error_set(err, PORO_ESOLVER, "mohr-coulomb return: singular plane system");
	for (int k = 0; k < n; k++)
		x[k] = b[k];
	evaluate(sys, x, R, J, s, NULL);
	x[n] -= R[n];                   /* eps_d consistent with dgamma at psi(eps_d^n) */
	for (*iterations = 0;; (*iterations)++) {
		evaluate(sys, x, R, J, s, NULL);
		if (converged(sys, x, R))
			return PORO_OK;
		if (*iterations == RETURN_ITERATIONS_MAX)
			return poro_error_set(err, PORO_ESOLVER, "mohr-coulomb return: no convergence in %d Newton "
					      "iterations (residual %.3g Pa, eps_d %.6g)", RETURN_ITERATIONS_MAX,
					      fabs(R[0]), x[n]);
		for (int k = 0; k <= n; k++)
			b[k] = -R[k];
		if (!solve_small(n + 1, J, b))
			return poro_error_set(err, PORO_ESOLVER, "mohr-coulomb return: singular Newton system "
					      "(softening too steep for the elastic stiffness?)");
		for (int k = 0; k <= n; k++)
			x[k] += b[k];
	}
}

/* d s / d e_trial of a converged plane or edge return (see the file comment). */
static void return_tangent(const struct system *sys, const double *x, double D[3][3])
{
	const struct material *m = sys->m;
	int n = sys->planes;
	double R[3], J[3][3], s[3], NG[3][3];
	evaluate(sys, x, R, J, s, NG);
	double X[3][3];                 /* dx / de_trial, (n + 1) x 3 */
	for (int b = 0; b < 3; b++) {
		double rhs[3] = {0, 0, 0}, Jc[3][3], e[3] = {0, 0, 0}, De[3];
		e[b] = 1.0;
		elastic_times(m, e, De);     /* column b of D */
		for (int k = 0; k < n; k++) {
			double av[3];
			plane_vector(sys->plane[k], m->sin_phi, av);
			rhs[k] = -(av[0] * De[0] + av[1] * De[1] + av[2] * De[2]);
		}
		memcpy(Jc, J, sizeof Jc);
		solve_small(n + 1, Jc, rhs);
		for (int k = 0; k <= n; k++)
			X[k][b] = rhs[k];
	}
	for (int a = 0; a < 3; a++)
		for (int b = 0; b < 3; b++) {
			double v[3] = {0, 0, 0}, Dv[3];  /* NG X column b */
			for (int c = 0; c < 3; c++)
				for (int k = 0; k <= n; k++)
					v[c] += NG[c][k] * X[k][b];
			elastic_times(m, v, Dv);
			double e[3] = {0, 0, 0}, De[3];
			e[b] = 1.0;
			elastic_times(m, e, De);
			D[a][b] = De[a] - Dv[a];
		}
}

static void elastic_matrix(const struct material *m, double D[3][3])
{
	for (int a = 0; a < 3; a++)
		for (int b = 0; b < 3; b++)
			D[a][b] = m->lambda + (a == b ? 2.0 * m->mu : 0.0);
}

/* Apex: s = c(eps_d) cot(phi) 1 with the whole deviatoric trial strain plastic. For psi <= 0 the
 * plastic potential has no apex (its normals never point into hydrostatic tension), so this
 * return is then a tension cut-off at the apex rather than a flow-rule return; Box 8.5's volumetric
 * hardening variable (which divides by sin psi) is not needed because eps_d is deviatoric. */
static enum poro_status apex_return(const struct material *m, plastic_law_fn law, struct principal_return *pr,
				    int want_tangent, struct poro_error *err)
{
	if (!(m->sin_phi > 0.0))
		return poro_error_set(err, PORO_ESOLVER, "mohr-coulomb return: no valid plane or edge return "
				      "and no apex (friction angle 0)");
	double mean = (pr->s[0] + pr->s[1] + pr->s[2]) / 3.0, dev[3], nd = 0.0;
	for (int a = 0; a < 3; a++) {
		dev[a] = pr->s[a] - mean;
		nd += dev[a] * dev[a];
	}
	nd = sqrt(nd);
	struct plastic_law lw;
	pr->eps_d += SQRT_2_3 * nd / (2.0 * m->mu);
	law(m, pr->eps_d, &lw);
	double cot = m->cos_phi / m->sin_phi;
	for (int a = 0; a < 3; a++)
		pr->s[a] = lw.c * cot;
	pr->regime = RETURN_APEX;
	if (want_tangent)
		for (int a = 0; a < 3; a++)
			for (int b = 0; b < 3; b++)
				pr->D[a][b] = nd > 0.0 ? cot * lw.dc * SQRT_2_3 * dev[b] / nd : 0.0;
	return PORO_OK;
}

/* Tries the return to the planes of regime; returns 1 and fills pr when it converges and the
 * returned stresses keep their order, 0 when it is not the valid return, -1 on a solver failure. */
static int try_return(const struct material *m, plastic_law_fn law, struct principal_return *pr,
		      enum principal_regime regime, double scale, int want_tangent, struct poro_error *err)
{
	static const int PLANE[1][2] = { {0, 2} };
	static const int EDGE_12[2][2] = { {0, 2}, {1, 2} };
	static const int EDGE_23[2][2] = { {0, 2}, {0, 1} };
	struct system sys = { .m = m, .law = law, .eps_n = pr->eps_d, .scale = scale };
	memcpy(sys.s_trial, pr->s, sizeof sys.s_trial);
	sys.planes = regime == RETURN_PLANE ? 1 : 2;
	sys.plane = regime == RETURN_PLANE ? PLANE : regime == RETURN_EDGE_12 ? EDGE_12 : EDGE_23;
	double x[3], s[3];
	int iterations = 0;
	if (solve_return(&sys, x, s, &iterations, err))
		return -1;
	/* Order check (Box 8.5): the pair an edge makes equal is not compared. */
	int ok = regime == RETURN_PLANE ? s[0] >= s[1] && s[1] >= s[2]
		 : regime == RETURN_EDGE_12 ? s[1] >= s[2] : s[0] >= s[1];
	if (!ok)
		return 0;
	memcpy(pr->s, s, sizeof pr->s);
	pr->eps_d = x[sys.planes];
	pr->regime = regime;
	pr->iterations = iterations;
	if (want_tangent)
		return_tangent(&sys, x, pr->D);
	return 1;
}

enum poro_status principal_return_map(const struct material *m, plastic_law_fn law, struct principal_return *pr,
				      int want_tangent, struct poro_error *err)
{
	struct plastic_law lw;
	law(m, pr->eps_d, &lw);
	double scale = fabs(pr->s[0]) + fabs(pr->s[2]) + 2.0 * lw.c * m->cos_phi;
	pr->iterations = 0;
	if (pr->elastic_only || principal_yield(m, pr->s, lw.c) <= YIELD_TOLERANCE * scale) {
		pr->regime = RETURN_ELASTIC;
		if (want_tangent)
			elastic_matrix(m, pr->D);
		return PORO_OK;
	}
	int done = try_return(m, law, pr, RETURN_PLANE, scale, want_tangent, err);
	if (done == 0) {
		/* Box 8.4: the edge on the side the trial stress leans to */
		double side = (1.0 - lw.sin_psi) * pr->s[0] - 2.0 * pr->s[1] + (1.0 + lw.sin_psi) * pr->s[2];
		done = try_return(m, law, pr, side > 0.0 ? RETURN_EDGE_23 : RETURN_EDGE_12, scale, want_tangent, err);
	}
	if (done < 0)
		return PORO_ESOLVER;
	if (done == 0)
		return apex_return(m, law, pr, want_tangent, err);
	return PORO_OK;
}
