/*
 * oscillation_test.c - the oscillation index of solver/output/oscillation.c on fields whose answer is
 * known: a point-level checkerboard, a checkerboard of whole cells (constant inside each cell, as
 * cell-wise averaging leaves p'), and a smooth field, on a 6 x 5 cell grid seeded 2x2 per cell
 * with high-entropy values.
 *
 * Oracles: a checkerboard of amplitude A on a mean P scores within [2A/(P+A), 2A/(P-A)]
 * (oscillation.h); a field monotone along every line scores 0; the point-level index cannot see
 * a checkerboard of cells (each point equals its same-cell neighbour), the cell-level one must.
 */
#include "../harness.h"
#include "oscillation.h"

#define CELLS_X 6
#define CELLS_Y 5
#define PPC 2
#define H 0.37                              /* m */
#define N (CELLS_X * CELLS_Y * PPC * PPC)
#define P_MEAN (-2.385e4)                   /* Pa: compression */
#define P_AMP 3.17e3                        /* Pa */

static double x0[2 * N], stress[4 * N];

/* Seeds the lattice and sets p' = (s_xx + s_yy + s_zz) / 3 = field(site u, v) at each point. */
static struct particles seed(double (*field)(int u, int v))
{
	int q = 0;
	for (int v = 0; v < CELLS_Y * PPC; v++)
		for (int u = 0; u < CELLS_X * PPC; u++, q++) {
			x0[2 * q] = (u + 0.5) * H / PPC;
			x0[2 * q + 1] = (v + 0.5) * H / PPC;
			double p = field(u, v);
			/* unequal components with the wanted mean: p' is what the index reads */
			stress[4 * q] = p + 1.3e3, stress[4 * q + 1] = p - 2.9e3, stress[4 * q + 2] = 4.1e2;
			stress[4 * q + 3] = p + 1.6e3;
		}
	return (struct particles){.n = N, .x0 = x0, .stress = stress};
}

static double point_checkerboard(int u, int v)
{
	return P_MEAN + ((u + v) % 2 ? P_AMP : -P_AMP);
}

static double cell_checkerboard(int u, int v)
{
	return P_MEAN + ((u / PPC + v / PPC) % 2 ? P_AMP : -P_AMP);
}

static double smooth(int u, int v)
{
	return P_MEAN + 173.0 * u - 61.0 * v + 2.3 * u * u;
}

static int within_checkerboard_bounds(double index)
{
	return index >= 2 * P_AMP / (-P_MEAN + P_AMP) && index <= 2 * P_AMP / (-P_MEAN - P_AMP);
}

int main(void)
{
	const struct case_grid g = {.origin = {0.0, 0.0}, .extent = {CELLS_X * H, CELLS_Y * H}, .cell_size = H};
	struct poro_error err = {0};
	double point, cell, one;

	struct particles p = seed(point_checkerboard);
	enum poro_status st = oscillation_index(&g, &p, H / PPC, &point, &err);
	st = st ? st : oscillation_index_blocks(&g, &p, H / PPC, 1, &one, &err);
	CHECK(!st && within_checkerboard_bounds(point), "point_checkerboard_scores_about_2A_over_P",
	      "status %d, index %.6f, want [%.6f, %.6f]", st, point, 2 * P_AMP / (-P_MEAN + P_AMP),
	      2 * P_AMP / (-P_MEAN - P_AMP));
	CHECK(!st && one == point, "blocks_of_one_site_are_the_point_index", "%.17g vs %.17g", one, point);

	p = seed(cell_checkerboard);
	st = oscillation_index(&g, &p, H / PPC, &point, &err);
	st = st ? st : oscillation_index_blocks(&g, &p, H / PPC, PPC, &cell, &err);
	CHECK(!st && point == 0.0, "point_index_blind_to_a_checkerboard_of_cells", "status %d, index %.6g", st, point);
	CHECK(!st && within_checkerboard_bounds(cell), "cell_index_sees_a_checkerboard_of_cells",
	      "status %d, index %.6f", st, cell);

	p = seed(smooth);
	st = oscillation_index_blocks(&g, &p, H / PPC, PPC, &cell, &err);
	CHECK(!st && cell == 0.0, "cell_index_of_a_monotone_field_is_zero", "status %d, index %.6g", st, cell);

	st = oscillation_index_blocks(&g, &p, H / PPC, 0, &cell, &err);
	CHECK(st == PORO_EINVAL && strstr(err.message, "block"), "block_of_zero_sites_refused", "status %d: %s", st,
	      err.message);
	HARNESS_EXIT();
}
