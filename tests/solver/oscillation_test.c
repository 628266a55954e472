/*
 * oscillation_test.c - the oscillation index of solver/output/oscillation.c on fields whose answer is
 * known: a point-level checkerboard, a checkerboard of whole cells (constant inside each cell, as
 * cell-wise averaging leaves p'), and a smooth field, on a 6 x 5 cell grid seeded 2x2 per cell
 * with high-entropy values; and the two-cell pattern index on the water pressure of the
 * Mohr-Coulomb slope of 000 §5.3 (k = 1e-3 m/s) as the report that asked for it read it along
 * y = 2 m at t = 3 s: 142, 212, 209, 137, 140, 210, 206, 135 kPa from one point column to the
 * next, a pair of high point columns either side of one node, a pair of low ones either side of
 * the next (docs/numerics.md, "A pressure pattern of period two cells").
 *
 * Oracles: a checkerboard of amplitude A on a mean P scores within [2A/(P+A), 2A/(P-A)]
 * (oscillation.h); a field monotone along every line scores 0; the point-level index cannot see
 * a checkerboard of cells (each point equals its same-cell neighbour), the cell-level one must.
 * The slope's pattern: the blocks centred on the nodes hold the pairs, whose means (210.5, 138.5,
 * 208, 138.5 kPa ...) each stick out of their neighbours' range along x by E = 69.5 to 72 kPa and
 * not at all along y (the pattern is the same in every row, on a hydrostatic trend); with as many
 * block triples along x as along y (fewer along x at the other placements) the index is at most
 * RMS(E) / sqrt(2) over the RMS of the block means, which lie within the field's range, and the
 * node-centred placement reaches it. The point and cell indices stay
 * near the few kPa by which single points of the sequence stick out (212 over 209).
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

/* The slope's row, kPa, repeated along x (period 8 sites = 4 cells, two periods of the pattern),
 * on a hydrostatic trend along y. */
#define SLOPE_CELLS 7                      /* node-centred full blocks: 6 x 6, as many triples along x as y */
#define SLOPE_N (SLOPE_CELLS * SLOPE_CELLS * PPC * PPC)
#define SLOPE_EXCESS_MIN 69.5e3            /* Pa: how far each node-centred block sticks out of its */
#define SLOPE_EXCESS_MAX 72.0e3            /* neighbours' range along x (208 - 138.5, 210.5 - 138.5 kPa) */
static const double slope_row[8] = {142e3, 212e3, 209e3, 137e3, 140e3, 210e3, 206e3, 135e3};

static double slope_pattern(int u, int v)
{
	return slope_row[u % 8] + 9.81e3 * H / PPC * (2 * SLOPE_CELLS - v);   /* deeper rows: higher */
}

/* The same row's pressure averaged over each cell: constant in the cells, monotone along y. */
static double slope_cells(int u, int v)
{
	return 0.5 * (slope_pattern(u - u % PPC, v) + slope_pattern(u - u % PPC + 1, v));
}

static double slope_x0[2 * SLOPE_N], slope_p[SLOPE_N];

/* Seeds the slope's lattice with pressure field(u, v) (a value per point, stress left NULL). */
static struct particles seed_pressure(double (*field)(int u, int v))
{
	int q = 0;
	for (int v = 0; v < SLOPE_CELLS * PPC; v++)
		for (int u = 0; u < SLOPE_CELLS * PPC; u++, q++) {
			slope_x0[2 * q] = (u + 0.5) * H / PPC;
			slope_x0[2 * q + 1] = (v + 0.5) * H / PPC;
			slope_p[q] = field(u, v);
		}
	return (struct particles){.n = SLOPE_N, .x0 = slope_x0};
}

/* Two-cell pattern index of the slope's row, and its point and cell indices. */
static void check_slope_pattern(void)
{
	const struct case_grid g = {.origin = {0.0, 0.0}, .extent = {SLOPE_CELLS * H, SLOPE_CELLS * H}, .cell_size = H};
	struct poro_error err = {0};
	double pattern, point, cell, lo = INFINITY, hi = -INFINITY;
	struct particles p = seed_pressure(slope_pattern);
	for (int q = 0; q < SLOPE_N; q++)   /* every block mean lies within the field's range */
		lo = fmin(lo, slope_p[q]), hi = fmax(hi, slope_p[q]);
	enum poro_status st = oscillation_index_pattern(&g, &p, H / PPC, PPC, slope_p, &pattern, &err);
	st = st ? st : oscillation_index_of(&g, &p, H / PPC, 1, slope_p, &point, &err);
	st = st ? st : oscillation_index_of(&g, &p, H / PPC, PPC, slope_p, &cell, &err);
	const double want_lo = SLOPE_EXCESS_MIN / sqrt(2.0) / hi, want_hi = SLOPE_EXCESS_MAX / sqrt(2.0) / lo;
	CHECK(!st && pattern >= want_lo && pattern <= want_hi, "slope_pattern_of_two_cells_flagged",
	      "status %d, index %.4f, want [%.4f, %.4f]", st, pattern, want_lo, want_hi);
	/* what the report found: the indices at the points and at the cells miss it */
	CHECK(!st && point < 0.1 * pattern && cell < 0.1 * pattern, "slope_pattern_missed_by_point_and_cell_indices",
	      "point %.4f, cell %.4f against pattern %.4f", point, cell, pattern);

	p = seed_pressure(slope_cells);
	st = oscillation_index_pattern(&g, &p, H / PPC, PPC, slope_p, &pattern, &err);
	st = st ? st : oscillation_index_of(&g, &p, H / PPC, PPC, slope_p, &cell, &err);
	/* the cell means of the slope's row still alternate (177, 173, 175, 170.5 kPa ...) by a few
	 * kPa: the cell index sees that, and the pattern index, which includes the cells' own
	 * placement, no less */
	CHECK(!st && pattern >= cell && pattern < 0.1 * SLOPE_EXCESS_MIN / hi, "slope_cell_means_not_flagged",
	      "status %d, pattern %.4f, cell %.4f", st, pattern, cell);
}

/* The smooth field averaged over each cell (as patch averaging leaves a field: Eq. 83). */
static double smooth_cells(int u, int v)
{
	const int u0 = u - u % PPC, v0 = v - v % PPC;
	return 0.25 * (smooth(u0, v0) + smooth(u0 + 1, v0) + smooth(u0, v0 + 1) + smooth(u0 + 1, v0 + 1));
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

	/* the two-cell pattern index: 0 for a smooth field and for its cell-wise constant version
	 * (patch averaging), at every placement of the blocks; a checkerboard of cells as the cell
	 * index scores it (every block of it is full) */
	double pattern;
	st = oscillation_index_pattern(&g, &p, H / PPC, PPC, NULL, &pattern, &err);
	CHECK(!st && pattern == 0.0, "pattern_index_of_a_smooth_field_is_zero", "status %d, index %.6g", st, pattern);
	p = seed(smooth_cells);
	st = oscillation_index_pattern(&g, &p, H / PPC, PPC, NULL, &pattern, &err);
	CHECK(!st && pattern == 0.0, "pattern_index_of_a_cell_wise_constant_field_is_zero", "status %d, index %.6g", st,
	      pattern);
	p = seed(cell_checkerboard);
	st = oscillation_index_pattern(&g, &p, H / PPC, PPC, NULL, &pattern, &err);
	st = st ? st : oscillation_index_blocks(&g, &p, H / PPC, PPC, &cell, &err);
	CHECK(!st && pattern >= cell && within_checkerboard_bounds(pattern), "pattern_index_sees_a_checkerboard_of_cells",
	      "status %d, pattern %.6f, cell %.6f", st, pattern, cell);
	check_slope_pattern();

	st = oscillation_index_blocks(&g, &p, H / PPC, 0, &cell, &err);
	CHECK(st == PORO_EINVAL && strstr(err.message, "block"), "block_of_zero_sites_refused", "status %d: %s", st,
	      err.message);
	const struct case_grid tiny = {.origin = {0.0, 0.0}, .extent = {2 * H, 2 * H}, .cell_size = H};
	st = oscillation_index_pattern(&tiny, &p, H / PPC, PPC, NULL, &pattern, &err);
	CHECK(st == PORO_EINVAL && strstr(err.message, "neighbours"), "pattern_index_needs_a_full_cell_between_two",
	      "status %d: %s", st, err.message);
	HARNESS_EXIT();
}
