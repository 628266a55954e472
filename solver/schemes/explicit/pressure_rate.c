/*
 * pressure_rate.c - step 7 of paper 002's explicit scheme for the pore pressure: the compressible
 * fluid's pressure rate (Eq. 9) and its node-based multi-field projection (Eqs. 28-34, after Chen
 * et al. 2018 and the node-based integration of Mast et al. 2012).
 *
 * Each point's rate from the step's volumetric strain rates (the cell averages of Eq. 26, or the
 * point's own without smoothing), with Eq. 30's second div v_s read as div v_f (spec-002 §12 E5):
 *     pdot*_p = -(K_f / n_p) ((1 - n_p) rate_s,p + n_p rate_f,p)                   (Eqs. 9, 30)
 * The multi-field principle approximates the rate by pdot(x) = Q(x)^T a and makes the residual of
 * Eq. 30 orthogonal to Q; integrated node by node (Eq. 33) it is a local least-squares fit at each
 * node I over the points of its support, weighted by S_Ip V_p:
 *     H_I a_I = sum_p S_Ip V_p Q_p pdot*_p,   H_I = sum_p S_Ip V_p Q_p Q_p^T          (Eq. 33)
 * and each point takes pdot_p = sum_I S_Ip Q_p^T a_I (Eq. 34). The paper does not say which basis
 * it used (E6):
 *  - constant, Q = [1] (the default): a_I is the volume-weighted nodal mean of pdot*, Eq. 34
 *    interpolates it back;
 *  - linear, Q = [1, (x - x_I) / h, (y - y_I) / h] in the node's own coordinates (the global
 *    [1, x, y] is ill-conditioned): the fit passes a linear rate field through exactly; a node
 *    whose points do not span a plane (H_I's smallest pivot below LINEAR_BASIS_PIVOT_MIN of its
 *    largest, a node reached by one row of points) falls back to the constant basis.
 * Then p_f += dt pdot_p at every point, and with the cell average of the strain rates every point
 * of a cell takes the cell's pressure (strain_rate.c, explicit_cell_pressure). A drained face needs
 * nothing here: it drains through the fluid's velocity (explicit.c).
 */
#include <math.h>
#include <string.h>

#include "explicit.h"
#include "transfer.h"

#define LINEAR_BASIS_PIVOT_MIN 1e-8

/* Eqs. 9 and 30 at every point, physical sign (compression positive). */
static void point_rates(struct sim *s)
{
	struct explicit_state *e = explicit_of(s);
	const struct particles *p = &s->soil;
	const double K_f = s->spec->fluid.bulk_modulus;
#pragma omp parallel for schedule(static)
	for (idx_t q = 0; q < p->n; q++) {
		const double n = p->porosity[q];
		e->pressure_rate[q] = -K_f / n * ((1.0 - n) * e->rate_s[q] + n * e->rate_f[q]);
	}
}

/* The offsets (X_a - x_p) / h of a point's support nodes along one direction, x_p = sum_a w_a X_a
 * (the shapes reproduce linear fields; the position the shapes were evaluated at, the step's
 * start, however far the point has moved since). */
static inline void offsets(const double *w, int S, double *d)
{
	double first_moment = 0.0;
	for (int a = 0; a < S; a++)
		first_moment += w[a] * a;
	for (int a = 0; a < S; a++)
		d[a] = a - first_moment;
}

/* Constant basis: a_I = sum S V pdot* / sum S V (moments 2 per node), pdot_p = sum S a_I. */
static void project_constant(struct sim *s)
{
	struct explicit_state *e = explicit_of(s);
	const struct grid *g = &s->grid;
	const struct particles *p = &s->soil;
	double *m = e->rate_moments, *a = e->rate_nodal;
	memset(m, 0, 2 * sizeof(double) * (size_t)g->node_count);
	FOR_POINTS_BY_BLOCK(p, q, {   /* a scatter: in parallel (point_blocks.h) */
		const double V = p->volume[q], Vr = V * e->pressure_rate[q];
		FOR_SUPPORT(g, p, q, {
			m[2 * I] += wk * Vr;
			m[2 * I + 1] += wk * V;
		});
	});
#pragma omp parallel for schedule(static)
	for (idx_t I = 0; I < g->node_count; I++)
		a[I] = m[2 * I + 1] > 0.0 ? m[2 * I] / m[2 * I + 1] : 0.0;
	g2p_scalar(g, p, a, e->pressure_rate);
}

/* Solves the 3x3 symmetric system H a = r by Gaussian elimination with partial pivoting; 0 when a
 * pivot falls below LINEAR_BASIS_PIVOT_MIN of the largest diagonal entry. */
static int solve3(double H[3][3], double r[3], double a[3])
{
	const double scale = fmax(H[0][0], fmax(H[1][1], H[2][2]));
	for (int k = 0; k < 3; k++) {
		int pivot = k;
		for (int i = k + 1; i < 3; i++)
			if (fabs(H[i][k]) > fabs(H[pivot][k]))
				pivot = i;
		if (!(fabs(H[pivot][k]) > LINEAR_BASIS_PIVOT_MIN * scale))
			return 0;
		for (int j = 0; j < 3; j++) {
			const double t = H[k][j];
			H[k][j] = H[pivot][j], H[pivot][j] = t;
		}
		const double t = r[k];
		r[k] = r[pivot], r[pivot] = t;
		for (int i = k + 1; i < 3; i++) {
			const double f = H[i][k] / H[k][k];
			for (int j = k; j < 3; j++)
				H[i][j] -= f * H[k][j];
			r[i] -= f * r[k];
		}
	}
	for (int k = 2; k >= 0; k--) {
		double x = r[k];
		for (int j = k + 1; j < 3; j++)
			x -= H[k][j] * a[j];
		a[k] = x / H[k][k];
	}
	return 1;
}

/* Linear basis in the node's coordinates, Q = [1, dx, dy] with d = (x_p - x_I) / h. */
static void project_linear(struct sim *s)
{
	struct explicit_state *e = explicit_of(s);
	const struct grid *g = &s->grid;
	const struct particles *p = &s->soil;
	const int S = p->support;
	const idx_t nx = g->nodes[0];
	enum { W, WX, WY, WXX, WXY, WYY, WR, WRX, WRY, MOMENTS };
	double *m = e->rate_moments, *a = e->rate_nodal;
	memset(m, 0, MOMENTS * sizeof(double) * (size_t)g->node_count);
	FOR_POINTS_BY_BLOCK(p, q, {   /* a scatter into q's support: in parallel (point_blocks.h) */
		const struct shape_factors f = particle_shape(p, q);
		double dX[SHAPE_SUPPORT_MAX], dY[SHAPE_SUPPORT_MAX];   /* (X_a - x_p) / h: minus Q's dx */
		offsets(f.wx, S, dX);
		offsets(f.wy, S, dY);
		const double V = p->volume[q], r = e->pressure_rate[q];
		for (int b = 0; b < S; b++)
			for (int c = 0; c < S; c++) {
				double *M = m + MOMENTS * (size_t)(p->node0[q] + c + b * nx);
				const double w = V * f.wx[c] * f.wy[b], dx = -dX[c], dy = -dY[b];
				M[W] += w, M[WX] += w * dx, M[WY] += w * dy;
				M[WXX] += w * dx * dx, M[WXY] += w * dx * dy, M[WYY] += w * dy * dy;
				M[WR] += w * r, M[WRX] += w * r * dx, M[WRY] += w * r * dy;
			}
	});
#pragma omp parallel for schedule(static)
	for (idx_t I = 0; I < g->node_count; I++) {
		const double *M = m + MOMENTS * (size_t)I;
		double *aI = a + 3 * (size_t)I;
		aI[0] = aI[1] = aI[2] = 0.0;
		if (!(M[W] > 0.0))
			continue;
		double H[3][3] = {{M[W], M[WX], M[WY]}, {M[WX], M[WXX], M[WXY]}, {M[WY], M[WXY], M[WYY]}};
		double rhs[3] = {M[WR], M[WRX], M[WRY]};
		if (!solve3(H, rhs, aI))
			aI[0] = M[WR] / M[W], aI[1] = aI[2] = 0.0;   /* the constant basis */
	}
#pragma omp parallel for schedule(static)
	for (idx_t q = 0; q < p->n; q++) {
		const struct shape_factors f = particle_shape(p, q);
		double dX[SHAPE_SUPPORT_MAX], dY[SHAPE_SUPPORT_MAX];
		offsets(f.wx, S, dX);
		offsets(f.wy, S, dY);
		double rate = 0.0;
		for (int b = 0; b < S; b++)
			for (int c = 0; c < S; c++) {
				const double *aI = a + 3 * (size_t)(p->node0[q] + c + b * nx);
				rate += f.wx[c] * f.wy[b] * (aI[0] - aI[1] * dX[c] - aI[2] * dY[b]);
			}
		e->pressure_rate[q] = rate;
	}
}

void explicit_pressure_rate(struct sim *s)
{
	struct explicit_state *e = explicit_of(s);
	struct particles *w = &s->water;
	const struct case_formulation *form = &s->spec->formulation;
	point_rates(s);
	if (form->pressure_rate_projection == PRESSURE_RATE_MULTI_FIELD) {
		if (form->pressure_rate_basis == PRESSURE_RATE_BASIS_LINEAR)
			project_linear(s);
		else
			project_constant(s);
	}
	const double dt = s->dt;
#pragma omp parallel for schedule(static)
	for (idx_t q = 0; q < w->n; q++)
		w->pressure[q] -= dt * e->pressure_rate[q];   /* tension positive inside the solver */
	if (form->strain_rate_smoothing == STRAIN_RATE_SMOOTHING_CELL_AVERAGE)
		explicit_cell_pressure(s);
}
