/*
 * transfer.h - particle-to-grid (P2G) and grid-to-particle (G2P) kernels shared by every scheme.
 *
 * Each kernel is one loop over the points of a set, using the shape cache filled by
 * shape_evaluate() (node0 and the 1-D factors, particles.h). Scatters ADD into their nodal
 * output (the caller zeroes it); gathers OVERWRITE their per-point output. A NULL per-point
 * weight or value array means 1.
 *
 * Nodal vectors and per-point vectors are interleaved (x, y). Per-point 2x2 tensors are row-major
 * (xx, xy, yx, yy). Stresses are (xx, yy, xy, zz).
 */
#ifndef PORO_TRANSFER_H
#define PORO_TRANSFER_H

#include "grid.h"

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

/* out_p = sum_I S_Ip node_I (Eqs. 38-40, 48). */
void g2p_scalar(const struct grid *g, const struct particles *p, const double *node, double *out);

/* out_p = sum_I S_Ip node_I for a nodal 2-vector. */
void g2p_vector(const struct grid *g, const struct particles *p, const double *node, double *out);

/* out_p = sum_I node_I grad S_Ip: gradient of a nodal scalar, 2 per point. */
void g2p_scalar_gradient(const struct grid *g, const struct particles *p, const double *node, double *out);

/* out_p = sum_I node_I (x) grad S_Ip: gradient of a nodal 2-vector, 4 per point, row-major
 * (d u_x/dx, d u_x/dy, d u_y/dx, d u_y/dy); step 8b uses it for the deformation gradient. */
void g2p_vector_gradient(const struct grid *g, const struct particles *p, const double *node, double *out);

/* out_p = div of a nodal 2-vector at each point. */
void g2p_divergence(const struct grid *g, const struct particles *p, const double *node, double *out);

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
 * point on an edge node, where the edge-modified basis has one node) gives no affine part. */
void p2g_affine_momentum(const struct grid *g, const struct particles *p, const double *mass, const double *v,
			 const double *C, double *out);
void g2p_affine_velocity(const struct grid *g, const struct particles *p, const double *node, double *v,
			 double *C);

#endif
