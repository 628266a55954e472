/*
 * shape.c - linear, quadratic and cubic B-spline and uGIMP shape functions (see shape.h for the
 * edge treatments).
 *
 * Local symbols: xi = (x - origin) / h, the coordinate in cells; d = xi - node, the signed distance
 * to a node in cells. Weights are dimensionless, gradients are per metre (multiplied by 1/h).
 */
#include "shape.h"

#include <math.h>

#include "point_blocks.h"

int shape_support(enum case_shape kind)
{
	return kind == SHAPE_LINEAR ? 2 : kind == SHAPE_CUBIC_BSPLINE ? 4 : 3;   /* GIMP: 3 (half width <= h/2) */
}

static inline int linear_1d(double xi, idx_t cells, double inv_h, idx_t *i0, double *w, double *dw)
{
	idx_t i = (idx_t)floor(xi);
	if (i == cells)
		i = cells - 1;          /* a point exactly on the last node belongs to the last cell */
	double f = xi - i;
	*i0 = i;
	w[0] = 1.0 - f;
	w[1] = f;
	dw[0] = -inv_h;
	dw[1] = inv_h;
	return 0;
}

static inline int quadratic_1d(double xi, idx_t cells, double inv_h, idx_t *i0, double *w, double *dw)
{
	if (xi < 0.5) {                 /* half cell at the lower edge: modified, interpolating */
		*i0 = 0;
		w[0] = 1.0 - xi, w[1] = xi, w[2] = 0.0;
		dw[0] = -inv_h, dw[1] = inv_h, dw[2] = 0.0;
		return 0;
	}
	if (xi >= cells - 0.5) {        /* half cell at the upper edge, mirrored; xi = cells - 1/2 lands here
					   so that no support node lies beyond the edge */
		double s = cells - xi;
		*i0 = cells - 2;
		w[0] = 0.0, w[1] = s, w[2] = 1.0 - s;
		dw[0] = 0.0, dw[1] = -inv_h, dw[2] = inv_h;
		return 0;
	}
	idx_t i = (idx_t)(xi + 0.5) - 1;   /* nearest node minus one; xi + 1/2 >= 1, so the cast is floor */
	double d0 = xi - i, d1 = d0 - 1.0, d2 = d0 - 2.0;   /* d0 in [1/2, 3/2) */
	*i0 = i;
	w[0] = 0.5 * (1.5 - d0) * (1.5 - d0);
	w[1] = 0.75 - d1 * d1;
	w[2] = 0.5 * (1.5 + d2) * (1.5 + d2);
	dw[0] = -(1.5 - d0) * inv_h;
	dw[1] = -2.0 * d1 * inv_h;
	dw[2] = (1.5 + d2) * inv_h;
	return 0;
}

/* The uniform cubic B-spline N(d) centred on a node, and dN/dd; zero for |d| >= 2. */
static void cubic_bspline(double d, double *N, double *dN)
{
	double a = fabs(d), sign = d < 0.0 ? -1.0 : 1.0;
	if (a < 1.0) {
		*N = 2.0 / 3.0 - a * a + 0.5 * a * a * a;
		*dN = sign * (-2.0 * a + 1.5 * a * a);
	} else if (a < 2.0) {
		double t = 2.0 - a;
		*N = t * t * t / 6.0;
		*dN = -sign * 0.5 * t * t;
	} else {
		*N = 0.0, *dN = 0.0;
	}
}

/* Node-centred cubic B-splines; the ghost nodes -1 and cells + 1 are folded into the grid by linear
 * extrapolation (shape.h): u_-1 = 2 u_0 - u_1 gives S_0 = N_0 + 2 N_-1 and S_1 = N_1 - N_-1. */
static int cubic_1d(double xi, idx_t cells, double inv_h, idx_t *i0, double *w, double *dw)
{
	idx_t i = (idx_t)floor(xi) - 1;   /* nodes floor(xi) - 1 .. floor(xi) + 2 carry N */
	if (i < 0)
		i = 0;
	if (i > cells - 3)
		i = cells - 3;             /* needs cells >= 3 (the case loader's minimum) */
	double Nlo, dNlo, Nhi, dNhi;       /* the ghost nodes' functions */
	cubic_bspline(xi + 1.0, &Nlo, &dNlo);
	cubic_bspline(xi - (double)(cells + 1), &Nhi, &dNhi);
	*i0 = i;
	for (int a = 0; a < 4; a++) {
		idx_t node = i + a;
		double N, dN;
		cubic_bspline(xi - (double)node, &N, &dN);
		if (node == 0)
			N += 2.0 * Nlo, dN += 2.0 * dNlo;
		else if (node == 1)
			N -= Nlo, dN -= dNlo;
		if (node == cells)
			N += 2.0 * Nhi, dN += 2.0 * dNhi;
		else if (node == cells - 1)
			N -= Nhi, dN -= dNhi;
		w[a] = N;
		dw[a] = dN * inv_h;
	}
	return 0;
}

static inline int gimp_1d(double xi, double lambda, idx_t cells, double inv_h, idx_t *i0, double *w, double *dw)
{
	if (lambda <= 0.0) {             /* the hat itself, on 3 nodes that stay inside the grid */
		idx_t i;
		linear_1d(xi, cells, inv_h, &i, w, dw);
		w[2] = dw[2] = 0.0;
		if (i > cells - 2) {       /* last cell: its two nodes are the upper two of the three */
			w[2] = w[1], w[1] = w[0], w[0] = 0.0;
			dw[2] = dw[1], dw[1] = dw[0], dw[0] = 0.0;
			i = cells - 2;
		}
		*i0 = i;
		return 0;
	}
	const double a = fmax(xi - lambda, 0.0), b = fmin(xi + lambda, (double)cells);
	/* The domain [a, b], at most a cell long, lies in the cells [i, i + 1] and [i + 1, i + 2],
	 * i = floor(a), where the hats are linear: s = a - i and m = min(b, i + 1) - i the part in the
	 * first cell, u = b - (i + 1) the part in the second (0 if none). In the first cell N_i = 1 - t,
	 * N_i+1 = t; in the second N_i+1 = 1 - t, N_i+2 = t (t from the cell's left node); the integrals
	 * and the mean gradients follow in closed form. */
	idx_t i = (idx_t)floor(a);
	const double s = a - (double)i, m = fmin(b - (double)i, 1.0), u = fmax(b - (double)i - 1.0, 0.0);
	const double inv_len = 1.0 / (b - a), first = m - s, half_sq = 0.5 * (m * m - s * s), u_sq = 0.5 * u * u;
	w[0] = (first - half_sq) * inv_len;
	w[1] = (half_sq + u - u_sq) * inv_len;
	w[2] = u_sq * inv_len;
	dw[0] = -first * inv_len * inv_h;
	dw[1] = (first - u) * inv_len * inv_h;
	dw[2] = u * inv_len * inv_h;
	if (i > cells - 2) {      /* a domain in the last cell: its nodes are the upper two of the three */
		w[2] = w[1], w[1] = w[0], w[0] = 0.0;
		dw[2] = dw[1], dw[1] = dw[0], dw[0] = 0.0;
		i = cells - 2;    /* needs cells >= 2 */
	}
	*i0 = i;
	return 0;
}

int shape_1d_gimp_cell_centre(double xi, double half_width, idx_t cells, double inv_h, idx_t *i0, double *G,
			      double *W)
{
	if (!(xi >= 0.0 && xi <= (double)cells) || !(half_width > 0.0))
		return -1;
	const double a = fmax(xi - half_width, 0.0), b = fmin(xi + half_width, (double)cells), inv_len = 1.0 / (b - a);
	idx_t i = (idx_t)floor(a);
	for (int k = 0; k < 3; k++) {
		const double node = (double)(i + k);
		const double left = fmax(0.0, fmin(b, node) - fmax(a, node - 1.0));    /* in [node - 1, node] */
		const double right = fmax(0.0, fmin(b, node + 1.0) - fmax(a, node));   /* in [node, node + 1] */
		G[k] = (left - right) * inv_len * inv_h;
		W[k] = (left + right) * inv_len;
	}
	if (i > cells - 2) {      /* as gimp_1d: the nodes are the upper two of the three */
		G[2] = G[1], G[1] = G[0], G[0] = 0.0;
		W[2] = W[1], W[1] = W[0], W[0] = 0.0;
		i = cells - 2;
	}
	*i0 = i;
	return 0;
}

int shape_1d_gimp(double xi, double half_width, idx_t cells, double inv_h, idx_t *i0, double *w, double *dw)
{
	if (!(xi >= 0.0 && xi <= (double)cells))
		return -1;
	return gimp_1d(xi, half_width, cells, inv_h, i0, w, dw);
}

/* shape_1d's body, inlined where kind is a constant so that the dispatch folds away. */
static inline int evaluate_1d(enum case_shape kind, double xi, idx_t cells, double inv_h, idx_t *i0, double *w,
			      double *dw)
{
	if (!(xi >= 0.0 && xi <= (double)cells))
		return -1;
	if (kind == SHAPE_LINEAR)
		return linear_1d(xi, cells, inv_h, i0, w, dw);
	if (kind == SHAPE_CUBIC_BSPLINE)
		return cubic_1d(xi, cells, inv_h, i0, w, dw);
	if (kind == SHAPE_GIMP)
		return gimp_1d(xi, 0.0, cells, inv_h, i0, w, dw);   /* a location: no domain of its own */
	return quadratic_1d(xi, cells, inv_h, i0, w, dw);
}

int shape_1d(enum case_shape kind, double xi, idx_t cells, double inv_h, idx_t *i0, double *w, double *dw)
{
	return evaluate_1d(kind, xi, cells, inv_h, i0, w, dw);
}

int shape_weights_at(const struct grid *g, enum case_shape kind, const double x[2], idx_t *node0, double *w)
{
	const int S = shape_support(kind);
	double wx[SHAPE_SUPPORT_MAX], wy[SHAPE_SUPPORT_MAX], d[SHAPE_SUPPORT_MAX];
	idx_t i0, j0;
	if (shape_1d(kind, (x[0] - g->origin[0]) * g->inv_h, g->cells[0], g->inv_h, &i0, wx, d) ||
	    shape_1d(kind, (x[1] - g->origin[1]) * g->inv_h, g->cells[1], g->inv_h, &j0, wy, d))
		return -1;
	*node0 = grid_node(g, i0, j0);
	for (int b = 0; b < S; b++)
		for (int a = 0; a < S; a++)
			w[a + b * S] = wx[a] * wy[b];
	return 0;
}

/* The shape cache of point q: node0 and the 1-D factors (particles.h, particle_shape), written in
 * place. Returns -1 if the point lies outside the grid. Called with constant kind and S, so that
 * each kind gets its own copy with the 1-D dispatch folded away (the water points of double
 * point double this phase, 000 §5.3). */
static inline int evaluate_point(const struct grid *g, enum case_shape kind, const int S, struct particles *p,
				 idx_t q)
{
	double *f = p->shape + (size_t)q * 4 * S;   /* wx, wy, dx, dy: particle_shape's layout */
	idx_t i0 = 0, j0 = 0;
	const double xi = (p->x[2 * q] - g->origin[0]) * g->inv_h;
	const double eta = (p->x[2 * q + 1] - g->origin[1]) * g->inv_h;
	if (kind == SHAPE_GIMP) {
		/* uGIMP: the square domain of the point's initial volume, kept through the motion */
		const double lambda = shape_gimp_half_width(g, p->volume0[q]);
		if (shape_1d_gimp(xi, lambda, g->cells[0], g->inv_h, &i0, f, f + 2 * S) ||
		    shape_1d_gimp(eta, lambda, g->cells[1], g->inv_h, &j0, f + S, f + 3 * S))
			return -1;
		p->node0[q] = grid_node(g, i0, j0);
		return 0;
	}
	if (evaluate_1d(kind, xi, g->cells[0], g->inv_h, &i0, f, f + 2 * S) ||
	    evaluate_1d(kind, eta, g->cells[1], g->inv_h, &j0, f + S, f + 3 * S))
		return -1;
	p->node0[q] = grid_node(g, i0, j0);
	return 0;
}

enum poro_status shape_evaluate(const struct grid *g, enum case_shape kind, struct particles *p,
				const char *set_name, struct poro_error *err)
{
	idx_t bad = -1;
	p->support = shape_support(kind);
#pragma omp parallel for schedule(static)
	for (idx_t q = 0; q < p->n; q++) {
		int outside;
		switch (kind) {
		case SHAPE_LINEAR: outside = evaluate_point(g, SHAPE_LINEAR, 2, p, q); break;
		case SHAPE_CUBIC_BSPLINE: outside = evaluate_point(g, SHAPE_CUBIC_BSPLINE, 4, p, q); break;
		case SHAPE_GIMP: outside = evaluate_point(g, SHAPE_GIMP, 3, p, q); break;
		default: outside = evaluate_point(g, SHAPE_QUADRATIC_BSPLINE, 3, p, q); break;
		}
		if (outside) {
#pragma omp critical
			if (bad < 0 || q < bad)
				bad = q;
		}
	}
	if (p->blocks && bad < 0)   /* the scatters' order follows the new node0 (point_blocks.h) */
		point_blocks_sort(p->blocks, p);
	else if (p->blocks)
		p->blocks->n = -1;
	if (bad >= 0)
		return poro_error_set(err, PORO_ESOLVER,
				      "%s point %ld left the grid at (%.6g, %.6g) m", set_name, (long)bad,
				      p->x[2 * bad], p->x[2 * bad + 1]);
	return PORO_OK;
}
