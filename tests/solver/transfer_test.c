/*
 * transfer_test.c - the APIC transfers of transfer.c against their defining properties, for
 * linear, quadratic and cubic B-spline shapes at high-entropy points over a whole grid (a third of
 * them in the cells next to the edges, where the edge-modified bases live):
 *   - an affine nodal velocity v_I = A x_I + b comes back exactly: v_p = A x_p + b, C_p = A;
 *   - P2G keeps linear momentum, sum_I P_I = sum_p m_p v_p, and angular momentum,
 *     sum_I x_I x P_I = sum_p m_p (x_p x v_p + (C_p D_p)_yx - (C_p D_p)_xy);
 *   - G2P keeps angular momentum: the points' sum of the same expression equals
 *     sum_I M_I x_I x v_I for any nodal velocity, M_I = sum_p S_Ip m_p;
 * with D_p = sum_I S_Ip (x_I - x_p)(x_I - x_p)^T summed by brute force over the support here.
 * And the per-point kernels that let a phase be one loop: the batched scatter, the one-point
 * gather and the FLIP update give bit for bit what the whole-set kernels give (transfer.h
 * promises it, and the scheme's results rest on it); the fused gradient and divergence scatters
 * match a brute-force evaluation from shape_1d; AFLIP's gather of the affine part alone equals
 * APIC's. The linear-fit scatter (p2g_scalar_linear_fit, the Laplacian's nodal pressure) returns
 * a linear point field's value at every node the points reach, edge nodes included, where the
 * mass-weighted mean it replaces is visibly off (the hydrostatic pressure's bias at a wall).
 * The scatters run in parallel in the block order of point_blocks.h when the set has blocks: on a
 * random cloud over a grid of many blocks, a third of it next to the edges and some points on
 * them, every scatter matches a brute-force serial sum in index order from shape_1d to 1e-13 of
 * its largest entry (the linear fit: the same kernel run serially in index order), and gives the
 * same bits on one thread as on two.
 */
#include <omp.h>

#include "../harness.h"
#include "particles.h"
#include "shape.h"
#include "transfer.h"

#define POINTS 3000
#define TOLERANCE 1e-12   /* relative */

/* Node coordinates, the point's position as the cache sees it (sum S x_I) and D_p, brute force. */
static void point_frame(const struct grid *g, const struct particles *p, idx_t q, double xp[2], double D[4])
{
	const int S = p->support;
	const struct shape_factors f = particle_shape(p, q);
	const idx_t nx = g->nodes[0], i0 = p->node0[q] % nx, j0 = p->node0[q] / nx;
	xp[0] = xp[1] = 0.0;
	for (int b = 0; b < S; b++)
		for (int a = 0; a < S; a++) {
			const double wk = f.wx[a] * f.wy[b];
			xp[0] += wk * (g->origin[0] + (double)(i0 + a) * g->h);
			xp[1] += wk * (g->origin[1] + (double)(j0 + b) * g->h);
		}
	D[0] = D[1] = D[2] = D[3] = 0.0;
	for (int b = 0; b < S; b++)
		for (int a = 0; a < S; a++) {
			const double wk = f.wx[a] * f.wy[b];
			const double d[2] = { g->origin[0] + (double)(i0 + a) * g->h - xp[0],
					      g->origin[1] + (double)(j0 + b) * g->h - xp[1] };
			for (int r = 0; r < 2; r++)
				for (int c = 0; c < 2; c++)
					D[2 * r + c] += wk * d[r] * d[c];
		}
}

/* m (x_p x v_p + (C D)_yx - (C D)_xy): a point's angular momentum about the origin under APIC. */
static double point_angular_momentum(double m, const double xp[2], const double *v, const double *C,
				     const double D[4])
{
	const double CD_xy = C[0] * D[1] + C[1] * D[3], CD_yx = C[2] * D[0] + C[3] * D[2];
	return m * (xp[0] * v[1] - xp[1] * v[0] + CD_yx - CD_xy);
}

static void check_kind(enum case_shape kind, const char *label)
{
	struct case_grid spec = {.origin = {-0.731, 1.259}, .extent = {7 * 0.0437, 6 * 0.0437}, .cell_size = 0.0437};
	struct grid g;
	struct particles p;
	char name[96];
	grid_init(&g, &spec, NULL);
	particles_init(&p, POINTS, 0, NULL);
	particles_add_affine(&p, NULL);
	for (idx_t q = 0; q < p.n; q++) {
		const double edge = 1.7 * spec.cell_size;   /* within the edge cells for a third of them */
		p.x[2 * q] = spec.origin[0] + (q % 3 == 0 ? rnd(0, edge) : rnd(0, spec.extent[0]));
		p.x[2 * q + 1] = spec.origin[1] + (q % 3 == 1 ? spec.extent[1] - rnd(0, edge) : rnd(0, spec.extent[1]));
		p.mass[q] = rnd(0.3, 2.9);
	}
	shape_evaluate(&g, kind, &p, "test", NULL);
	const idx_t N = g.node_count;
	double *node = calloc(2 * (size_t)N, sizeof(double)), *mom = calloc(2 * (size_t)N, sizeof(double));
	double *M = calloc((size_t)N, sizeof(double));

	/* an affine nodal field comes back exactly */
	const double A[4] = { 0.813, -1.247, 2.061, 0.379 }, bvec[2] = { -0.452, 1.137 };
	for (idx_t I = 0; I < N; I++) {
		const double x = g.origin[0] + (double)(I % g.nodes[0]) * g.h, y = g.origin[1] + (double)(I / g.nodes[0]) * g.h;
		node[2 * I] = A[0] * x + A[1] * y + bvec[0];
		node[2 * I + 1] = A[2] * x + A[3] * y + bvec[1];
	}
	g2p_affine_velocity(&g, &p, node, p.v, p.C);
	double worst_v = 0, worst_C = 0;
	idx_t no_affine = 0;
	for (idx_t q = 0; q < p.n; q++) {
		double xp[2], D[4];
		point_frame(&g, &p, q, xp, D);
		worst_v = fmax(worst_v, hypot(p.v[2 * q] - (A[0] * xp[0] + A[1] * xp[1] + bvec[0]),
					      p.v[2 * q + 1] - (A[2] * xp[0] + A[3] * xp[1] + bvec[1])));
		if (D[0] > 1e-9 * g.h * g.h && D[3] > 1e-9 * g.h * g.h)
			for (int c = 0; c < 4; c++)
				worst_C = fmax(worst_C, fabs(p.C[4 * q + c] - A[c]));
		else
			no_affine++;
	}
	snprintf(name, sizeof name, "%s_apic_affine_field_returned_exactly", label);
	CHECK(worst_v < TOLERANCE * 10 && worst_C < 1e-9 && no_affine < p.n / 100, name,
	      "velocity %.2e m/s, affine %.2e 1/s, %ld points without an affine part", worst_v, worst_C,
	      (long)no_affine);

	/* P2G keeps linear and angular momentum, for arbitrary point velocities and affine parts */
	double P_points[2] = {0, 0}, L_points = 0, scale_P = 0, scale_L = 0;
	for (idx_t q = 0; q < p.n; q++) {
		double xp[2], D[4];
		point_frame(&g, &p, q, xp, D);
		p.v[2 * q] = rnd(-1.3, 1.3), p.v[2 * q + 1] = rnd(-1.3, 1.3);
		for (int c = 0; c < 4; c++)
			p.C[4 * q + c] = rnd(-20, 20);
		P_points[0] += p.mass[q] * p.v[2 * q], P_points[1] += p.mass[q] * p.v[2 * q + 1];
		scale_P += p.mass[q] * hypot(p.v[2 * q], p.v[2 * q + 1]);
		L_points += point_angular_momentum(p.mass[q], xp, p.v + 2 * q, p.C + 4 * q, D);
		scale_L += fabs(point_angular_momentum(p.mass[q], xp, p.v + 2 * q, p.C + 4 * q, D));
	}
	p2g_affine_momentum(&g, &p, p.mass, p.v, p.C, mom);
	double P_grid[2] = {0, 0}, L_grid = 0;
	for (idx_t I = 0; I < N; I++) {
		const double x = g.origin[0] + (double)(I % g.nodes[0]) * g.h, y = g.origin[1] + (double)(I / g.nodes[0]) * g.h;
		P_grid[0] += mom[2 * I], P_grid[1] += mom[2 * I + 1];
		L_grid += x * mom[2 * I + 1] - y * mom[2 * I];
	}
	snprintf(name, sizeof name, "%s_apic_p2g_keeps_linear_momentum", label);
	CHECK(hypot(P_grid[0] - P_points[0], P_grid[1] - P_points[1]) < TOLERANCE * scale_P, name,
	      "difference %.2e of %.2e", hypot(P_grid[0] - P_points[0], P_grid[1] - P_points[1]), scale_P);
	snprintf(name, sizeof name, "%s_apic_p2g_keeps_angular_momentum", label);
	CHECK(fabs(L_grid - L_points) < TOLERANCE * scale_L, name, "difference %.2e of %.2e", fabs(L_grid - L_points),
	      scale_L);

	/* G2P keeps angular momentum: any nodal velocity, the nodal masses the points give */
	p2g_scalar(&g, &p, NULL, p.mass, M);
	double L_nodes = 0, scale_nodes = 0;
	for (idx_t I = 0; I < N; I++) {
		const double x = g.origin[0] + (double)(I % g.nodes[0]) * g.h, y = g.origin[1] + (double)(I / g.nodes[0]) * g.h;
		node[2 * I] = rnd(-2.1, 2.1), node[2 * I + 1] = rnd(-2.1, 2.1);
		L_nodes += M[I] * (x * node[2 * I + 1] - y * node[2 * I]);
		scale_nodes += M[I] * fabs(x * node[2 * I + 1] - y * node[2 * I]);
	}
	g2p_affine_velocity(&g, &p, node, p.v, p.C);
	double L_back = 0;
	for (idx_t q = 0; q < p.n; q++) {
		double xp[2], D[4];
		point_frame(&g, &p, q, xp, D);
		L_back += point_angular_momentum(p.mass[q], xp, p.v + 2 * q, p.C + 4 * q, D);
	}
	snprintf(name, sizeof name, "%s_apic_g2p_keeps_angular_momentum", label);
	CHECK(fabs(L_back - L_nodes) < 1e-10 * scale_nodes, name, "difference %.2e of %.2e", fabs(L_back - L_nodes),
	      scale_nodes);
	free(node);
	free(mom);
	free(M);
	particles_release(&p);
}

/* A point's brute-force shape functions from shape_1d: node0 and S, grad S over the support. */
static idx_t brute_shape(const struct grid *g, enum case_shape kind, const double x[2], double *S, double *Sx,
			 double *Sy)
{
	double wx[SHAPE_SUPPORT_MAX], wy[SHAPE_SUPPORT_MAX], dx[SHAPE_SUPPORT_MAX], dy[SHAPE_SUPPORT_MAX];
	idx_t i0, j0;
	shape_1d(kind, (x[0] - g->origin[0]) * g->inv_h, g->cells[0], g->inv_h, &i0, wx, dx);
	shape_1d(kind, (x[1] - g->origin[1]) * g->inv_h, g->cells[1], g->inv_h, &j0, wy, dy);
	const int n = shape_support(kind);
	for (int b = 0; b < n; b++)
		for (int a = 0; a < n; a++) {
			S[a + b * n] = wx[a] * wy[b];
			Sx[a + b * n] = dx[a] * wy[b];
			Sy[a + b * n] = wx[a] * dy[b];
		}
	return i0 + j0 * g->nodes[0];
}

static double max_abs_difference(const double *a, const double *b, size_t n, double *scale)
{
	double worst = 0.0;
	*scale = 0.0;
	for (size_t i = 0; i < n; i++) {
		worst = fmax(worst, fabs(a[i] - b[i]));
		*scale = fmax(*scale, fabs(b[i]));
	}
	return worst;
}

static void check_fused(enum case_shape kind, const char *label)
{
	struct case_grid spec = {.origin = {0.383, -2.117}, .extent = {9 * 0.0611, 5 * 0.0611}, .cell_size = 0.0611};
	struct grid g;
	struct particles p;
	char name[96];
	grid_init(&g, &spec, NULL);
	particles_init(&p, POINTS, 0, NULL);
	double *value[4], *vec = malloc(2 * POINTS * sizeof(double));
	for (int k = 0; k < 4; k++)
		value[k] = malloc(POINTS * sizeof(double));
	for (idx_t q = 0; q < p.n; q++) {
		p.x[2 * q] = spec.origin[0] + rnd(0, spec.extent[0]);
		p.x[2 * q + 1] = spec.origin[1] + rnd(0, spec.extent[1]);
		p.mass[q] = rnd(0.3, 2.9);
		for (int k = 0; k < 4; k++)
			value[k][q] = rnd(-3.7, 5.3);
		vec[2 * q] = rnd(-1.9, 1.9), vec[2 * q + 1] = rnd(-1.9, 1.9);
	}
	shape_evaluate(&g, kind, &p, "test", NULL);
	const size_t N = (size_t)g.node_count;
	double *fused = calloc(6 * N, sizeof(double)), *apart = calloc(6 * N, sizeof(double));
	double *node = malloc(2 * N * sizeof(double)), *dnode = malloc(2 * N * sizeof(double));
	for (size_t I = 0; I < 2 * N; I++)
		node[I] = rnd(-2.3, 2.3), dnode[I] = rnd(-0.7, 0.7);

	/* the batch: four scalar channels (weighted and not) and a vector channel */
	const struct p2g_batch b = {
		.scalars = 4,
		.scalar = {{NULL, value[0], fused}, {p.mass, value[1], fused + N}, {value[2], NULL, fused + 2 * N},
			   {p.mass, value[3], fused + 3 * N}},
		.vector = {p.mass, vec, fused + 4 * N},
	};
	p2g_batch(&g, &p, &b);
	p2g_scalar(&g, &p, NULL, value[0], apart);
	p2g_scalar(&g, &p, p.mass, value[1], apart + N);
	p2g_scalar(&g, &p, value[2], NULL, apart + 2 * N);
	p2g_scalar(&g, &p, p.mass, value[3], apart + 3 * N);
	p2g_vector(&g, &p, p.mass, vec, apart + 4 * N);
	snprintf(name, sizeof name, "%s_p2g_batch_is_the_separate_scatters_bit_for_bit", label);
	CHECK(memcmp(fused, apart, 6 * N * sizeof(double)) == 0, name, "the nodal sums differ");

	/* the one-point gather */
	g2p_scalar(&g, &p, node, value[0]);
	idx_t differ = 0;
	for (idx_t q = 0; q < p.n; q++)
		differ += g2p_scalar_point(&g, &p, q, node) != value[0][q];
	snprintf(name, sizeof name, "%s_g2p_scalar_point_is_g2p_scalar_bit_for_bit", label);
	CHECK(differ == 0, name, "%ld points differ", (long)differ);

	/* the FLIP update against the two gathers and the blend written out */
	const double alpha = 0.973, dt = 1.37e-3;
	double *v_ref = malloc(2 * POINTS * sizeof(double)), *x_ref = malloc(2 * POINTS * sizeof(double));
	double *pic = malloc(2 * POINTS * sizeof(double)), *inc = malloc(2 * POINTS * sizeof(double));
	g2p_vector(&g, &p, node, pic);
	g2p_vector(&g, &p, dnode, inc);
	for (idx_t k = 0; k < 2 * p.n; k++) {
		v_ref[k] = alpha * (vec[k] + inc[k]) + (1.0 - alpha) * pic[k];
		x_ref[k] = p.x[k] + dt * pic[k];
	}
	memcpy(p.v, vec, 2 * POINTS * sizeof(double));
	memcpy(inc, p.x, 2 * POINTS * sizeof(double));
	g2p_flip_update(&g, &p, node, dnode, alpha, dt, 0);
	const int kept = memcmp(p.x, inc, 2 * POINTS * sizeof(double)) == 0;
	memcpy(p.v, vec, 2 * POINTS * sizeof(double));
	g2p_flip_update(&g, &p, node, dnode, alpha, dt, 1);
	snprintf(name, sizeof name, "%s_g2p_flip_update_is_the_blend_bit_for_bit", label);
	CHECK(kept && memcmp(p.v, v_ref, 2 * POINTS * sizeof(double)) == 0 &&
	      memcmp(p.x, x_ref, 2 * POINTS * sizeof(double)) == 0, name,
	      "positions kept without move: %d; velocities or moved positions differ", kept);
	memcpy(p.x, inc, 2 * POINTS * sizeof(double));   /* the cache's positions again */

	/* its count of points moved beyond a grid face, with a step long enough to move some out */
	idx_t counted = g2p_flip_update(&g, &p, node, dnode, alpha, 0.071, 1), beyond = 0;
	for (idx_t q = 0; q < p.n; q++) {
		const double xi = (p.x[2 * q] - g.origin[0]) / g.h, eta = (p.x[2 * q + 1] - g.origin[1]) / g.h;
		beyond += xi < 0 || eta < 0 || xi > g.cells[0] || eta > g.cells[1];
	}
	snprintf(name, sizeof name, "%s_g2p_flip_update_counts_points_beyond_the_grid", label);
	CHECK(beyond > 0 && counted == beyond, name, "counted %ld, %ld beyond", (long)counted, (long)beyond);
	memcpy(p.x, inc, 2 * POINTS * sizeof(double));

	/* AFLIP's gather of the affine part alone gives the C of the full APIC gather */
	double *C_full = malloc(4 * POINTS * sizeof(double)), *C_only = malloc(4 * POINTS * sizeof(double));
	g2p_affine_velocity(&g, &p, node, pic, C_full);
	g2p_affine_velocity(&g, &p, node, NULL, C_only);
	snprintf(name, sizeof name, "%s_g2p_affine_part_alone_is_apics_bit_for_bit", label);
	CHECK(memcmp(C_full, C_only, 4 * POINTS * sizeof(double)) == 0, name, "the affine velocities differ");
	free(C_full), free(C_only);

	/* gradient and divergence scattered back, against brute force */
	memset(fused, 0, 6 * N * sizeof(double));
	memset(apart, 0, 6 * N * sizeof(double));
	p2g_point_gradient(&g, &p, value[1], node, fused);
	p2g_point_divergence(&g, &p, value[2], node, fused + 2 * N);
	for (idx_t q = 0; q < p.n; q++) {
		double S[SHAPE_NODES_MAX], Sx[SHAPE_NODES_MAX], Sy[SHAPE_NODES_MAX];
		const idx_t base = brute_shape(&g, kind, p.x + 2 * q, S, Sx, Sy);
		const int n = shape_support(kind);
		double grad[2] = {0, 0}, div = 0;
		for (int a = 0; a < n * n; a++) {
			const idx_t I = base + a % n + (a / n) * g.nodes[0];
			grad[0] += Sx[a] * node[I], grad[1] += Sy[a] * node[I];
			div += Sx[a] * node[2 * I] + Sy[a] * node[2 * I + 1];
		}
		for (int a = 0; a < n * n; a++) {
			const idx_t I = base + a % n + (a / n) * g.nodes[0];
			apart[2 * I] += S[a] * value[1][q] * grad[0];
			apart[2 * I + 1] += S[a] * value[1][q] * grad[1];
			apart[2 * N + I] += S[a] * value[2][q] * div;
		}
	}
	double scale_g, scale_d;
	const double err_g = max_abs_difference(fused, apart, 2 * N, &scale_g);
	const double err_d = max_abs_difference(fused + 2 * N, apart + 2 * N, N, &scale_d);
	snprintf(name, sizeof name, "%s_p2g_point_gradient_matches_brute_force", label);
	CHECK(err_g < TOLERANCE * scale_g, name, "difference %.2e of %.2e", err_g, scale_g);
	snprintf(name, sizeof name, "%s_p2g_point_divergence_matches_brute_force", label);
	CHECK(err_d < TOLERANCE * scale_d, name, "difference %.2e of %.2e", err_d, scale_d);

	for (int k = 0; k < 4; k++)
		free(value[k]);
	free(vec), free(fused), free(apart), free(node), free(dnode);
	free(v_ref), free(x_ref), free(pic), free(inc);
	particles_release(&p);
}

/* A linear point field v = c + a . x_p (x_p as the cache sees it) through p2g_scalar_linear_fit
 * must come back as c + a . x_I at every reached node; the mean sum S m v / sum S m is printed
 * beside it and must be off at the edges (the check sees what the fit corrects). */
static void check_linear_fit(enum case_shape kind, const char *label)
{
	struct case_grid spec = {.origin = {0.417, -0.283}, .extent = {6 * 0.0391, 8 * 0.0391}, .cell_size = 0.0391};
	struct grid g;
	struct particles p;
	char name[96];
	grid_init(&g, &spec, NULL);
	particles_init(&p, POINTS, 0, NULL);
	for (idx_t q = 0; q < p.n; q++) {
		const double edge = 1.3 * spec.cell_size;
		p.x[2 * q] = spec.origin[0] + (q % 3 == 0 ? rnd(0, edge) : rnd(0, spec.extent[0]));
		p.x[2 * q + 1] = spec.origin[1] + (q % 3 == 1 ? spec.extent[1] - rnd(0, edge) : rnd(0, spec.extent[1]));
		p.mass[q] = rnd(0.3, 2.9);
	}
	shape_evaluate(&g, kind, &p, "test", NULL);
	const idx_t N = g.node_count;
	const double c0 = -3.917e3, a[2] = {1.283e4, -9.677e3};   /* Pa, Pa/m: a pressure field */
	double *v = malloc(sizeof(double) * (size_t)p.n), *fit = calloc((size_t)N, sizeof(double));
	double *moments = malloc(9 * sizeof(double) * (size_t)N), *mean = calloc((size_t)N, sizeof(double));
	double *weight = calloc((size_t)N, sizeof(double));
	for (idx_t q = 0; q < p.n; q++) {
		double xp[2], D[4];
		point_frame(&g, &p, q, xp, D);
		v[q] = c0 + a[0] * xp[0] + a[1] * xp[1];
	}
	p2g_scalar_linear_fit(&g, &p, p.mass, v, moments, fit);
	p2g_scalar(&g, &p, p.mass, v, mean);
	p2g_scalar(&g, &p, p.mass, NULL, weight);
	const double scale = fabs(c0) + (fabs(a[0]) + fabs(a[1])) * (spec.extent[0] + spec.extent[1]);
	double worst_fit = 0.0, worst_mean = 0.0;
	for (idx_t I = 0; I < N; I++) {
		if (!(weight[I] > 0.0))
			continue;
		const double x = g.origin[0] + (double)(I % g.nodes[0]) * g.h, y = g.origin[1] + (double)(I / g.nodes[0]) * g.h;
		const double exact = c0 + a[0] * x + a[1] * y;
		worst_fit = fmax(worst_fit, fabs(fit[I] - exact) / scale);
		worst_mean = fmax(worst_mean, fabs(mean[I] / weight[I] - exact) / scale);
	}
	printf("INFO %s linear fit: largest nodal error %.2e of the field's range; the mass-weighted mean %.2e\n", label,
	       worst_fit, worst_mean);
	snprintf(name, sizeof name, "%s_linear_fit_returns_linear_field", label);
	CHECK(worst_fit < 1e-10 && worst_mean > 1e-3, name, "fit %.3e, mean %.3e", worst_fit, worst_mean);
	free(v);
	free(fit);
	free(moments);
	free(mean);
	free(weight);
	particles_release(&p);
}

#define CLOUD_POINTS 20000
#define PARALLEL_TOLERANCE 1e-13   /* of the largest entry of the output */

/* Every scatter of transfer.h into one output array, the outputs laid side by side:
 * scalar [N], vector [2N], internal force [2N], batch [4N + 2N], point gradient [2N], point
 * divergence [N], affine momentum [2N], linear fit [N] (moments: scratch). */
enum { OUT_SCALAR = 0, OUT_VECTOR = 1, OUT_FORCE = 3, OUT_BATCH = 5, OUT_GRADIENT = 11, OUT_DIVERGENCE = 13,
       OUT_AFFINE = 14, OUT_FIT = 16, OUT_WIDTH = 17 };

struct cloud {
	double *value[4], *vec, *stress, *iso, *node;
};

static void scatter_all(const struct grid *g, struct particles *p, const struct cloud *c, double *out,
			double *moments)
{
	const size_t N = (size_t)g->node_count;
	memset(out, 0, OUT_WIDTH * N * sizeof(double));
	p2g_scalar(g, p, p->mass, c->value[0], out + OUT_SCALAR * N);
	p2g_vector(g, p, p->mass, c->vec, out + OUT_VECTOR * N);
	p2g_internal_force(g, p, p->volume, c->stress, c->iso, out + OUT_FORCE * N);
	double *b0 = out + OUT_BATCH * N;
	const struct p2g_batch b = {
		.scalars = 4,
		.scalar = {{NULL, c->value[0], b0}, {p->mass, c->value[1], b0 + N}, {c->value[2], NULL, b0 + 2 * N},
			   {p->mass, c->value[3], b0 + 3 * N}},
		.vector = {p->mass, c->vec, b0 + 4 * N},
	};
	p2g_batch(g, p, &b);
	p2g_point_gradient(g, p, p->volume, c->node, out + OUT_GRADIENT * N);
	p2g_point_divergence(g, p, p->volume, c->node, out + OUT_DIVERGENCE * N);
	p2g_affine_momentum(g, p, p->mass, c->vec, p->C, out + OUT_AFFINE * N);
	p2g_scalar_linear_fit(g, p, p->mass, c->value[1], moments, out + OUT_FIT * N);
}

/* The same sums, point by point in index order, from brute-force shape functions (shape_1d);
 * not the linear fit. */
static void scatter_brute_force(const struct grid *g, enum case_shape kind, const struct particles *p,
				const struct cloud *c, double *out)
{
	const size_t N = (size_t)g->node_count;
	const int n = shape_support(kind);
	memset(out, 0, OUT_WIDTH * N * sizeof(double));
	for (idx_t q = 0; q < p->n; q++) {
		double S[SHAPE_NODES_MAX], Sx[SHAPE_NODES_MAX], Sy[SHAPE_NODES_MAX], xp[2] = {0, 0};
		const idx_t base = brute_shape(g, kind, p->x + 2 * q, S, Sx, Sy);
		const double m = p->mass[q], V = p->volume[q], *v = c->vec + 2 * q, *sg = c->stress + 4 * q;
		const double sxx = V * (sg[0] + c->iso[q]), syy = V * (sg[1] + c->iso[q]), sxy = V * sg[2];
		double grad[2] = {0, 0}, div = 0;
		for (int a = 0; a < n * n; a++) {
			const idx_t I = base + a % n + (a / n) * g->nodes[0];
			xp[0] += S[a] * (g->origin[0] + (double)(I % g->nodes[0]) * g->h);
			xp[1] += S[a] * (g->origin[1] + (double)(I / g->nodes[0]) * g->h);
			grad[0] += Sx[a] * c->node[I], grad[1] += Sy[a] * c->node[I];
			div += Sx[a] * c->node[2 * I] + Sy[a] * c->node[2 * I + 1];
		}
		for (int a = 0; a < n * n; a++) {
			const idx_t I = base + a % n + (a / n) * g->nodes[0];
			const double dx = g->origin[0] + (double)(I % g->nodes[0]) * g->h - xp[0];
			const double dy = g->origin[1] + (double)(I / g->nodes[0]) * g->h - xp[1];
			const double *C = p->C + 4 * q;
			out[OUT_SCALAR * N + I] += S[a] * m * c->value[0][q];
			out[OUT_VECTOR * N + 2 * I] += S[a] * m * v[0];
			out[OUT_VECTOR * N + 2 * I + 1] += S[a] * m * v[1];
			out[OUT_FORCE * N + 2 * I] -= sxx * Sx[a] + sxy * Sy[a];
			out[OUT_FORCE * N + 2 * I + 1] -= sxy * Sx[a] + syy * Sy[a];
			out[OUT_BATCH * N + I] += S[a] * c->value[0][q];
			out[(OUT_BATCH + 1) * N + I] += S[a] * m * c->value[1][q];
			out[(OUT_BATCH + 2) * N + I] += S[a] * c->value[2][q];
			out[(OUT_BATCH + 3) * N + I] += S[a] * m * c->value[3][q];
			out[(OUT_BATCH + 4) * N + 2 * I] += S[a] * m * v[0];
			out[(OUT_BATCH + 4) * N + 2 * I + 1] += S[a] * m * v[1];
			out[OUT_GRADIENT * N + 2 * I] += S[a] * V * grad[0];
			out[OUT_GRADIENT * N + 2 * I + 1] += S[a] * V * grad[1];
			out[OUT_DIVERGENCE * N + I] += S[a] * V * div;
			out[OUT_AFFINE * N + 2 * I] += S[a] * m * (v[0] + C[0] * dx + C[1] * dy);
			out[OUT_AFFINE * N + 2 * I + 1] += S[a] * m * (v[1] + C[2] * dx + C[3] * dy);
		}
	}
}

/* A random cloud on a grid of 3 x 5 blocks (point_blocks.h), a third of it within 1.3 cells of
 * an edge and every 97th point on an edge or a corner, through every scatter with blocks: on one
 * thread and on two the same bits, and each output within PARALLEL_TOLERANCE of its largest
 * entry of the brute-force sums (the linear fit: of the same kernel without blocks, which runs
 * serially in index order). */
static void check_parallel_scatters(enum case_shape kind, const char *label)
{
	const double h = 0.0473;
	struct case_grid spec = {.origin = {-1.917, 0.661}, .extent = {150 * h, 29 * h}, .cell_size = h};
	struct grid g;
	struct particles p;
	struct cloud c;
	char name[96];
	grid_init(&g, &spec, NULL);
	particles_init(&p, CLOUD_POINTS, 0, NULL);
	particles_add_affine(&p, NULL);
	particles_add_blocks(&p, &g, NULL);
	for (int k = 0; k < 4; k++)
		c.value[k] = malloc(CLOUD_POINTS * sizeof(double));
	c.vec = malloc(2 * CLOUD_POINTS * sizeof(double));
	c.stress = malloc(4 * CLOUD_POINTS * sizeof(double));
	c.iso = malloc(CLOUD_POINTS * sizeof(double));
	for (idx_t q = 0; q < p.n; q++) {
		const double edge = 1.3 * h, X = spec.extent[0], Y = spec.extent[1];
		double x = rnd(0, X), y = rnd(0, Y);
		if (q % 3 == 0)   /* next to one of the four edges */
			switch (q % 4) {
			case 0: x = rnd(0, edge); break;
			case 1: x = X - rnd(0, edge); break;
			case 2: y = rnd(0, edge); break;
			default: y = Y - rnd(0, edge); break;
			}
		if (q % 97 == 0)   /* on an edge, or in a corner */
			x = q % 2 ? 0.0 : X, y = q % 3 ? y : q % 5 ? 0.0 : Y;
		p.x[2 * q] = spec.origin[0] + x, p.x[2 * q + 1] = spec.origin[1] + y;
		p.mass[q] = rnd(0.3, 2.9), p.volume[q] = rnd(0.5e-3, 1.1e-3);
		for (int k = 0; k < 4; k++)
			c.value[k][q] = rnd(-3.7, 5.3);
		for (int k = 0; k < 2; k++)
			c.vec[2 * q + k] = rnd(-1.9, 1.9);
		for (int k = 0; k < 4; k++)
			c.stress[4 * q + k] = rnd(-2.3e4, 1.1e4), p.C[4 * q + k] = rnd(-20, 20);
		c.iso[q] = rnd(-5.1e3, 3.3e3);
	}
	const int sorted = shape_evaluate(&g, kind, &p, "test", NULL) == PORO_OK && point_blocks_of(&p) != NULL;
	const size_t N = (size_t)g.node_count;
	c.node = malloc(2 * N * sizeof(double));
	for (size_t I = 0; I < 2 * N; I++)
		c.node[I] = rnd(-2.3, 2.3);
	double *one = malloc(OUT_WIDTH * N * sizeof(double)), *two = malloc(OUT_WIDTH * N * sizeof(double));
	double *ref = malloc(OUT_WIDTH * N * sizeof(double)), *moments = malloc(9 * N * sizeof(double));
	const int threads = omp_get_max_threads();
	omp_set_num_threads(1);
	scatter_all(&g, &p, &c, one, moments);
	omp_set_num_threads(2);
	scatter_all(&g, &p, &c, two, moments);
	omp_set_num_threads(threads);
	idx_t differ = 0;
	for (size_t k = 0; k < OUT_WIDTH * N; k++)
		differ += memcmp(one + k, two + k, sizeof(double)) != 0;
	snprintf(name, sizeof name, "%s_parallel_scatters_same_bits_on_one_and_two_threads", label);
	CHECK(sorted && differ == 0, name, "sorted %d; %ld of %ld nodal values differ", sorted, (long)differ,
	      (long)(OUT_WIDTH * N));

	scatter_brute_force(&g, kind, &p, &c, ref);
	struct point_blocks *blocks = p.blocks;   /* without blocks the kernels run serially in index order */
	p.blocks = NULL;
	p2g_scalar_linear_fit(&g, &p, p.mass, c.value[1], moments, ref + OUT_FIT * N);
	p.blocks = blocks;
	static const struct { int first, width; const char *what; } outputs[] = {
		{OUT_SCALAR, 1, "scalar"}, {OUT_VECTOR, 2, "vector"}, {OUT_FORCE, 2, "internal_force"},
		{OUT_BATCH, 6, "batch"}, {OUT_GRADIENT, 2, "point_gradient"}, {OUT_DIVERGENCE, 1, "point_divergence"},
		{OUT_AFFINE, 2, "affine_momentum"}, {OUT_FIT, 1, "linear_fit"}};
	for (size_t k = 0; k < sizeof outputs / sizeof outputs[0]; k++) {
		double scale;
		const size_t at = (size_t)outputs[k].first * N, count = (size_t)outputs[k].width * N;
		const double err = max_abs_difference(two + at, ref + at, count, &scale);
		snprintf(name, sizeof name, "%s_parallel_%s_matches_serial_brute_force", label, outputs[k].what);
		CHECK(sorted && scale > 0.0 && err <= PARALLEL_TOLERANCE * scale, name, "difference %.2e of %.2e",
		      err, scale);
	}
	for (int k = 0; k < 4; k++)
		free(c.value[k]);
	free(c.vec), free(c.stress), free(c.iso), free(c.node);
	free(one), free(two), free(ref), free(moments);
	particles_release(&p);
}

int main(void)
{
	check_linear_fit(SHAPE_LINEAR, "linear");
	check_linear_fit(SHAPE_QUADRATIC_BSPLINE, "quadratic_bspline");
	check_linear_fit(SHAPE_CUBIC_BSPLINE, "cubic_bspline");
	check_kind(SHAPE_LINEAR, "linear");
	check_kind(SHAPE_QUADRATIC_BSPLINE, "quadratic_bspline");
	check_kind(SHAPE_CUBIC_BSPLINE, "cubic_bspline");
	check_fused(SHAPE_LINEAR, "linear");
	check_fused(SHAPE_QUADRATIC_BSPLINE, "quadratic_bspline");
	check_fused(SHAPE_CUBIC_BSPLINE, "cubic_bspline");
	check_parallel_scatters(SHAPE_LINEAR, "linear");
	check_parallel_scatters(SHAPE_QUADRATIC_BSPLINE, "quadratic_bspline");
	check_parallel_scatters(SHAPE_CUBIC_BSPLINE, "cubic_bspline");
	HARNESS_EXIT();
}
