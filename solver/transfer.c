/*
 * transfer.c - P2G scatters and G2P gathers over the shape cache (see transfer.h).
 *
 * Scatters are serial: several points share nodes, and a race-free parallel scatter (colouring or
 * per-thread grids) is a performance change that must keep these results bit-for-bit, so it lives
 * behind this same interface when it comes. Gathers are independent per point and run in parallel.
 */
#include "transfer.h"

/* Iterates the support nodes of point q: node index `I`, shape weight `wk`, gradient `gx`, `gy`.
 * The quadratic B-spline's 3x3 support (the default shape) gets its own copy of the body with
 * the support a constant, so the compiler unrolls it; the order of the sums is the same. */
#define FOR_SUPPORT(g, p, q, ...)                                                    \
	do {                                                                         \
		if ((p)->support == 3)                                               \
			FOR_SUPPORT_OF(3, g, p, q, __VA_ARGS__);                     \
		else                                                                 \
			FOR_SUPPORT_OF((p)->support, g, p, q, __VA_ARGS__);          \
	} while (0)

/* FOR_SUPPORT on a support of S nodes per direction: the weight and gradient are formed from the
 * 1-D factors (particles.h), the same products the shape functions define. */
#define FOR_SUPPORT_OF(S, g, p, q, ...)                                              \
	do {                                                                         \
		const int S_ = (S);                                                  \
		const double *wx_ = (p)->shape + (size_t)(q) * 4 * S_;               \
		const double *wy_ = wx_ + S_, *dx_ = wx_ + 2 * S_, *dy_ = wx_ + 3 * S_; \
		const idx_t base_ = (p)->node0[q];                                   \
		_Pragma("GCC unroll 4") for (int b_ = 0; b_ < S_; b_++)              \
			_Pragma("GCC unroll 4") for (int a_ = 0; a_ < S_; a_++) {    \
				const idx_t I = base_ + a_ + b_ * (g)->nodes[0];     \
				const double wk = wx_[a_] * wy_[b_];                 \
				const double gx = dx_[a_] * wy_[b_];                 \
				const double gy = wx_[a_] * dy_[b_];                 \
				(void)wk, (void)gx, (void)gy;                        \
				__VA_ARGS__                                          \
			}                                                            \
	} while (0)

void p2g_scalar(const struct grid *g, const struct particles *p, const double *weight,
		const double *value, double *out)
{
	for (idx_t q = 0; q < p->n; q++) {
		double s = (weight ? weight[q] : 1.0) * (value ? value[q] : 1.0);
		FOR_SUPPORT(g, p, q, { out[I] += wk * s; });
	}
}

void p2g_vector(const struct grid *g, const struct particles *p, const double *weight,
		const double *value, double *out)
{
	for (idx_t q = 0; q < p->n; q++) {
		double s = weight ? weight[q] : 1.0;
		double vx = s * value[2 * q], vy = s * value[2 * q + 1];
		FOR_SUPPORT(g, p, q, {
			out[2 * I] += wk * vx;
			out[2 * I + 1] += wk * vy;
		});
	}
}

void p2g_internal_force(const struct grid *g, const struct particles *p, const double *weight,
			const double *stress, const double *iso, double *out)
{
	for (idx_t q = 0; q < p->n; q++) {
		double V = weight ? weight[q] : 1.0;
		double sp = iso ? iso[q] : 0.0;
		double sxx = sp, syy = sp, sxy = 0.0;
		if (stress) {
			sxx += stress[4 * q];
			syy += stress[4 * q + 1];
			sxy = stress[4 * q + 2];
		}
		sxx *= V, syy *= V, sxy *= V;
		FOR_SUPPORT(g, p, q, {
			out[2 * I] -= sxx * gx + sxy * gy;
			out[2 * I + 1] -= sxy * gx + syy * gy;
		});
	}
}

void g2p_scalar(const struct grid *g, const struct particles *p, const double *node, double *out)
{
#pragma omp parallel for schedule(static)
	for (idx_t q = 0; q < p->n; q++) {
		double s = 0.0;
		FOR_SUPPORT(g, p, q, { s += wk * node[I]; });
		out[q] = s;
	}
}

void g2p_vector(const struct grid *g, const struct particles *p, const double *node, double *out)
{
#pragma omp parallel for schedule(static)
	for (idx_t q = 0; q < p->n; q++) {
		double sx = 0.0, sy = 0.0;
		FOR_SUPPORT(g, p, q, {
			sx += wk * node[2 * I];
			sy += wk * node[2 * I + 1];
		});
		out[2 * q] = sx;
		out[2 * q + 1] = sy;
	}
}

void g2p_scalar_gradient(const struct grid *g, const struct particles *p, const double *node, double *out)
{
#pragma omp parallel for schedule(static)
	for (idx_t q = 0; q < p->n; q++) {
		double sx = 0.0, sy = 0.0;
		FOR_SUPPORT(g, p, q, {
			sx += gx * node[I];
			sy += gy * node[I];
		});
		out[2 * q] = sx;
		out[2 * q + 1] = sy;
	}
}

void g2p_vector_gradient(const struct grid *g, const struct particles *p, const double *node, double *out)
{
#pragma omp parallel for schedule(static)
	for (idx_t q = 0; q < p->n; q++) {
		double l[4] = {0, 0, 0, 0};
		FOR_SUPPORT(g, p, q, {
			double ux = node[2 * I], uy = node[2 * I + 1];
			l[0] += ux * gx, l[1] += ux * gy;
			l[2] += uy * gx, l[3] += uy * gy;
		});
		for (int c = 0; c < 4; c++)
			out[4 * q + c] = l[c];
	}
}

void g2p_divergence(const struct grid *g, const struct particles *p, const double *node, double *out)
{
#pragma omp parallel for schedule(static)
	for (idx_t q = 0; q < p->n; q++) {
		double s = 0.0;
		FOR_SUPPORT(g, p, q, { s += node[2 * I] * gx + node[2 * I + 1] * gy; });
		out[q] = s;
	}
}

/* The offsets X_a - x_p (in metres) of a point's support nodes along one direction, x_p being
 * sum_a w_a X_a: the first moment of the 1-D weights (transfer.h, APIC), and D = sum_a w_a d_a^2.
 * Relative to the first support node, so no large coordinates cancel. */
static inline double support_offsets(const double *w, int S, double h, double *d)
{
	double first_moment = 0.0;
	for (int a = 0; a < S; a++)
		first_moment += w[a] * a;
	double D = 0.0;
	for (int a = 0; a < S; a++) {
		d[a] = (a - first_moment) * h;
		D += w[a] * d[a] * d[a];
	}
	return D;
}

#define AFFINE_D_FLOOR 1e-12   /* of h^2: below it a direction has no affine part (transfer.h) */

void p2g_affine_momentum(const struct grid *g, const struct particles *p, const double *mass, const double *v,
			 const double *C, double *out)
{
	const int S = p->support;
	const idx_t nx = g->nodes[0];
	for (idx_t q = 0; q < p->n; q++) {
		const struct shape_factors f = particle_shape(p, q);
		double dX[SHAPE_SUPPORT_MAX], dY[SHAPE_SUPPORT_MAX];
		support_offsets(f.wx, S, g->h, dX);
		support_offsets(f.wy, S, g->h, dY);
		const double m = mass[q], *Cq = C + 4 * q;
		for (int b = 0; b < S; b++)
			for (int a = 0; a < S; a++) {
				const idx_t I = p->node0[q] + a + b * nx;
				const double mS = m * (f.wx[a] * f.wy[b]);
				out[2 * I] += mS * (v[2 * q] + Cq[0] * dX[a] + Cq[1] * dY[b]);
				out[2 * I + 1] += mS * (v[2 * q + 1] + Cq[2] * dX[a] + Cq[3] * dY[b]);
			}
	}
}

void g2p_affine_velocity(const struct grid *g, const struct particles *p, const double *node, double *v,
			 double *C)
{
	const int S = p->support;
	const idx_t nx = g->nodes[0];
	const double floor = AFFINE_D_FLOOR * g->h * g->h;
#pragma omp parallel for schedule(static)
	for (idx_t q = 0; q < p->n; q++) {
		const struct shape_factors f = particle_shape(p, q);
		double dX[SHAPE_SUPPORT_MAX], dY[SHAPE_SUPPORT_MAX];
		const double Dxx = support_offsets(f.wx, S, g->h, dX), Dyy = support_offsets(f.wy, S, g->h, dY);
		double vx = 0, vy = 0, Bxx = 0, Bxy = 0, Byx = 0, Byy = 0;   /* B = sum S v (x_I - x_p)^T */
		for (int b = 0; b < S; b++)
			for (int a = 0; a < S; a++) {
				const idx_t I = p->node0[q] + a + b * nx;
				const double wk = f.wx[a] * f.wy[b], ux = wk * node[2 * I], uy = wk * node[2 * I + 1];
				vx += ux, vy += uy;
				Bxx += ux * dX[a], Bxy += ux * dY[b];
				Byx += uy * dX[a], Byy += uy * dY[b];
			}
		v[2 * q] = vx, v[2 * q + 1] = vy;
		double *Cq = C + 4 * q;
		Cq[0] = Dxx > floor ? Bxx / Dxx : 0.0;
		Cq[1] = Dyy > floor ? Bxy / Dyy : 0.0;
		Cq[2] = Dxx > floor ? Byx / Dxx : 0.0;
		Cq[3] = Dyy > floor ? Byy / Dyy : 0.0;
	}
}
