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
