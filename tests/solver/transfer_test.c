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
 */
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

int main(void)
{
	check_kind(SHAPE_LINEAR, "linear");
	check_kind(SHAPE_QUADRATIC_BSPLINE, "quadratic_bspline");
	check_kind(SHAPE_CUBIC_BSPLINE, "cubic_bspline");
	HARNESS_EXIT();
}
