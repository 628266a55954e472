/*
 * recovery.c - the pore-pressure increments of the points from the converged nodal ones (001 §2.2,
 * the paragraph after Eq. 11; spec-001 §6.2): the MLSA patch recovery after Zienkiewicz and Zhu,
 * which replaces Eq. 11e's direct interpolation because equal-order u-p elements leave a nodal
 * checkerboard in Delta p that the points would otherwise inherit.
 *
 *   1. cell centres: Delta p_c = 1/4 of the cell's four nodal increments, in every cell that holds
 *      a point: the bilinear value at the centre, where the checkerboard mode vanishes exactly;
 *   2. a patch per node: the active cells among the four around it, their centres at
 *      (xi, eta) = (+-1/2, +-1/2) cells from the node, and the least-squares plane
 *      a0 + a1 xi + a2 eta through their values (equal weights: the centres are equidistant);
 *      with two cells side by side (a node on a wall) the slope along them is theirs and the plane
 *      flat across them, with one cell (a corner) flat; then a node whose patch lacks cells (on a
 *      wall, the free surface, a corner) takes the plane of a neighbour with a full patch, as
 *      Zienkiewicz and Zhu treat boundaries. spec-001 §6.2 reads "two cells or fewer: the mean",
 *      which loses the slope at a wall: every point next to the walls of a hydrostatic column
 *      then stood rho_w g h / 4 off its pressure, and those under the surface 0.56% of rho_w g H;
 *   3. a point takes the plane of the node nearest it, at its own (xi, eta) ("mlsa_patch", 001's
 *      literal "the increments at MPs are determined by the linear patch"), or the uGIMP
 *      interpolation of the nodes' a0 ("mlsa_nodal": continuous, where the first jumps by
 *      O(h grad p) between the nodes' squares), or Eq. 11e as printed ("none").
 */
#include <math.h>
#include <string.h>

#include "implicit.h"
#include "transfer.h"

/* Step 2 at node (i, j): the plane's coefficients from the active cells around it. */
static int node_patch(const struct grid *g, const double *cell, const double *fill, idx_t i, idx_t j, double a[3])
{
	double A[3][3] = {{0}}, b[3] = {0};
	int count = 0;
	for (int dj = -1; dj <= 0; dj++)
		for (int di = -1; di <= 0; di++) {
			const idx_t ci = i + di, cj = j + dj;
			if (ci < 0 || ci >= g->cells[0] || cj < 0 || cj >= g->cells[1] || !(fill[ci + cj * g->cells[0]] > 0.0))
				continue;
			const double r[3] = {1.0, di + 0.5, dj + 0.5}, v = cell[ci + cj * g->cells[0]];
			for (int m = 0; m < 3; m++) {
				b[m] += r[m] * v;
				for (int k = 0; k < 3; k++)
					A[m][k] += r[m] * r[k];
			}
			count++;
		}
	a[0] = count > 0 ? b[0] / count : 0.0, a[1] = a[2] = 0.0;
	if (count == 2) {
		/* two cells in a row or a column (a node on a wall): the slope along them is fixed by
		 * them, the one across is not; A's diagonal is 1/2 along them (their (+-1/2)^2 sum),
		 * its off-diagonal zero */
		for (int m = 1; m <= 2; m++)
			if (fabs(A[0][m]) < 1e-12 && A[m][m] > 0.0 && fabs(A[1][2]) < 1e-12)
				a[m] = b[m] / A[m][m];
		return count;
	}
	if (count < 3)
		return count;
	/* three or four centres of a square's corners: A is regular; Cramer's rule */
	const double det = A[0][0] * (A[1][1] * A[2][2] - A[1][2] * A[2][1]) -
			   A[0][1] * (A[1][0] * A[2][2] - A[1][2] * A[2][0]) + A[0][2] * (A[1][0] * A[2][1] - A[1][1] * A[2][0]);
	for (int m = 0; m < 3; m++) {
		double M[3][3];
		memcpy(M, A, sizeof M);
		for (int k = 0; k < 3; k++)
			M[k][m] = b[k];
		a[m] = (M[0][0] * (M[1][1] * M[2][2] - M[1][2] * M[2][1]) - M[0][1] * (M[1][0] * M[2][2] - M[1][2] * M[2][0]) +
			M[0][2] * (M[1][0] * M[2][1] - M[1][1] * M[2][0])) / det;
	}
	return count;
}

/* Zienkiewicz and Zhu's boundary treatment: a node whose patch lacks cells (on a wall, the free
 * surface, a corner) takes the plane of the nearest node with a full patch among its eight
 * neighbours, evaluated at itself; with none, its own fit stands. */
static void borrow_patch(const struct grid *g, const double *patch, const unsigned char *full, idx_t i, idx_t j,
			 double a[3])
{
	static const int order[8][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}, {1, 1}, {-1, 1}, {1, -1}, {-1, -1}};
	for (int k = 0; k < 8; k++) {
		const idx_t ni = i + order[k][0], nj = j + order[k][1];
		if (ni < 0 || ni >= g->nodes[0] || nj < 0 || nj >= g->nodes[1] || !full[ni + nj * g->nodes[0]])
			continue;
		const double *b = patch + 3 * (size_t)(ni + nj * g->nodes[0]);
		a[0] = b[0] - b[1] * order[k][0] - b[2] * order[k][1];
		a[1] = b[1], a[2] = b[2];
		return;
	}
}

void implicit_pressure_recovery(struct sim *s, double *out)
{
	struct implicit_state *e = implicit_of(s);
	const struct grid *g = &s->grid;
	const struct particles *p = &s->soil;
	const enum pressure_recovery how = s->spec->formulation.pressure_recovery;
	const idx_t nx = g->nodes[0];
	if (how == PRESSURE_RECOVERY_NONE) {
#pragma omp parallel for schedule(static)
		for (idx_t q = 0; q < s->water.n; q++) {
			double dp = 0.0;
			FOR_SUPPORT(g, p, q, { dp += wk * e->increment[DOFS_PER_NODE * (size_t)I + DOF_P]; });
			out[q] = dp;
		}
		return;
	}
	for (idx_t c = 0; c < g->cell_count; c++) {                         /* (1) */
		const idx_t i = c % g->cells[0], j = c / g->cells[0], I = i + j * nx;
		const idx_t corner[4] = {I, I + 1, I + nx, I + nx + 1};
		double sum = 0.0;
		for (int k = 0; k < 4; k++)
			sum += e->increment[DOFS_PER_NODE * (size_t)corner[k] + DOF_P];
		e->cell_pressure[c] = 0.25 * sum;
	}
#pragma omp parallel for schedule(static)
	for (idx_t I = 0; I < g->node_count; I++)                            /* (2) */
		e->patch_full[I] = node_patch(g, e->cell_pressure, e->fill, I % nx, I / nx, e->patch + 3 * (size_t)I) == 4;
#pragma omp parallel for schedule(static)
	for (idx_t I = 0; I < g->node_count; I++) {
		double *a = e->patch_edge + 3 * (size_t)I;
		memcpy(a, e->patch + 3 * (size_t)I, 3 * sizeof(double));
		if (!e->patch_full[I])
			borrow_patch(g, e->patch, e->patch_full, I % nx, I / nx, a);
	}
#pragma omp parallel for schedule(static)
	for (idx_t q = 0; q < s->water.n; q++) {                             /* (3) */
		if (how == PRESSURE_RECOVERY_MLSA_NODAL) {
			double dp = 0.0;
			FOR_SUPPORT(g, p, q, { dp += wk * e->patch_edge[3 * (size_t)I]; });
			out[q] = dp;
			continue;
		}
		const double xi = (p->x[2 * q] - g->origin[0]) * g->inv_h, eta = (p->x[2 * q + 1] - g->origin[1]) * g->inv_h;
		const idx_t i = (idx_t)lround(xi), j = (idx_t)lround(eta);
		const double *a = e->patch_edge + 3 * (size_t)(i + j * nx);
		out[q] = a[0] + a[1] * (xi - (double)i) + a[2] * (eta - (double)j);
	}
}
