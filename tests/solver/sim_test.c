/*
 * sim_test.c - seeding of material points (solver/sim.c): points at the centres of equal
 * sub-cells, kept when strictly inside the body.
 *
 * Oracles: 000 Table 4's point counts for the slope of §5.3 at h = 1 m (tests/cases/
 * mc_slope_k1e-3_double_point.json; soil and water points, 6x6 to 32x32 per cell), §5.3's 38,320
 * at h = 0.5 m and 4x4, §5.4's 21,540 for the landslide at h = 0.025 m and 3x3; and a square whose
 * edges run through rows and columns of sub-cell centres, where the count of strictly interior
 * points is known exactly.
 */
#include <stdlib.h>

#include "../harness.h"
#include "case.h"
#include "particles.h"
#include "poro.h"

#define SLOPE "tests/cases/mc_slope_k1e-3_double_point.json"
#define LANDSLIDE "tests/cases/landslide_dense_double_point.json"

/* Soil + water points of `file` at cell size h, ppc^2 per cell; -1 when it cannot be made. The
 * square variant replaces the body by the polygon [lo, hi]^2. */
static long points(const char *file, double h, int ppc, const double *square)
{
	struct case_spec *c = NULL;
	struct sim *s = NULL;
	struct poro_error err = {0};
	long n = -1;
	if (!case_load_file(file, &c, &err)) {
		c->grid.cell_size = h;
		c->bodies[0].particles_per_cell = ppc;
		if (square) {
			const double v[4][2] = { { square[0], square[0] }, { square[1], square[0] },
						 { square[1], square[1] }, { square[0], square[1] } };
			c->bodies[0].polygon_count = 4;
			for (int k = 0; k < 4; k++)
				c->bodies[0].polygon[k][0] = v[k][0], c->bodies[0].polygon[k][1] = v[k][1];
			c->bodies[0].min[0] = c->bodies[0].min[1] = square[0];
			c->bodies[0].max[0] = c->bodies[0].max[1] = square[1];
		}
		if (!sim_create(&s, c, &err))
			n = (long)(sim_soil(s)->n + sim_water(s)->n);
	}
	if (n < 0)
		printf("INFO %s: %s\n", file, err.message);
	sim_destroy(&s);
	case_destroy(&c);
	return n;
}

int main(void)
{
	static const struct { int ppc; long points; } table4[] = {
		{ 6, 21540 }, { 8, 38320 }, { 10, 59900 }, { 12, 86280 }, { 18, 194220 }, { 24, 345360 }, { 32, 614080 },
	};
	char name[96];
	for (size_t k = 0; k < sizeof table4 / sizeof table4[0]; k++) {
		long n = points(SLOPE, 1.0, table4[k].ppc, NULL);
		snprintf(name, sizeof name, "slope_seeding_matches_table4_%dx%d", table4[k].ppc, table4[k].ppc);
		CHECK(n == table4[k].points, name, "%ld points, Table 4 %ld", n, table4[k].points);
	}
	long n = points(SLOPE, 0.5, 4, NULL);
	CHECK(n == 38320, "slope_seeding_matches_section_5_3", "%ld points, 000 §5.3: 38,320", n);
	n = points(LANDSLIDE, 0.025, 3, NULL);
	CHECK(n == 21540, "landslide_seeding_matches_section_5_4", "%ld points, 000 §5.4: 21,540", n);
	/* h = 1, 4x4: centres at 0.125 + 0.25 i. The square [2.125, 6.625]^2 has centres on all four
	 * edges (2.125 and 6.625 are centres); strictly inside lie 2.375 .. 6.375: 17 per row, 17^2
	 * soil points, doubled for water. */
	const double square[2] = { 2.125, 6.625 };
	n = points(SLOPE, 1.0, 4, square);
	CHECK(n == 2 * 17 * 17, "points_on_polygon_edges_are_not_seeded", "%ld points, want %d", n, 2 * 17 * 17);
	HARNESS_EXIT();
}
