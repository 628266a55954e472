/*
 * material_nor_sand.c - Nor-Sand (Jefferies 1993) with the implicit return mapping of Borja and
 * Andrade (2006, Comput. Methods Appl. Mech. Engrg. 195) in principal elastic strains, and the
 * changes of 000 App. B.1 for large deformation. Finite strain (000 Eqs. 69-76: Be, logarithmic
 * strain, Kirchhoff stress) or small strain, both through the spectral kinematics of
 * principal_update.c (principal_return.h).
 *
 * Symbols. Inside this file pressures are compression positive (Borja and Andrade's p and pi_i are
 * negative); strains are tension positive, as everywhere else.
 *   e[3]       principal elastic strains of the trial (e_tr) and of the result
 *   ev, es     elastic volumetric strain tr e and deviatoric strain sqrt(2/3) |dev e|
 *   p, q       -tr tau / 3 and sqrt(3/2) |dev tau| of the Kirchhoff stress tau
 *   p0, ev0    the point's reference pressure and the elastic volumetric strain at it (state)
 *   pi         image pressure; v, v0 specific volume (v = J v0, 000 Eq. 95; v = J_v v0, Eq. 96,
 *              when the scheme passes the node-wise averaged J of Eq. 97 as u->J_v, material.h)
 *   psi_i      state parameter at the image, v - v_c0 + lambda ln(pi / p_ref)
 *   dl         plastic multiplier, equal to the increment of eps_s^p because dQ/dq = 1
 *   Ed         accumulated deviatoric plastic strain E_d^p of 000 Eq. 92 (state slot 0)
 *
 * Elasticity: Borja, Tamagnini and Amorosi's hyperelastic law with its coupling constant alpha = 0,
 * which is what 000 Table 6 gives (a constant shear modulus G and a swelling index kappa):
 *     p = p0 exp(-(ev - ev0) / kappa),   q = 3 G es,   so the bulk modulus is K = p / kappa.
 * Yield function (N > 0; N = 0 is its limit):
 *     F = q - eta p,  eta = M / N [1 - (1 - N) (p / pi)^(N / (1 - N))]   (N = 0: M [1 + ln(pi / p)]).
 * Plastic potential: the same form with Nbar through the current stress; its gradient is
 *     d eps_v^p = dl D,  D = (q / p - M) / (1 - Nbar)  (dilation positive),  d eps_s^p = dl.
 * Hardening, backward Euler: pi = pi_n + h dl (pi* - pi), with the limit image pressure of the
 * maximum dilatancy D* = alpha psi_i (alpha < 0; dense psi_i < 0 dilates):
 *     pi* / p = (1 - N D* / M)^((N - 1) / N)   (N = 0: exp(D* / M)).
 * The N > 0 form is Borja and Andrade's; the N = 0 form is its limit (both put the stress ratio of
 * the yield surface at p to M + (1 - N) D*, the stress-dilatancy of Nor-Sand at D = D*).
 *
 * Return mapping: the deviatoric direction of the trial is kept (isotropic elasticity, potential in
 * p and q), so the unknowns are x = (ln p, es, ln pi), with dl = es_tr - es and ev = ev0 - kappa
 * ln(p / p0):
 *     R0 = ev - ev_tr + dl D(p, q),   R1 = F(p, q, pi) / p,   R2 = (pi - pi_n - h dl (pi* - pi)) / pi_n,
 * solved by Newton's method with backtracking, from the trial pressure, the old image pressure and
 * the q of the surface there. Borja and Andrade iterate on the elastic strains; ln p makes R0 linear
 * where ev makes p = exp(..) overshoot (kappa = 0.002), and es rather than dl as unknown keeps
 * q = 3 G es free of cancellation near liquefaction (q of a few Pa against 3 G of 1e8 Pa). When
 * the smooth return fails or would give es < 0 the stress goes to the tip of the surface (q = 0,
 * p = c_N pi, c_N = (1 - N)^(-(1 - N)/N), or e for N = 0), the whole deviatoric trial strain being
 * plastic (dl = es_tr); pi then solves R2 alone. If that tip would lie above the trial pressure the
 * stress stays at the trial pressure with q = 0 (a tension cut-off, tip_return()).
 *
 * 000 App. B.1:
 *   Eq. 92, dilatancy cut-off: with Ed = E_d^p after the step, psi_i is the usual value while
 *     Ed <= cutoff_start, (1 - (Ed - start) / (end - start)) psi_cut between, 0 from cutoff_end on.
 *     psi_cut ("psi_i at Ed = start") is recorded at the end of every step that ends with
 *     Ed <= start, so the step that crosses the start uses psi_i of its starting state.
 *   Eqs. 93-94, gas-like state: when v > v_crit = gas_ratio v0 the update returns sigma = 0, Be = I
 *     exactly (E^e = 0; sym2_eigen is closed form and needs no unequal eigenvalues), a zero tangent,
 *     and keeps E_d^p and pi. Once v <= v_crit again the next step starts from Be = I, so the
 *     stress restarts at p = p0 exp(ev0 / kappa) plus what that step's dF adds.
 *   Eqs. 95-97: v = J v0 with J = u->J, or u->J_v when the scheme gives one.
 *
 * Tangent: Ds = d tau / d e_tr from the linearised system (material.h), with J held fixed; the
 * specific volume's dependence on J is not linearised (J is an input of the update).
 */
#include <math.h>
#include <string.h>

#include "principal_return.h"

#define NS_TOLERANCE 1e-13        /* Newton: |R0|, |R1| / (p + q), |R2| / pi_n */
#define NS_STAGNATION 1e-15       /* ... or a correction this small relative to x */
#define NS_ITERATIONS_MAX 80
#define NS_BACKTRACK_MAX 40
#define NS_YIELD_TOLERANCE 1e-12  /* a trial with F <= this (p + q) is elastic */
#define NS_BRACKET_SPAN 200.0     /* the tip return brackets its root within e^(+-200) of its junction */
#define NS_BRACKET_ITERATIONS 200 /* safeguarded Newton: bisection alone needs ~60 from span 1 */

/* Where a plastic return ends (tip_return). */
enum { RETURN_SMOOTH, TIP_CORNER, TIP_TENSION };

static const double SQRT_2_3 = 0.81649658092772603273;   /* sqrt(2/3) */

/* The data of one point's return. */
struct ns_point {
	const struct nor_sand_parameters *n;
	double G, v, p0, ev0, pi_n, Ed_n, psi_cut;
	double ev_tr, es_tr;
};

static double pressure(const struct ns_point *c, double ev)
{
	return c->p0 * exp(-(ev - c->ev0) / c->n->kappa);
}

/* F(p, q, pi) and its derivatives d F / d p, d F / d pi. */
static double yield(const struct nor_sand_parameters *n, double p, double q, double pi, double *Fp, double *Fpi)
{
	double eta, ra;
	if (n->N == 0.0) {
		eta = n->M * (1.0 + log(pi / p));
		ra = 1.0;
	} else {
		double a = n->N / (1.0 - n->N), lr = log(p / pi);
		ra = exp(a * lr);
		/* (M/N)(1 - (1-N) r^a) without cancellation for small N */
		eta = -(n->M / n->N) * expm1(log1p(-n->N) + a * lr);
	}
	if (Fp)
		*Fp = n->M * ra - eta;
	if (Fpi)
		*Fpi = -n->M * ra * p / pi;
	return q - eta * p;
}

/* p / pi at the tip of the yield surface (q = 0). */
static double tip_ratio(const struct nor_sand_parameters *n)
{
	return n->N == 0.0 ? exp(1.0) : exp(-(1.0 - n->N) / n->N * log1p(-n->N));
}

/* psi_i (Eq. 92) at image pressure pi after a multiplier dl, with d psi / d pi and d psi / d dl. */
static double image_state(const struct ns_point *c, double pi, double dl, double *dpi, double *ddl)
{
	const struct nor_sand_parameters *n = c->n;
	double Ed = c->Ed_n + dl;
	*dpi = *ddl = 0.0;
	if (Ed <= n->cutoff_start) {
		*dpi = n->lambda / pi;
		return c->v - n->v_c0 + n->lambda * log(pi / n->p_ref);
	}
	if (Ed >= n->cutoff_end)
		return 0.0;
	double w = n->cutoff_end - n->cutoff_start;
	*ddl = -c->psi_cut / w;
	return (1.0 - (Ed - n->cutoff_start) / w) * c->psi_cut;
}

/* pi* / p = g(psi_i) and g'; -1 when 1 - N D* / M <= 0 (no surface reaches that dilatancy). */
static int limit_ratio(const struct nor_sand_parameters *n, double psi, double *g, double *dg)
{
	double x = n->alpha * psi / n->M;
	if (n->N == 0.0) {
		*g = exp(x);
		*dg = n->alpha / n->M * *g;
		return 0;
	}
	double base = 1.0 - n->N * x;
	if (!(base > 0.0))
		return -1;
	double lb = log(base);
	*g = exp((n->N - 1.0) / n->N * lb);
	*dg = (1.0 - n->N) * n->alpha / n->M * exp(-lb / n->N);
	return 0;
}

/* Residuals R of x = (ln p, es, ln pi), dimensionless: R0 = (ev - ev_tr + dl D) as a strain,
 * R1 = F / p, R2 = (pi - pi_n - h dl (pi* - pi)) / pi_n; *norm = max(|R0| / kappa, |R1| p / (p + |q|),
 * |R2|). The Jacobian A = dR / dx when A, and b = dR / d es_tr at fixed x when b. Returns -1 when
 * x is outside the model's domain. (ln p and ln pi as unknowns make R0 linear in the first and
 * keep both pressures positive.) */
static int residual(const struct ns_point *c, const double x[3], double R[3], double *norm, double A[3][3],
		    double b[3])
{
	const struct nor_sand_parameters *n = c->n;
	double p = exp(x[0]), es = x[1], pi = exp(x[2]), dl = c->es_tr - es, G3 = 3.0 * c->G;
	double ev = c->ev0 - n->kappa * (x[0] - log(c->p0)), q = G3 * es, nb = 1.0 - n->N_bar;
	double D = (q / p - n->M) / nb, Fp, Fpi, psi_pi, psi_dl, g, dg;
	double F = yield(n, p, q, pi, &Fp, &Fpi);
	double psi = image_state(c, pi, dl, &psi_pi, &psi_dl);
	if (!(p > 0.0) || !(pi > 0.0) || !isfinite(p) || !isfinite(pi) || limit_ratio(n, psi, &g, &dg))
		return -1;
	double pistar = p * g, h = n->h, Mra = Fp + (q - F) / p;   /* M (p/pi)^a = F_p + eta */
	R[0] = ev - c->ev_tr + dl * D;
	R[1] = F / p;
	R[2] = (pi - c->pi_n - h * dl * (pistar - pi)) / c->pi_n;
	*norm = fmax(fabs(R[0]) / n->kappa, fmax(fabs(R[1]) * p / (p + fabs(q)), fabs(R[2])));
	double R2_dl = (-h * (pistar - pi) - h * dl * p * dg * psi_dl) / c->pi_n;
	if (A) {
		A[0][0] = -n->kappa - dl * q / (p * nb);
		A[0][1] = -D + dl * G3 / (p * nb);
		A[0][2] = 0.0;
		A[1][0] = -q / p + Mra;
		A[1][1] = G3 / p;
		A[1][2] = -Mra;
		A[2][0] = -h * dl * pistar / c->pi_n;
		A[2][1] = -R2_dl;
		A[2][2] = pi * (1.0 + h * dl - h * dl * p * dg * psi_pi) / c->pi_n;
	}
	if (b) {
		b[0] = D;
		b[1] = 0.0;
		b[2] = R2_dl;
	}
	(void)Fpi;
	return isfinite(*norm) ? 0 : -1;
}

/* Solves A y = r (3x3, partial pivoting) in place of r; -1 when singular. */
static int solve3(double A[3][3], double r[3])
{
	for (int k = 0; k < 3; k++) {
		int piv = k;
		for (int i = k + 1; i < 3; i++)
			if (fabs(A[i][k]) > fabs(A[piv][k]))
				piv = i;
		if (!(fabs(A[piv][k]) > 0.0))
			return -1;
		if (piv != k) {
			for (int j = 0; j < 3; j++) {
				double t = A[k][j]; A[k][j] = A[piv][j]; A[piv][j] = t;
			}
			double t = r[k]; r[k] = r[piv]; r[piv] = t;
		}
		for (int i = k + 1; i < 3; i++) {
			double f = A[i][k] / A[k][k];
			for (int j = k; j < 3; j++)
				A[i][j] -= f * A[k][j];
			r[i] -= f * r[k];
		}
	}
	for (int k = 2; k >= 0; k--) {
		for (int j = k + 1; j < 3; j++)
			r[k] -= A[k][j] * r[j];
		r[k] /= A[k][k];
	}
	return 0;
}

/* The smooth return: Newton with backtracking on the scaled residual. x in: the trial; out: the
 * solution. -1 when it does not converge. */
static int smooth_return(const struct ns_point *c, double x[3], int *iterations)
{
	double R[3], A[3][3], norm;
	if (residual(c, x, R, &norm, A, NULL))
		return -1;
	for (int it = 0; it < NS_ITERATIONS_MAX; it++) {
		*iterations = it;
		if (norm <= NS_TOLERANCE)
			return 0;
		double dx[3] = { -R[0], -R[1], -R[2] };
		if (solve3(A, dx))
			return -1;
		double t = 1.0, xn[3], Rn[3], An[3][3], normn = 0;
		int ok = 0;
		for (int k = 0; k < NS_BACKTRACK_MAX; k++, t *= 0.5) {
			for (int i = 0; i < 3; i++)
				xn[i] = x[i] + t * dx[i];
			if (residual(c, xn, Rn, &normn, An, NULL) == 0 && normn < norm) {
				ok = 1;
				break;
			}
		}
		double size = fabs(dx[0]) + fabs(dx[1]) / (fabs(x[1]) + c->es_tr + 1e-300) + fabs(dx[2]);
		if (!ok)
			return size <= NS_STAGNATION && norm <= 1e3 * NS_TOLERANCE ? 0 : -1;
		memcpy(x, xn, sizeof xn);
		memcpy(R, Rn, sizeof Rn);
		memcpy(A, An, sizeof An);
		norm = normn;
		if (t == 1.0 && size <= NS_STAGNATION && norm <= 1e3 * NS_TOLERANCE)
			return 0;
	}
	return norm <= NS_TOLERANCE ? 0 : -1;
}

/* The stress of the tip return for image pressure pi: the tip, p = c_N pi, while that is at most
 * the trial pressure; above it the trial pressure itself (q = 0 inside the surface). */
static double tip_pressure(const struct ns_point *c, double pi, double p_tr, double *dp_dpi)
{
	double cN = tip_ratio(c->n);
	*dp_dpi = cN * pi <= p_tr ? cN : 0.0;
	return fmin(cN * pi, p_tr);
}

/* The tip return's hardening residual R2 / pi as a function of y = ln pi (dl = es_tr, q = 0, p from
 * tip_pressure):
 *     r(y) = 1 - pi_n / pi - h dl (p g(psi_i) / pi - 1),
 * with dr / dy in *dr. r rises with y: pi_n / pi falls, and p g / pi falls (p grows at most like pi,
 * psi_i rises with pi so g falls, alpha <= 0); r -> 1 + h dl > 0 as pi -> inf, so a root exists.
 * Returns -1 where psi_i is beyond the limit of the dilatancy (g undefined: r = -inf there). */
static int tip_residual(const struct ns_point *c, double y, double p_tr, double *r, double *dr, double *g,
			double *dg, double *psi_dl)
{
	const struct nor_sand_parameters *n = c->n;
	double pi = exp(y), dl = c->es_tr, h = n->h, psi_pi, dp;
	double psi = image_state(c, pi, dl, &psi_pi, psi_dl), p = tip_pressure(c, pi, p_tr, &dp);
	if (limit_ratio(n, psi, g, dg))
		return -1;
	*r = 1.0 - c->pi_n / pi - h * dl * (p * *g / pi - 1.0);
	*dr = c->pi_n / pi - h * dl * (dp * *g + p * *dg * psi_pi - p * *g / pi);
	return 0;
}

/* The return to the tip: q = 0, dl = es_tr, pi from R2 alone, and p = c_N pi, or p = p_tr when the
 * tip of the surface that satisfies R2 lies above the trial pressure. The tip is a corner of the
 * surface; its plastic volume change is what the trial's elastic volume and p leave, and the flow
 * rule there (D = -M / (1 - Nbar) at q = 0) is compaction, so the stress must end at p <= p_tr.
 * When even the fully softened surface of the step has its tip above p_tr (a point pulled apart:
 * a trial p of a few mPa under a shear of 0.8 MPa, image pressure 270 Pa, was met in a landslide),
 * the stress stays at the trial's p with q = 0, inside the surface, and the image pressure
 * softens by R2 with pi* = g p_tr: a tension cut-off, not in 000, written down in docs/numerics.md.
 * Returns TIP_TENSION for that branch, TIP_CORNER for the tip, -1 when no root is found. Fills pi
 * and dpi / d es_tr.
 * The root is bracketed first, stepping down by factors of e from the junction pi = p_tr / c_N
 * (or up from it), then found by Newton steps kept inside the bracket (bisection when a step leaves
 * it). Plain Newton in pi from pi_n failed at a liquefied point (pi_n 0.13 Pa, trial q 0.5 MPa at
 * p 23 Pa): h dl (c_N g - 1) > 1 at pi_n, the root lies six times above pi_n and the iteration ran
 * to pi <= 0. */
static int tip_return(const struct ns_point *c, double p_tr, double *pi_out, double *dpi_des)
{
	const struct nor_sand_parameters *n = c->n;
	double dl = c->es_tr, h = n->h, g, dg, psi_dl, r, dr;
	double mid = log(p_tr / tip_ratio(n)), lo = mid, hi = mid, y;
	/* below: residual undefined (psi_i past the dilatancy limit) counts as r < 0 */
	int below = tip_residual(c, mid, p_tr, &r, &dr, &g, &dg, &psi_dl) || r < 0.0;
	if (below) {
		do
			hi += 1.0;
		while ((below = tip_residual(c, hi, p_tr, &r, &dr, &g, &dg, &psi_dl) || r < 0.0) &&
		       hi < mid + NS_BRACKET_SPAN);
		if (below)
			return -1;
	} else {
		do
			lo -= 1.0;
		while (!(below = tip_residual(c, lo, p_tr, &r, &dr, &g, &dg, &psi_dl) || r < 0.0) &&
		       lo > mid - NS_BRACKET_SPAN);
		if (!below)
			return -1;
	}
	y = 0.5 * (lo + hi);
	for (int it = 0; it < NS_BRACKET_ITERATIONS; it++) {
		if (tip_residual(c, y, p_tr, &r, &dr, &g, &dg, &psi_dl)) {
			lo = y;
			y = 0.5 * (lo + hi);
			continue;
		}
		if (fabs(r) <= NS_TOLERANCE) {
			double pi = exp(y), dp, p = tip_pressure(c, pi, p_tr, &dp);
			*pi_out = pi;
			/* dR2 / dpi = dr / dy at the root, since r = R2 / pi; p_tr does not move with es_tr */
			*dpi_des = (h * (p * g - pi) + h * dl * p * dg * psi_dl) / dr;
			return dp == 0.0 ? TIP_TENSION : TIP_CORNER;
		}
		if (r < 0.0)
			lo = y;
		else
			hi = y;
		double next = dr > 0.0 ? y - r / dr : 0.5 * (lo + hi);
		y = next > lo && next < hi ? next : 0.5 * (lo + hi);
	}
	return -1;
}

/* Reads the point's state and trial into c; dev[3] = deviatoric trial strains. */
static void load_point(const struct material *m, const double *state, const double e[3], double J,
		       struct ns_point *c, double dev[3])
{
	c->n = &m->ns;
	c->G = m->mu;
	c->v = J * state[NOR_SAND_INITIAL_SPECIFIC_VOLUME];
	c->p0 = state[NOR_SAND_REFERENCE_PRESSURE];
	c->ev0 = state[NOR_SAND_REFERENCE_STRAIN];
	c->pi_n = state[NOR_SAND_IMAGE_PRESSURE];
	c->Ed_n = state[NOR_SAND_DEVIATORIC_PLASTIC_STRAIN];
	c->psi_cut = state[NOR_SAND_CUTOFF_STATE];
	c->ev_tr = e[0] + e[1] + e[2];
	double sum = 0;
	for (int a = 0; a < 3; a++) {
		dev[a] = e[a] - c->ev_tr / 3.0;
		sum += dev[a] * dev[a];
	}
	c->es_tr = SQRT_2_3 * sqrt(sum);
}

/* 000 Eqs. 93-94: the gas-like state. */
static void gas_like(struct stress_update *u, double v)
{
	static const double I[4] = { 1, 1, 0, 1 };
	memset(u->stress, 0, 4 * sizeof *u->stress);
	memcpy(u->Be, I, sizeof I);
	if (u->tangent)
		memset(u->tangent, 0, 16 * sizeof *u->tangent);
	u->state[NOR_SAND_SPECIFIC_VOLUME] = v;
}

/* Elastic principal tangent d tau / d e: K 1 (x) 1 + 2 G (I - 1 (x) 1 / 3), K = p / kappa. */
static void elastic_Ds(double K, double G, double Ds[3][3])
{
	for (int a = 0; a < 3; a++)
		for (int b = 0; b < 3; b++)
			Ds[a][b] = K - 2.0 * G / 3.0 + (a == b ? 2.0 * G : 0.0);
}

/* Ds = d tau / d e_tr after a plastic return (slot order), from the linearised system. */
static void plastic_Ds(const struct ns_point *c, const double x[3], const double dev[3], int tip, double dpi_des,
		       double Ds[3][3])
{
	double k = SQRT_2_3, ndev = c->es_tr / k, nv[3];
	for (int a = 0; a < 3; a++)
		nv[a] = ndev > 0.0 ? dev[a] / ndev : 0.0;
	if (tip == TIP_TENSION) {   /* p = p_tr: the elastic bulk response, q = 0 */
		for (int a = 0; a < 3; a++)
			for (int b = 0; b < 3; b++)
				Ds[a][b] = exp(x[0]) / c->n->kappa;
		return;
	}
	if (tip == TIP_CORNER) {
		double dp = tip_ratio(c->n) * dpi_des;
		for (int a = 0; a < 3; a++)
			for (int b = 0; b < 3; b++)
				Ds[a][b] = -dp * k * nv[b];
		return;
	}
	double R[3], A[3][3], B[3][3], bs[3], norm;
	residual(c, x, R, &norm, A, bs);
	memcpy(B, A, sizeof A);
	double yv[3] = { 1.0, 0.0, 0.0 }, ys[3] = { -bs[0], -bs[1], -bs[2] };
	if (solve3(A, yv) || solve3(B, ys)) {
		memset(Ds, 0, 9 * sizeof(double));
		return;
	}
	double G3 = 3.0 * c->G, p = exp(x[0]), q = G3 * x[1];
	double p_v = p * yv[0], p_s = p * ys[0], q_v = G3 * yv[1], q_s = G3 * ys[1];
	for (int a = 0; a < 3; a++)
		for (int b = 0; b < 3; b++)
			Ds[a][b] = -(p_v + p_s * k * nv[b]) + k * nv[a] * (q_v + q_s * k * nv[b]) +
				   k * q * ((a == b) - 1.0 / 3.0 - nv[a] * nv[b]) / ndev;
}

/* State after the step from the solution x = (ln p, es, ln pi). */
static void update_state(const struct ns_point *c, struct stress_update *u, const double x[3], double v)
{
	const struct nor_sand_parameters *n = c->n;
	double Ed = c->Ed_n + (c->es_tr - x[1]), p = exp(x[0]), pi = exp(x[2]);
	u->state[NOR_SAND_DEVIATORIC_PLASTIC_STRAIN] = Ed;
	*u->plastic_strain = Ed;
	u->state[NOR_SAND_IMAGE_PRESSURE] = pi;
	if (Ed <= n->cutoff_start)
		u->state[NOR_SAND_CUTOFF_STATE] = v - n->v_c0 + n->lambda * log(pi / n->p_ref);
	u->state[NOR_SAND_SPECIFIC_VOLUME] = v;
	u->state[NOR_SAND_STATE_PARAMETER] = v - n->v_c0 + n->lambda * log(p / n->p_ref);
}

/* Image pressure of 000 Eq. 113 from the reference pressure p0. */
static double image_from_ocr(const struct nor_sand_parameters *n, double p0)
{
	return n->ocr * p0 / tip_ratio(n);
}

/* The image pressure whose surface passes through (p, q), p > 0, q >= 0: F(p, q, pi) = 0 of
 * yield() solved for pi. With N > 0 no surface reaches a stress ratio of M / N or more; such a
 * stress is taken just below it, and the first plastic step returns the rest. */
static double image_through(const struct nor_sand_parameters *n, double p, double q)
{
	double eta = q / p;
	if (n->N == 0.0)
		return p * exp(eta / n->M - 1.0);
	eta = fmin(eta, (1.0 - 1e-9) * n->M / n->N);
	return p * exp(log((1.0 - n->N) / (1.0 - eta * n->N / n->M)) * (1.0 - n->N) / n->N);
}

/* Sets the reference (p0, eps_v0^e), the image pressure and the derived slots. The image pressure
 * is Eq. 113's; with initial_yield_surface "through_stress" it is at least the one whose surface
 * passes through the point's present shear q (at p0), so the reference state is not outside. */
static void set_reference(const struct material *m, double p0, double q, double ev0, double J, double *state)
{
	const struct nor_sand_parameters *n = &m->ns;
	double v = J * state[NOR_SAND_INITIAL_SPECIFIC_VOLUME], pi = image_from_ocr(n, p0);
	if (n->through_stress)
		pi = fmax(pi, image_through(n, p0, q));
	state[NOR_SAND_DEVIATORIC_PLASTIC_STRAIN] = 0.0;
	state[NOR_SAND_REFERENCE_PRESSURE] = p0;
	state[NOR_SAND_REFERENCE_STRAIN] = ev0;
	state[NOR_SAND_IMAGE_PRESSURE] = pi;
	state[NOR_SAND_CUTOFF_STATE] = v - n->v_c0 + n->lambda * log(pi / n->p_ref);
	state[NOR_SAND_SPECIFIC_VOLUME] = v;
	state[NOR_SAND_STATE_PARAMETER] = v - n->v_c0 + n->lambda * log(p0 / n->p_ref);
}

/* sqrt(3/2) |dev s| of a (xx, yy, xy, zz) stress. */
static double shear_invariant(const double *s)
{
	double m = (s[0] + s[1] + s[3]) / 3.0, a = s[0] - m, b = s[1] - m, c = s[3] - m;
	return sqrt(1.5 * (a * a + b * b + c * c + 2.0 * s[2] * s[2]));
}

/* A point at the effective stress `stress` (tension positive) with eps_v0^e = 0 (000 App. B.3):
 * p0 = -tr(stress) / 3 and eps^e = dev(stress) / (2 G), so Be = exp(2 eps^e) reproduces the stress.
 * A stress-free point (p0 <= 0) takes p0 = initial_reference_pressure and Be = I, the start of
 * 000 App. B.4's elastic gravity loading; its stress becomes p0 at the first update. */
void nor_sand_init_state(const struct material *m, const double *stress, double *Be, double *state)
{
	double p = -(stress[0] + stress[1] + stress[3]) / 3.0, e[4] = { 0, 0, 0, 0 };
	state[NOR_SAND_INITIAL_SPECIFIC_VOLUME] = m->ns.v0;
	if (p > 0.0) {
		for (int k = 0; k < 4; k++)
			e[k] = (stress[k] + (k == 2 ? 0.0 : p)) / (2.0 * m->mu);
	} else {
		p = m->ns.p_start;
	}
	double l[2], th;
	sym2_eigen(e[0], e[1], e[2], l, &th);
	double c = cos(th), s = sin(th), a = exp(2.0 * l[0]), b = exp(2.0 * l[1]);
	Be[0] = c * c * a + s * s * b;
	Be[1] = s * s * a + c * c * b;
	Be[2] = c * s * (a - b);
	Be[3] = exp(2.0 * e[3]);
	set_reference(m, p, shear_invariant(stress), 0.0, 1.0, state);
}

void material_reset_reference(const struct material *m, const double *stress, const double *Be, double J,
			      double *state)
{
	if (m->model != MODEL_NOR_SAND)
		return;
	const double kirchhoff = m->strain == STRAIN_FINITE ? J : 1.0;
	double p = -(stress[0] + stress[1] + stress[3]) / 3.0 * kirchhoff;
	double det = (Be[0] * Be[1] - Be[2] * Be[2]) * Be[3];
	if (!(p > 0.0))   /* the elastic law's p = p0 exp(..) is > 0: a stress set from outside, as when stress-free */
		p = m->ns.p_start;
	set_reference(m, p, shear_invariant(stress) * kirchhoff, 0.5 * log(det), J, state);
}

int nor_sand_state_outputs(const struct material *m, const double *state, const char **names, double *values)
{
	static const char *const out[] = { "deviatoric_plastic_strain", "image_pressure", "specific_volume",
					   "state_parameter" };
	static const int slot[] = { NOR_SAND_DEVIATORIC_PLASTIC_STRAIN, NOR_SAND_IMAGE_PRESSURE,
				    NOR_SAND_SPECIFIC_VOLUME, NOR_SAND_STATE_PARAMETER };
	(void)m;
	for (int k = 0; k < 4; k++) {
		if (names)
			names[k] = out[k];
		values[k] = state[slot[k]];
	}
	return 4;
}

enum poro_status nor_sand_update(const struct material *m, struct stress_update *u, struct poro_error *err)
{
	const struct nor_sand_parameters *n = &m->ns;
	int finite = m->strain == STRAIN_FINITE;
	const double J_v = u->J_v > 0.0 ? u->J_v : u->J;   /* Eq. 96 or Eq. 95 */
	double v = J_v * u->state[NOR_SAND_INITIAL_SPECIFIC_VOLUME];
	if (v > n->gas_ratio * u->state[NOR_SAND_INITIAL_SPECIFIC_VOLUME]) {
		gas_like(u, v);
		return PORO_OK;
	}
	struct spectral_trial t;
	if (spectral_trial(u, finite, &t, "nor-sand", err))
		return PORO_ESOLVER;
	struct ns_point c;
	double dev[3], x[3], e[3], s[3], Ds[3][3], G = m->mu;
	load_point(m, u->state, t.e, J_v, &c, dev);
	double p_tr = pressure(&c, c.ev_tr), q_tr = 3.0 * G * c.es_tr;
	double F_tr = yield(n, p_tr, q_tr, c.pi_n, NULL, NULL);
	if (!isfinite(F_tr))
		return poro_error_set(err, PORO_ESOLVER, "nor-sand: trial state not finite (p %.3g Pa, image "
				      "pressure %.3g Pa)", p_tr, c.pi_n);
	if (u->elastic_only || F_tr <= NS_YIELD_TOLERANCE * (p_tr + q_tr)) {
		for (int a = 0; a < 3; a++)
			s[a] = -p_tr + 2.0 * G * dev[a];
		elastic_Ds(p_tr / n->kappa, G, Ds);
		spectral_finish(u, finite, &t, s, t.e, 1, Ds);
		x[0] = log(p_tr), x[1] = c.es_tr, x[2] = log(c.pi_n);
	} else {
		int iterations = 0, tip = RETURN_SMOOTH;
		/* start from the trial pressure, the old image pressure and the q of the surface there */
		double q0 = q_tr - yield(n, p_tr, q_tr, c.pi_n, NULL, NULL);
		x[0] = log(p_tr), x[1] = fmin(fmax(q0 / (3.0 * G), 0.0), c.es_tr), x[2] = log(c.pi_n);
		if (smooth_return(&c, x, &iterations) || x[1] < 0.0)
			tip = TIP_CORNER;
		double ratio, p, dpi_des = 0;
		if (tip) {
			tip = tip_return(&c, p_tr, &x[2], &dpi_des);
			if (tip < 0)
				return poro_error_set(err, PORO_ESOLVER, "nor-sand: return mapping did not converge "
						      "(trial p %.6g Pa, q %.6g Pa, image pressure %.6g Pa, v %.6g)",
						      p_tr, q_tr, c.pi_n, v);
			double dp_dpi;
			p = tip_pressure(&c, x[2], p_tr, &dp_dpi);
			x[0] = log(p), x[1] = 0.0, x[2] = log(x[2]);
			ratio = 0.0;
		} else {
			p = exp(x[0]);
			ratio = x[1] / c.es_tr;
		}
		double ev = c.ev0 - n->kappa * log(p / c.p0);
		for (int a = 0; a < 3; a++) {
			e[a] = ev / 3.0 + ratio * dev[a];
			s[a] = -p + 2.0 * G * ratio * dev[a];
		}
		if (u->tangent)
			plastic_Ds(&c, x, dev, tip, dpi_des, Ds);
		spectral_finish(u, finite, &t, s, e, 0, Ds);
	}
	update_state(&c, u, x, v);
	return PORO_OK;
}
