/*
 * transfer.c - P2G scatters and G2P gathers over the shape cache (see transfer.h).
 *
 * Gathers are independent per point and run in parallel in index order. Scatters share nodes
 * between neighbouring points: they run in parallel in the block order of point_blocks.h, four
 * colours of blocks one after another, so that no two threads add into one node and every node's
 * sum is formed in an order the thread count does not change (the file comment there says why
 * this design and what it costs; docs/performance.md, "Parallel scatters", the figures). The
 * loops' bodies are those of the serial kernels: only the order of the points changed.
 */
#include "transfer.h"

void p2g_scalar(const struct grid *g, const struct particles *p, const double *weight,
		const double *value, double *out)
{
	FOR_POINTS_BY_BLOCK(p, q, {
		double s = (weight ? weight[q] : 1.0) * (value ? value[q] : 1.0);
		FOR_SUPPORT(g, p, q, { out[I] += wk * s; });
	});
}

void p2g_vector(const struct grid *g, const struct particles *p, const double *weight,
		const double *value, double *out)
{
	FOR_POINTS_BY_BLOCK(p, q, {
		double s = weight ? weight[q] : 1.0;
		double vx = s * value[2 * q], vy = s * value[2 * q + 1];
		FOR_SUPPORT(g, p, q, {
			out[2 * I] += wk * vx;
			out[2 * I + 1] += wk * vy;
		});
	});
}

void p2g_internal_force(const struct grid *g, const struct particles *p, const double *weight,
			const double *stress, const double *iso, double *out)
{
	FOR_POINTS_BY_BLOCK(p, q, {
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
	});
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

void p2g_batch(const struct grid *g, const struct particles *p, const struct p2g_batch *b)
{
	FOR_POINTS_BY_BLOCK(p, q, { p2g_batch_point(g, p, q, b); });
}

void p2g_point_gradient(const struct grid *g, const struct particles *p, const double *weight, const double *node,
			double *out)
{
	FOR_POINTS_BY_BLOCK(p, q, {
		double sx = 0.0, sy = 0.0;
		FOR_SUPPORT(g, p, q, {
			sx += gx * node[I];
			sy += gy * node[I];
		});
		const double V = weight ? weight[q] : 1.0, fx = V * sx, fy = V * sy;
		FOR_SUPPORT(g, p, q, {
			out[2 * I] += wk * fx;
			out[2 * I + 1] += wk * fy;
		});
	});
}

void p2g_point_divergence(const struct grid *g, const struct particles *p, const double *weight,
			  const double *node, double *out)
{
	FOR_POINTS_BY_BLOCK(p, q, {
		double div = 0.0;
		FOR_SUPPORT(g, p, q, { div += node[2 * I] * gx + node[2 * I + 1] * gy; });
		const double s = (weight ? weight[q] : 1.0) * div;
		FOR_SUPPORT(g, p, q, { out[I] += wk * s; });
	});
}

idx_t g2p_flip_update(const struct grid *g, struct particles *p, const double *v_new, const double *dv, double alpha,
		     double dt, int move)
{
	idx_t beyond = 0;
#pragma omp parallel for schedule(static) reduction(+ : beyond)
	for (idx_t q = 0; q < p->n; q++) {
		double px = 0.0, py = 0.0, dx = 0.0, dy = 0.0;
		FOR_SUPPORT(g, p, q, {
			px += wk * v_new[2 * I];
			py += wk * v_new[2 * I + 1];
			dx += wk * dv[2 * I];
			dy += wk * dv[2 * I + 1];
		});
		double *v = p->v + 2 * q;
		v[0] = alpha * (v[0] + dx) + (1.0 - alpha) * px;
		v[1] = alpha * (v[1] + dy) + (1.0 - alpha) * py;
		if (move) {
			p->x[2 * q] += dt * px;
			p->x[2 * q + 1] += dt * py;
			beyond += grid_beyond_face(g, p->x + 2 * q);
		}
	}
	return beyond;
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

void p2g_scalar_linear_fit(const struct grid *g, const struct particles *p, const double *weight,
			   const double *value, double *moments, double *out)
{
	const int S = p->support;
	const idx_t nx = g->nodes[0];
	enum { W, WX, WY, WXX, WXY, WYY, WV, WVX, WVY, MOMENTS };   /* sums of w, w dx, ..., w v dy */
	double *m = moments;
	grid_zero(m, MOMENTS * (size_t)g->node_count);
	FOR_POINTS_BY_BLOCK(p, q, {
		const struct shape_factors f = particle_shape(p, q);
		double dX[SHAPE_SUPPORT_MAX], dY[SHAPE_SUPPORT_MAX];   /* X_a - x_p: minus x_p - x_I */
		support_offsets(f.wx, S, g->h, dX);
		support_offsets(f.wy, S, g->h, dY);
		const double wq = weight ? weight[q] : 1.0, v = value[q];
		for (int b = 0; b < S; b++)
			for (int a = 0; a < S; a++) {
				double *M = m + MOMENTS * (size_t)(p->node0[q] + a + b * nx);
				const double c = wq * (f.wx[a] * f.wy[b]), dx = -dX[a], dy = -dY[b];
				M[W] += c, M[WX] += c * dx, M[WY] += c * dy;
				M[WXX] += c * dx * dx, M[WXY] += c * dx * dy, M[WYY] += c * dy * dy;
				M[WV] += c * v, M[WVX] += c * v * dx, M[WVY] += c * v * dy;
			}
	});
	const double spread_min = LINEAR_FIT_SPREAD_MIN * g->h * g->h;
	#pragma omp parallel for schedule(static)
	for (idx_t I = 0; I < g->node_count; I++) {
		const double *M = m + MOMENTS * (size_t)I;
		if (!(M[W] > 0.0))
			continue;
		/* centred moments: the fit's slope solves C b = c_v, and a = mean - b . centroid */
		const double mx = M[WX] / M[W], my = M[WY] / M[W], mean = M[WV] / M[W];
		const double cxx = M[WXX] / M[W] - mx * mx, cxy = M[WXY] / M[W] - mx * my, cyy = M[WYY] / M[W] - my * my;
		const double cvx = M[WVX] / M[W] - mean * mx, cvy = M[WVY] / M[W] - mean * my;
		const int fit_x = cxx > spread_min, fit_y = cyy > spread_min;
		const double det = cxx * cyy - cxy * cxy;
		double bx = 0.0, by = 0.0;
		if (fit_x && fit_y && det > spread_min * spread_min)
			bx = (cyy * cvx - cxy * cvy) / det, by = (cxx * cvy - cxy * cvx) / det;
		else if (fit_y && !fit_x)
			by = cvy / cyy;
		else if (fit_x && !fit_y)
			bx = cvx / cxx;
		out[I] = mean - bx * mx - by * my;
	}
}

void p2g_affine_momentum(const struct grid *g, const struct particles *p, const double *mass, const double *v,
			 const double *C, double *out)
{
	const int S = p->support;
	const idx_t nx = g->nodes[0];
	FOR_POINTS_BY_BLOCK(p, q, {
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
	});
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
		if (v)
			v[2 * q] = vx, v[2 * q + 1] = vy;
		double *Cq = C + 4 * q;
		Cq[0] = Dxx > floor ? Bxx / Dxx : 0.0;
		Cq[1] = Dyy > floor ? Bxy / Dyy : 0.0;
		Cq[2] = Dxx > floor ? Byx / Dxx : 0.0;
		Cq[3] = Dyy > floor ? Byy / Dyy : 0.0;
	}
}
