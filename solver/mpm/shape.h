/*
 * shape.h - shape functions S_Ip and gradients for a point's support nodes (000 §4.5 step 1).
 *
 * Kinds: linear (tent, 2x2 nodes), quadratic B-spline (3x3 nodes, Steffen et al. 2008 style,
 * node-centred), cubic B-spline (4x4 nodes, node-centred, knots at the nodes) and uGIMP (3x3
 * nodes). All are tensor
 * products of 1-D functions.
 *
 * Quadratic B-spline at the grid edges: the standard node-centred basis would need a ghost node
 * beyond the edge. We instead modify the half cell next to an edge so that the basis keeps the
 * partition of unity and is interpolating at the edge (S_edge = 1 there), which makes a velocity
 * constraint on edge nodes an exact wall condition. In local coordinate s in [0, 1/2] measured
 * from the edge (in cells), the edge node's function is 1 - s and its neighbour's s; elsewhere the
 * standard pieces apply. Matching value and slope at s = 1/2 with the standard pieces
 * (1/2 (3/2 - s)^2 and 3/4 - (s - 1)^2) shows the modified basis is still C1 and non-negative.
 *
 * Cubic B-spline at the grid edges: the standard node-centred basis N_i (support 4 cells) needs a
 * ghost node -1 (and cells + 1) within one cell of an edge. The ghost node is eliminated by linear
 * extrapolation, u_-1 = 2 u_0 - u_1, i.e. the boundary-modified basis S_0 = N_0 + 2 N_-1,
 * S_1 = N_1 - N_-1 (mirrored at the upper edge), all other S_i = N_i. This is the cubic analogue
 * of the quadratic treatment above, in the spirit of the boundary-modified B-splines of Steffen,
 * Kirby and Berzins (2008) (not an open knot vector, which would add functions without nodes):
 * one function per grid node, C2, non-negative (S_1 = 2/3 - t^2 + t^3/3 with
 * t = 1 - s falls from 2/3 to 0 over the edge cell), partition of unity and linear fields
 * reproduced exactly (the extrapolation is exact for linear fields), and interpolating at the edge
 * (S_0 = 2/3 + 2/6 = 1, S_1 = 1/6 - 1/6 = 0 there), so a constraint on edge nodes is an exact wall.
 * Needs at least 3 cells per direction.
 *
 * uGIMP (Bardenhagen and Kober 2004; 001 and 002 use it): each point's weight is the average of the
 * linear hat over the point's domain, a square of side sqrt(V0) (its initial volume, kept through
 * the motion: "undeformed" GIMP), S_I = (1/|D|) int_D N_I. 3x3 support nodes (the half width is at
 * most h/2 for the seedings of 1 or more points per cell). Near the grid edges the domain is
 * clipped to the grid, which keeps the partition of unity and linear fields; unlike the
 * B-splines' edge treatment it does not interpolate at the edge (a point whose domain touches the
 * wall gives the edge node less than 1). Locations that are not material points (surface
 * quadrature points) have no domain and get the linear hat, GIMP's zero-width limit.
 * The case loader does not offer it yet: clipped at a wall, the domains put a quarter of the
 * wall's reaction on the node next to the wall node, which no wall condition holds (measured under
 * a uniform stress; docs/numerics.md, "Shape functions at the grid edges"), and the single-point
 * Terzaghi column inverts its corner point at step 45.
 */
#ifndef PORO_SHAPE_H
#define PORO_SHAPE_H

#include <math.h>

#include "grid.h"

/* Support nodes per direction for a shape kind. */
int shape_support(enum case_shape kind);

/* 1-D weights and derivatives (per metre) for coordinate xi (in cells from the grid origin) on a
 * grid of `cells` cells. Writes the first support node to *i0 and support() values to w, dw.
 * Returns 0, or -1 if xi lies outside [0, cells]. */
int shape_1d(enum case_shape kind, double xi, idx_t cells, double inv_h, idx_t *i0, double *w, double *dw);

/* uGIMP's 1-D weights for a point of half width `half_width` (cells, in [0, 1/2]); 3 support
 * nodes. Returns 0, or -1 if xi lies outside [0, cells]. */
int shape_1d_gimp(double xi, double half_width, idx_t cells, double inv_h, idx_t *i0, double *w, double *dw);

/* uGIMP's half width of a point of initial volume V0, in cells: half the side of the square of area
 * V0, at most 1/2 (one point per cell). */
static inline double shape_gimp_half_width(const struct grid *g, double volume0)
{
	const double half = 0.5 * sqrt(volume0) * g->inv_h;
	return half < 0.5 ? half : 0.5;
}

/* uGIMP sampled at the cell centres, for the B-bar of 001 Eqs. 12-16 (spec-001 §3.2): for each of
 * the 3 support nodes (the same i0 as shape_1d_gimp), with o_L and o_R the parts of the point's
 * domain in the node's left and right cells and L the domain's length (clipped to the grid),
 *     G = (o_L - o_R) / (L h)   the overlap-weighted centre gradient of the node's hat, per metre,
 *     W = (o_L + o_R) / L       the share of the domain in the node's two cells.
 * In 2-D the cell-centre gradient of node (a, b) is (G_x[a] W_y[b], W_x[a] G_y[b]) / 2: the other
 * direction's hat is 1/2 at a cell's centre. A domain inside one cell gives the Q4 centre gradient
 * -1/(2h) to its lower-left node. Returns -1 for xi outside [0, cells] or a zero half width. */
int shape_1d_gimp_cell_centre(double xi, double half_width, idx_t cells, double inv_h, idx_t *i0, double *G,
			      double *W);

/* Weights of the support nodes at one location x (for surface quadrature points that are not
 * material points). Writes the first support node and support^2 weights, node order i fastest.
 * Returns 0, or -1 if x lies outside the grid. */
int shape_weights_at(const struct grid *g, enum case_shape kind, const double x[2], idx_t *node0, double *w);

/* Fills p->node0 and p->shape for every point (the shape cache, particles.h) and, when p has
 * scatter blocks, sorts them by the new node0 (point_blocks.h). Returns PORO_ESOLVER naming the
 * first point found outside the grid (the blocks are then stale). */
enum poro_status shape_evaluate(const struct grid *g, enum case_shape kind, struct particles *p,
				const char *set_name, struct poro_error *err);

#endif
