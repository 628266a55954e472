/*
 * sim_test.c - seeding of material points (solver/sim.c): points at the centres of equal
 * sub-cells, kept when strictly inside the body.
 *
 * Oracles: 000 Table 4's point counts for the slope of §5.3 at h = 1 m (tests/cases/
 * mc_slope_k1e-3_double_point.json; soil and water points, 6x6 to 32x32 per cell), §5.3's 38,320
 * at h = 0.5 m and 4x4, §5.4's 21,540 for the landslide at h = 0.025 m and 3x3; and a square whose
 * edges run through rows and columns of sub-cell centres, where the count of strictly interior
 * points is known exactly. Rectangles fill their extent: with sides off the lattice of sub-cells,
 * the points' volumes and first moments are the rectangle's area and centroid times its area,
 * every point's volume is that of a row 1/2 to 3/2 sub-cells thick, and the count per direction
 * is that of a one-dimensional reference (sub-cells covered at least half); on the lattice the
 * points are the sub-cell centres.
 */
#include <stdlib.h>
#include <string.h>

#include "../harness.h"
#include "case.h"
#include "particles.h"
#include "poro.h"

#define SLOPE "tests/cases/mc_slope_k1e-3_double_point.json"
#define LANDSLIDE "tests/cases/landslide_dense_double_point.json"
#define COLUMN "tests/cases/terzaghi.json"

/* Reference count of points along one direction: sub-cells [origin + i d, origin + (i+1) d]
 * that [lo, hi] covers at least half (a thinner cut part joins its neighbour's point). */
static long covered_count(double origin, double d, long cells, double lo, double hi)
{
	long n = 0;
	for (long i = 0; i < cells; i++) {
		double a = origin + i * d, covered = fmin(a + d, hi) - fmax(a, lo);
		n += covered >= 0.5 * d - 1e-12;
	}
	return n;
}

/* The Terzaghi column's body replaced by the rectangle [lo, hi]: checks its seeding. */
static void check_rectangle(const char *label, const double lo[2], const double hi[2])
{
	struct case_spec *c = NULL;
	struct sim *s = NULL;
	struct poro_error err = { 0 };
	char name[128];
	int ok = !case_load_file(COLUMN, &c, &err);
	if (ok) {
		for (int k = 0; k < 2; k++)
			c->bodies[0].min[k] = lo[k], c->bodies[0].max[k] = hi[k];
		ok = !sim_create(&s, c, &err);
	}
	if (!ok)
		printf("INFO %s: %s\n", label, err.message);
	const struct particles *p = ok ? sim_soil(s) : NULL;
	const double d = ok ? c->grid.cell_size / c->bodies[0].particles_per_cell : 0;
	double V = 0, Vx = 0, Vy = 0, vmin = INFINITY, vmax = 0;
	for (idx_t q = 0; p && q < p->n; q++) {
		V += p->volume0[q], Vx += p->volume0[q] * p->x0[2 * q], Vy += p->volume0[q] * p->x0[2 * q + 1];
		vmin = fmin(vmin, p->volume0[q] / (d * d)), vmax = fmax(vmax, p->volume0[q] / (d * d));
	}
	const double area = (hi[0] - lo[0]) * (hi[1] - lo[1]);
	long want = -1;
	if (ok) {
		long nx = covered_count(c->grid.origin[0], d, lround(c->grid.extent[0] / d), lo[0], hi[0]);
		want = nx * covered_count(c->grid.origin[1], d, lround(c->grid.extent[1] / d), lo[1], hi[1]);
	}
	snprintf(name, sizeof name, "%s_volumes_fill_it", label);
	CHECK(ok && fabs(V / area - 1) <= 1e-12, name, "volumes / area - 1 = %.3e", V / area - 1);
	snprintf(name, sizeof name, "%s_points_at_its_centroid", label);
	CHECK(ok && fabs(Vx / V - 0.5 * (lo[0] + hi[0])) <= 1e-12 && fabs(Vy / V - 0.5 * (lo[1] + hi[1])) <= 1e-12,
	      name, "centroid (%.15f, %.15f)", Vx / V, Vy / V);
	snprintf(name, sizeof name, "%s_rows_half_to_three_halves_thick", label);
	CHECK(ok && vmin >= 0.25 - 1e-12 && vmax < 2.25, name, "volumes %.4f-%.4f sub-cells", vmin, vmax);
	snprintf(name, sizeof name, "%s_point_count", label);
	CHECK(ok && (long)p->n == want, name, "%ld points, reference %ld", ok ? (long)p->n : -1L, want);
	if (ok && !strcmp(label, "rectangle_on_the_lattice")) {
		CHECK(p->x0[0] == 0.5 * d && p->x0[1] == 0.5 * d && p->volume0[0] == d * d,
		      "rectangle_on_the_lattice_seeded_at_sub_cell_centres", "first point (%.17g, %.17g)", p->x0[0],
		      p->x0[1]);
	}
	sim_destroy(&s);
	case_destroy(&c);
}

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
	/* h = 0.025 m, 2x2: sub-cells of 0.0125 m. A top on a sub-cell centre (0.99375, the column
	 * that used to be seeded to 0.9875), sides cutting sub-cells at 0.3 and 0.77 of them */
	check_rectangle("rectangle_on_the_lattice", (const double[2]){ 0.0, 0.0 }, (const double[2]){ 0.1, 1.0 });
	check_rectangle("rectangle_top_on_a_sub_cell_centre", (const double[2]){ 0.0, 0.0 },
			(const double[2]){ 0.1, 0.99375 });
	check_rectangle("rectangle_off_the_lattice", (const double[2]){ 0.003751, 0.0096251 },
			(const double[2]){ 0.0913, 0.7361 });
	HARNESS_EXIT();
}
