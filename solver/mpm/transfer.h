/*
 * transfer.h - particle-to-grid (P2G) and grid-to-particle (G2P) kernels shared by every scheme.
 *
 * Each kernel is one loop over the points of a set, using the shape cache filled by
 * shape_evaluate() (node0 and the 1-D factors, particles.h). Scatters ADD into their nodal
 * output (the caller zeroes it); gathers OVERWRITE their per-point output. A NULL per-point
 * weight or value array means 1.
 *
 * Every kernel runs on the calling OpenMP team's threads. Gathers take the points in any order.
 * Scatters take them in the block order of point_blocks.h (FOR_POINTS_BY_BLOCK), so that each
 * node's sum is formed in the same order, and is the same bit for bit, at any thread count; a
 * phase that scatters in a loop of its own (p2g_batch_point below) runs that loop the same way.
 *
 * Nodal vectors and per-point vectors are interleaved (x, y). Per-point 2x2 tensors are row-major
 * (xx, xy, yx, yy). Stresses are (xx, yy, xy, zz).
 */
#ifndef PORO_TRANSFER_H
#define PORO_TRANSFER_H

#include "grid.h"
#include "point_blocks.h"

/* out_I += sum_p S_Ip weight_p value_p  (mass, Eq. 44; porosity numerator, Eq. 46; ...). */
void p2g_scalar(const struct grid *g, const struct particles *p, const double *weight,
		const double *value, double *out);

/* out_I += sum_p S_Ip weight_p value_p for a 2-vector value (momentum, Eq. 45; ...). */
void p2g_vector(const struct grid *g, const struct particles *p, const double *weight,
		const double *value, double *out);

/* out_I -= sum_p weight_p (stress_p + iso_p I) . grad S_Ip: the internal force of Eqs. 55 and 57.
 * stress (4 per point) or iso (1 per point) may be NULL. */
void p2g_internal_force(const struct grid *g, const struct particles *p, const double *weight,
			const double *stress, const double *iso, double *out);

/* The nodal value of a point scalar as a local linear fit: at each node I, the a_I of
 *     min over (a_I, b_I) of sum_p S_Ip weight_p (value_p - a_I - b_I . (x_p - x_I))^2,
 * the weighted mean sum S w v / sum S w corrected by the slope times the offset of the points'
 * weighted centroid from the node. Where the points' centroid in a node's support is the node
 * itself (the interior of a regular lattice) that is the mean; at walls, the free surface and
 * where the points have moved apart the mean is the field's value at the centroid, not at the
 * node, and only the fit passes a linear field (the hydrostatic pressure) through unchanged
 * (docs/numerics.md, "Water at rest under gravity"). A direction in which the points of a
 * support spread less than LINEAR_FIT_SPREAD_MIN h^2 (in variance; e.g. a node reached by one
 * row of points) gets no slope. moments: scratch, 9 node_count doubles; out is overwritten at
 * every node the points reach and left alone elsewhere. */
#define LINEAR_FIT_SPREAD_MIN 1e-3
void p2g_scalar_linear_fit(const struct grid *g, const struct particles *p, const double *weight,
			   const double *value, double *moments, double *out);

/* out_p = sum_I S_Ip node_I (Eqs. 38-40, 48). */
void g2p_scalar(const struct grid *g, const struct particles *p, const double *node, double *out);

/* out_p = sum_I S_Ip node_I for a nodal 2-vector. */
void g2p_vector(const struct grid *g, const struct particles *p, const double *node, double *out);

/* out_p = sum_I node_I (x) grad S_Ip: gradient of a nodal 2-vector, 4 per point, row-major
 * (d u_x/dx, d u_x/dy, d u_y/dx, d u_y/dy); step 8b uses it for the deformation gradient. */
void g2p_vector_gradient(const struct grid *g, const struct particles *p, const double *node, double *out);

/* APIC, the affine particle-in-cell transfer (Jiang, Schroeder, Selle, Teran and Stomakhin 2015):
 * each point carries a velocity v_p and an affine velocity C_p (4 per point, row-major), and
 *     P2G  out_I += sum_p S_Ip m_p (v_p + C_p (x_I - x_p))
 *     G2P  v_p = sum_I S_Ip v_I,   C_p = sum_I S_Ip v_I (x_I - x_p)^T D_p^-1,
 *          D_p = sum_I S_Ip (x_I - x_p)(x_I - x_p)^T.
 * A nodal field that is affine near the point comes back exactly, and linear and angular
 * momentum survive the round trip, while the velocity the grid cannot represent is dropped, as
 * in PIC (FLIP keeps it; docs/numerics.md, "Point velocities"). x_p is the position the shape
 * cache was evaluated at, sum_I S_Ip x_I (the shapes reproduce linear fields), so the pair is
 * consistent with the cache however far the points have moved since. For the tensor-product
 * shapes D_p is diagonal: D_xx = sum_a wx_a (X_a - x_p)^2. A direction in which D_p vanishes (a
 * point on an edge node, where the edge-modified basis has one node) gives no affine part.
 * AFLIP (Fei, Guo, Wu, Huang and Gao 2021) keeps the points' FLIP velocities and gathers only
 * C_p: g2p_affine_velocity then takes v = NULL. */
void p2g_affine_momentum(const struct grid *g, const struct particles *p, const double *mass, const double *v,
			 const double *C, double *out);
void g2p_affine_velocity(const struct grid *g, const struct particles *p, const double *node, double *v,
			 double *C);

/* Per-point kernels, for a phase that is one loop over the points (STYLE 1) and needs several
 * transfers of the same point: each point's shape factors are then read once instead of once a
 * transfer. Run in a FOR_POINTS_BY_BLOCK loop, every output gets the same sums in the same order
 * as the whole-set kernels above, so a fused loop's results are bit for bit those of the
 * separate calls. */

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

/* One scatter channel: out_I += S_Ip weight_p value_p (NULL weight or value: 1). */
struct p2g_channel {
	const double *weight, *value;
	double *out;
};

#define P2G_SCALARS_MAX 4

/* Several quantities of one set scattered together: up to P2G_SCALARS_MAX scalar channels and,
 * when vector.out is set, one 2-vector channel (value 2 per point). Outputs must be distinct. */
struct p2g_batch {
	int scalars;
	struct p2g_channel scalar[P2G_SCALARS_MAX];
	struct p2g_channel vector;
};

/* The batch's scatters for point q alone, in a FOR_POINTS_BY_BLOCK loop (point_blocks.h). */
static inline void p2g_batch_point(const struct grid *g, const struct particles *p, idx_t q,
				   const struct p2g_batch *b)
{
	double s[P2G_SCALARS_MAX];
	const int K = b->scalars;
	for (int k = 0; k < K; k++) {
		const struct p2g_channel *c = &b->scalar[k];
		s[k] = (c->weight ? c->weight[q] : 1.0) * (c->value ? c->value[q] : 1.0);
	}
	if (b->vector.out) {
		const struct p2g_channel *c = &b->vector;
		double m = c->weight ? c->weight[q] : 1.0, vx = m * c->value[2 * q], vy = m * c->value[2 * q + 1];
		double *out = c->out;
		FOR_SUPPORT(g, p, q, {
			for (int k = 0; k < K; k++)
				b->scalar[k].out[I] += wk * s[k];
			out[2 * I] += wk * vx;
			out[2 * I + 1] += wk * vy;
		});
	} else {
		FOR_SUPPORT(g, p, q, {
			for (int k = 0; k < K; k++)
				b->scalar[k].out[I] += wk * s[k];
		});
	}
}

/* The batch over every point of the set. */
void p2g_batch(const struct grid *g, const struct particles *p, const struct p2g_batch *b);

/* sum_I S_Ip node_I at point q (g2p_scalar for one point). */
static inline double g2p_scalar_point(const struct grid *g, const struct particles *p, idx_t q, const double *node)
{
	double s = 0.0;
	FOR_SUPPORT(g, p, q, { s += wk * node[I]; });
	return s;
}

/* out_I += sum_p S_Ip weight_p (sum_J node_J grad S_Jp): a nodal scalar's gradient taken at the
 * points and scattered back (the correction's G dp, Eqs. 67-68), each point's gradient gathered
 * and scattered in one visit. */
void p2g_point_gradient(const struct grid *g, const struct particles *p, const double *weight, const double *node,
			double *out);

/* out_I += sum_p S_Ip weight_p (div of a nodal 2-vector at p): the divergence of Eqs. 62-63
 * taken at the points and scattered back, likewise. */
void p2g_point_divergence(const struct grid *g, const struct particles *p, const double *weight,
			  const double *node, double *out);

/* The FLIP/PIC blend of step 7a-b in one pass (000 §4.5): v_pic = sum_I S_Ip v_new_I, then
 * v_p = alpha (v_p + sum_I S_Ip dv_I) + (1 - alpha) v_pic and, if move, x_p += dt v_pic.
 * Returns how many moved points now lie beyond a grid face (grid_beyond_face), 0 without move. */
idx_t g2p_flip_update(const struct grid *g, struct particles *p, const double *v_new, const double *dv, double alpha,
		     double dt, int move);

#endif
