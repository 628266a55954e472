/*
 * shape_test.c - shape functions: partition of unity and zero gradient sum at
 * high-entropy points, including the half cells next to the grid edges; gradients against
 * central finite differences of the weights; non-negativity; the interpolating edge property;
 * reproduction of linear fields (sum S_i x_i = x, sum dS_i x_i = 1) for linear, quadratic and
 * cubic B-splines, the cubic ones with their boundary-modified edge cells (shape.h), and uGIMP at
 * several half widths, its domains clipped at the edges; uGIMP against its closed form inside the
 * grid and against the linear hat at zero width.
 */
#include "../harness.h"
#include "shape.h"

#define SAMPLES 20000

/* One kind's 1-D weights; `lambda` is uGIMP's half width in cells (ignored by the B-splines). */
static int weights_1d(enum case_shape kind, double lambda, double xi, idx_t cells, double inv_h, idx_t *i0, double *w,
		      double *dw)
{
	return kind == SHAPE_GIMP ? shape_1d_gimp(xi, lambda, cells, inv_h, i0, w, dw)
				  : shape_1d(kind, xi, cells, inv_h, i0, w, dw);
}

/* Whether xi lies within 1e-4 cells of a place where a kind's pieces join (where a central
 * difference straddles two pieces): integers and half-integers for the B-splines, integers +-
 * lambda for uGIMP (|d| = lambda, 1 - lambda, 1 + lambda, and the clipping at the edges). */
static int near_a_join(enum case_shape kind, double lambda, double xi)
{
	if (kind == SHAPE_GIMP)
		return fabs(xi - lambda - round(xi - lambda)) < 1e-4 || fabs(xi + lambda - round(xi + lambda)) < 1e-4 ||
		       fabs(xi - round(xi)) < 1e-4;
	return fabs(2 * xi - round(2 * xi)) < 1e-4;
}

static void check_kind(enum case_shape kind, double lambda, const char *label)
{
	const idx_t cells = 7;
	const double h = 0.0371, inv_h = 1.0 / h;
	const int S = shape_support(kind);
	double worst_sum = 0, worst_grad = 0, worst_fd = 0, min_w = 1, worst_lin = 0, worst_dlin = 0, worst_clipped = 0;
	int out_of_range = 0;
	for (int k = 0; k < SAMPLES; k++) {
		/* half the samples inside the two cells next to either edge, where the edge pieces live */
		double xi = k % 4 == 0 ? rnd(0, 2) : k % 4 == 1 ? rnd(cells - 2, cells) : rnd(0, cells);
		idx_t i0;
		double w[SHAPE_SUPPORT_MAX], dw[SHAPE_SUPPORT_MAX];
		weights_1d(kind, lambda, xi, cells, inv_h, &i0, w, dw);
		if (i0 < 0 || i0 + S - 1 > cells)
			out_of_range++;
		double sum = 0, gsum = 0;
		for (int a = 0; a < S; a++) {
			sum += w[a], gsum += dw[a];
			min_w = fmin(min_w, w[a]);
		}
		worst_sum = fmax(worst_sum, fabs(sum - 1));
		worst_grad = fmax(worst_grad, fabs(gsum) * h);
		/* linear field u = x (in cells): sum S_a (i0 + a) = xi, sum dS_a (i0 + a) = 1 / h; uGIMP
		 * gives the mean of x over its domain, the domain's centre (xi itself wherever the domain
		 * is inside), and the mean of its gradient, 1 / h, clipped or not (shape.c) */
		double lin = 0, dlin = 0, centre = xi, dcentre = 1;
		const int clipped = kind == SHAPE_GIMP && lambda > 0 && (xi - lambda <= 0 || xi + lambda >= cells);
		if (kind == SHAPE_GIMP && lambda > 0) {
			const double lo = fmax(xi - lambda, 0), hi = fmin(xi + lambda, (double)cells);
			centre = 0.5 * (lo + hi);
		}
		for (int a = 0; a < S; a++)
			lin += w[a] * (double)(i0 + a), dlin += dw[a] * (double)(i0 + a);
		worst_lin = fmax(worst_lin, fabs(lin - centre) / cells);
		worst_dlin = fmax(worst_dlin, fabs(dlin * h - dcentre));
		/* uGIMP's gradient weight where the domain is clipped is the mean of the hat's gradient
		 * over the clipped domain, (N(b) - N(a)) / (b - a), not the derivative of the weight */
		if (clipped) {
			const double lo = fmax(xi - lambda, 0), hi = fmin(xi + lambda, (double)cells);
			for (int a = 0; a < S; a++) {
				const double node = (double)(i0 + a);
				const double mean = (fmax(0, 1 - fabs(hi - node)) - fmax(0, 1 - fabs(lo - node))) / (hi - lo);
				worst_clipped = fmax(worst_clipped, fabs(mean - dw[a] * h));
			}
		}
		/* finite difference of node i0+a's weight in x (in metres) */
		const double eps = 1e-6;
		if (xi > eps && xi < cells - eps && !near_a_join(kind, lambda, xi) && !clipped) {
			for (int a = 0; a < S; a++) {
				double wp[SHAPE_SUPPORT_MAX], wm[SHAPE_SUPPORT_MAX], d[SHAPE_SUPPORT_MAX];
				idx_t ip, im;
				weights_1d(kind, lambda, xi + eps, cells, inv_h, &ip, wp, d);
				weights_1d(kind, lambda, xi - eps, cells, inv_h, &im, wm, d);
				double vp = 0, vm = 0;   /* weight of node i0+a seen from either side */
				if (i0 + a - ip >= 0 && i0 + a - ip < S) vp = wp[i0 + a - ip];
				if (i0 + a - im >= 0 && i0 + a - im < S) vm = wm[i0 + a - im];
				double fd = (vp - vm) / (2 * eps * h);
				worst_fd = fmax(worst_fd, fabs(fd - dw[a]) * h);
			}
		}
	}
	char name[96];
	printf("INFO %s: max |sum S - 1| = %.2e, max |sum dS| h = %.2e, max FD gradient error %.2e, min S %.2e, "
	       "linear field error %.2e (value / cells), %.2e (gradient h)\n",
	       label, worst_sum, worst_grad, worst_fd, min_w, worst_lin, worst_dlin);
	snprintf(name, sizeof name, "%s_partition_of_unity", label);
	CHECK(worst_sum < 1e-14, name, "max |sum - 1| = %.3e", worst_sum);
	snprintf(name, sizeof name, "%s_gradient_sum_zero", label);
	CHECK(worst_grad < 1e-13, name, "max |sum dS| h = %.3e", worst_grad);
	snprintf(name, sizeof name, "%s_gradient_matches_finite_difference", label);
	CHECK(worst_fd < 1e-6, name, "max error %.3e", worst_fd);
	if (kind == SHAPE_GIMP && lambda > 0) {
		printf("INFO %s: clipped domains' gradient weights against the mean hat gradient: %.2e\n", label,
		       worst_clipped);
		snprintf(name, sizeof name, "%s_clipped_gradient_is_mean_gradient", label);
		CHECK(worst_clipped < 1e-14, name, "max error %.3e", worst_clipped);
	}
	snprintf(name, sizeof name, "%s_reproduces_linear_fields", label);
	CHECK(worst_lin < 1e-14 && worst_dlin < 1e-13, name, "value error %.3e, gradient error %.3e", worst_lin, worst_dlin);
	snprintf(name, sizeof name, "%s_non_negative", label);
	CHECK(min_w >= 0, name, "min weight %.3e", min_w);
	snprintf(name, sizeof name, "%s_support_inside_grid", label);
	CHECK(out_of_range == 0, name, "%d samples reach beyond the grid", out_of_range);

	/* interpolating at the edges: the edge node's weight is 1 there (not uGIMP with a width: a
	 * point on the edge averages the hat over the half of its domain inside the grid) */
	idx_t i0;
	double w[SHAPE_SUPPORT_MAX], dw[SHAPE_SUPPORT_MAX];
	if (kind != SHAPE_GIMP || lambda == 0.0) {
		weights_1d(kind, lambda, 0.0, cells, inv_h, &i0, w, dw);
		int lower = i0 == 0 && fabs(w[0] - 1) < 1e-15;
		weights_1d(kind, lambda, (double)cells, cells, inv_h, &i0, w, dw);
		int upper = i0 + S - 1 == cells && fabs(w[S - 1] - 1) < 1e-15;
		snprintf(name, sizeof name, "%s_interpolating_at_edges", label);
		CHECK(lower && upper, name, "edge weights not 1");
	}
	snprintf(name, sizeof name, "%s_outside_rejected", label);
	CHECK(weights_1d(kind, lambda, -1e-9, cells, inv_h, &i0, w, dw) == -1 &&
	      weights_1d(kind, lambda, cells + 1e-9, cells, inv_h, &i0, w, dw) == -1, name, "a point outside was accepted");
}

/* uGIMP against brute force: the mean of the hat and of its gradient over the point's domain
 * [xi - lambda, xi + lambda] clipped to the grid, by the midpoint rule on QUADRATURE_SAMPLES
 * sub-intervals, at random points inside and next to the edges and random half widths. */
#define QUADRATURE_SAMPLES 20000
static void check_gimp_brute_force(void)
{
	const idx_t cells = 5;
	const double inv_h = 1.0 / 0.0437;
	double worst = 0, worst_grad = 0;
	for (int k = 0; k < 400; k++) {
		const double lambda = rnd(0.01, 0.5), xi = k % 2 ? rnd(0, 1) : rnd(0, (double)cells);
		const double a = fmax(xi - lambda, 0), b = fmin(xi + lambda, (double)cells);
		double w[SHAPE_SUPPORT_MAX], dw[SHAPE_SUPPORT_MAX];
		idx_t i0;
		shape_1d_gimp(xi, lambda, cells, inv_h, &i0, w, dw);
		for (int n = 0; n < 3; n++) {
			const double node = (double)(i0 + n);
			double mean = 0, mean_grad = 0;
			for (int j = 0; j < QUADRATURE_SAMPLES; j++) {
				const double x = a + (j + 0.5) * (b - a) / QUADRATURE_SAMPLES, d = x - node;
				mean += fmax(0, 1 - fabs(d)) / QUADRATURE_SAMPLES;
				mean_grad += (fabs(d) < 1 ? (d < 0 ? 1.0 : -1.0) : 0.0) / QUADRATURE_SAMPLES;
			}
			worst = fmax(worst, fabs(w[n] - mean));
			worst_grad = fmax(worst_grad, fabs(dw[n] / inv_h - mean_grad));
		}
	}
	printf("INFO gimp against the midpoint rule (%d samples): weights %.2e, gradients h %.2e\n", QUADRATURE_SAMPLES,
	       worst, worst_grad);
	CHECK(worst < 1e-8 && worst_grad < 1e-3, "gimp_matches_brute_force_means", "weights %.3e gradients %.3e", worst,
	      worst_grad);
}

/* uGIMP next to a wall: under a uniform stress sigma the nodal forces -sigma sum_p V_p dS_I/dx of
 * rows of points seeded h/2 apart from the wall (2 points per cell, half width h/4, the first
 * domain touching the wall) are -sigma on the wall node and 0 on every other node, so a wall
 * condition takes the whole reaction; the derivative of the clipped weight gave -0.75 and -0.25. */
static void check_gimp_wall_row(void)
{
	const idx_t cells = 6;
	const double h = 0.0437, inv_h = 1.0 / h, lambda = 0.25;
	double force[8] = {0};
	for (int k = 0; k < 2 * (int)cells; k++) {
		const double xi = 0.25 + 0.5 * k;
		double w[SHAPE_SUPPORT_MAX], dw[SHAPE_SUPPORT_MAX];
		idx_t i0;
		shape_1d_gimp(xi, lambda, cells, inv_h, &i0, w, dw);
		for (int a = 0; a < 3; a++)
			force[i0 + a] -= 0.5 * h * dw[a];   /* V = h / 2 per unit height, sigma = 1 */
	}
	double worst_inner = 0;
	for (idx_t I = 1; I < cells; I++)
		worst_inner = fmax(worst_inner, fabs(force[I]));
	printf("INFO gimp wall row: forces under a unit stress: wall nodes %.6f and %.6f, largest inner %.2e\n",
	       force[0], force[cells], worst_inner);
	CHECK(fabs(force[0] - 1.0) < 1e-14 && fabs(force[cells] + 1.0) < 1e-14 && worst_inner < 1e-14,
	      "gimp_wall_row_takes_whole_reaction", "wall %.6f / %.6f, inner %.3e", force[0], force[cells], worst_inner);
}

/* 2-D: the tensor product keeps both properties at random points of a whole grid. */
static void check_2d(enum case_shape kind, const char *label)
{
	const double spacing = 0.0413 / 2;   /* uGIMP: 2x2 points per cell, half width h/4 */
	struct case_grid spec = {.origin = {-1.234, 0.567}, .extent = {6 * 0.0413, 5 * 0.0413}, .cell_size = 0.0413};
	struct grid g;
	grid_init(&g, &spec, NULL);
	struct particles p;
	particles_init(&p, 5000, 0, NULL);
	for (idx_t q = 0; q < p.n; q++) {
		p.x[2 * q] = spec.origin[0] + rnd(0, spec.extent[0]);
		p.x[2 * q + 1] = spec.origin[1] + rnd(0, spec.extent[1]);
		p.volume0[q] = spacing * spacing;
	}
	enum poro_status st = shape_evaluate(&g, kind, &p, "test", NULL);
	int S = p.support, nn = S * S;
	double worst = 0, worst_g = 0;
	for (idx_t q = 0; q < p.n; q++) {
		double s = 0, gx = 0, gy = 0;
		const struct shape_factors f = particle_shape(&p, q);
		for (int k = 0; k < nn; k++) {
			const int a = k % S, b = k / S;
			s += f.wx[a] * f.wy[b];
			gx += f.dx[a] * f.wy[b], gy += f.wx[a] * f.dy[b];
		}
		worst = fmax(worst, fabs(s - 1));
		worst_g = fmax(worst_g, fmax(fabs(gx), fabs(gy)) * g.h);
	}
	char name[96];
	snprintf(name, sizeof name, "%s_2d_partition_and_gradient", label);
	CHECK(st == PORO_OK && worst < 1e-14 && worst_g < 1e-13, name, "sum err %.3e grad %.3e", worst, worst_g);
	p.x[0] = spec.origin[0] - 1e-6;
	struct poro_error err = {0};
	st = shape_evaluate(&g, kind, &p, "soil", &err);
	snprintf(name, sizeof name, "%s_point_outside_grid_reported", label);
	CHECK(st == PORO_ESOLVER && strstr(err.message, "soil point 0 left the grid"), name, "status %d '%s'", st, err.message);
	particles_release(&p);
}

/* Cubic B-splines: away from the edges the weights are the uniform cubic B-spline's, and the
 * boundary-modified edge functions take the closed forms of shape.h: at s in the edge cell,
 * S_0 = N(s) + 2 (1 - s)^3 / 6 and S_1 = 2/3 - t^2 + t^3 / 3 with t = 1 - s (mirrored at the top);
 * with only 3 cells (the fewest the case loader allows) both edge treatments act in one support. */
static void check_cubic_closed_form(void)
{
	const double inv_h = 1.0 / 0.0271;
	double worst = 0;
	for (idx_t cells = 3; cells <= 9; cells += 6)
		for (int k = 0; k < 2000; k++) {
			double xi = rnd(0, (double)cells), w[SHAPE_SUPPORT_MAX], dw[SHAPE_SUPPORT_MAX];
			idx_t i0;
			shape_1d(SHAPE_CUBIC_BSPLINE, xi, cells, inv_h, &i0, w, dw);
			for (int a = 0; a < 4; a++) {
				double node = (double)(i0 + a), d = fabs(xi - node), ref;
				ref = d < 1 ? 2.0 / 3 - d * d + d * d * d / 2 : d < 2 ? (2 - d) * (2 - d) * (2 - d) / 6 : 0;
				double s0 = xi, s1 = cells - xi;   /* distances to the edges, cells */
				if (i0 + a == 0 && s0 < 1)
					ref += (1 - s0) * (1 - s0) * (1 - s0) / 3;
				if (i0 + a == 1 && s0 < 1)
					ref = 2.0 / 3 - (1 - s0) * (1 - s0) + (1 - s0) * (1 - s0) * (1 - s0) / 3;
				if (i0 + a == cells && s1 < 1)
					ref += (1 - s1) * (1 - s1) * (1 - s1) / 3;
				if (i0 + a == cells - 1 && s1 < 1)
					ref = 2.0 / 3 - (1 - s1) * (1 - s1) + (1 - s1) * (1 - s1) * (1 - s1) / 3;
				worst = fmax(worst, fabs(w[a] - ref));
			}
		}
	printf("INFO cubic_bspline: max difference from the closed-form weights %.2e\n", worst);
	CHECK(worst < 1e-14, "cubic_bspline_matches_closed_form", "max difference %.3e", worst);
}

/* uGIMP inside the grid against Bardenhagen and Kober's piecewise form (d = xi - I in cells,
 * lambda the half width): S = 1 - (d^2 + lambda^2) / (2 lambda) for |d| < lambda, 1 - |d| for
 * lambda <= |d| < 1 - lambda, (1 + lambda - |d|)^2 / (4 lambda) for 1 - lambda <= |d| < 1 + lambda;
 * and at zero width, the linear hat's weights. */
static void check_gimp_closed_form(void)
{
	const idx_t cells = 8;
	const double inv_h = 1.0 / 0.0311;
	double worst = 0, worst_grad = 0, worst_hat = 0;
	for (int k = 0; k < 4000; k++) {
		const double lambda = rnd(0.01, 0.5), xi = rnd(lambda, cells - lambda);   /* domain inside the grid */
		double w[SHAPE_SUPPORT_MAX], dw[SHAPE_SUPPORT_MAX];
		idx_t i0;
		shape_1d_gimp(xi, lambda, cells, inv_h, &i0, w, dw);
		for (int a = 0; a < 3; a++) {
			const double d = xi - (double)(i0 + a), ad = fabs(d), sg = d < 0 ? -1.0 : 1.0;
			double ref = 0, dref = 0;   /* dref: dS/dxi */
			if (ad < lambda)
				ref = 1 - (d * d + lambda * lambda) / (2 * lambda), dref = -d / lambda;
			else if (ad < 1 - lambda)
				ref = 1 - ad, dref = -sg;
			else if (ad < 1 + lambda)
				ref = (1 + lambda - ad) * (1 + lambda - ad) / (4 * lambda), dref = -sg * (1 + lambda - ad) / (2 * lambda);
			worst = fmax(worst, fabs(w[a] - ref));
			worst_grad = fmax(worst_grad, fabs(dw[a] / inv_h - dref));
		}
		/* zero width: the hat's two weights on the same nodes */
		double wl[SHAPE_SUPPORT_MAX], dl[SHAPE_SUPPORT_MAX];
		idx_t il;
		shape_1d_gimp(xi, 0.0, cells, inv_h, &i0, w, dw);
		shape_1d(SHAPE_LINEAR, xi, cells, inv_h, &il, wl, dl);
		for (int a = 0; a < 3; a++) {
			const idx_t node = i0 + a;
			const double lin = node == il ? wl[0] : node == il + 1 ? wl[1] : 0.0;
			const double dlin = node == il ? dl[0] : node == il + 1 ? dl[1] : 0.0;
			worst_hat = fmax(worst_hat, fmax(fabs(w[a] - lin), fabs(dw[a] - dlin) / inv_h));
		}
	}
	printf("INFO gimp: max difference from the closed form %.2e (weights), %.2e (gradients h); zero width from "
	       "the linear hat %.2e\n", worst, worst_grad, worst_hat);
	CHECK(worst < 1e-14 && worst_grad < 1e-13, "gimp_matches_closed_form", "weights %.3e gradients %.3e", worst,
	      worst_grad);
	CHECK(worst_hat < 1e-15, "gimp_zero_width_is_linear", "difference %.3e", worst_hat);
}

int main(void)
{
	check_kind(SHAPE_LINEAR, 0, "linear");
	check_kind(SHAPE_QUADRATIC_BSPLINE, 0, "quadratic_bspline");
	check_kind(SHAPE_CUBIC_BSPLINE, 0, "cubic_bspline");
	check_kind(SHAPE_GIMP, 0.25, "gimp_2x2");       /* half widths of 2, 3 and 1 points per cell */
	check_kind(SHAPE_GIMP, 1.0 / 6, "gimp_3x3");
	check_kind(SHAPE_GIMP, 0.5, "gimp_1x1");
	check_kind(SHAPE_GIMP, 0.0, "gimp_zero_width");
	check_cubic_closed_form();
	check_gimp_closed_form();
	check_gimp_wall_row();
	check_gimp_brute_force();
	check_2d(SHAPE_LINEAR, "linear");
	check_2d(SHAPE_QUADRATIC_BSPLINE, "quadratic_bspline");
	check_2d(SHAPE_CUBIC_BSPLINE, "cubic_bspline");
	check_2d(SHAPE_GIMP, "gimp");
	HARNESS_EXIT();
}
