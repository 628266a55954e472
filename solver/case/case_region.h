/*
 * case_region.h - private to the case loader: the geometry of a case's regions (case_region.c).
 *
 * Boxes {"min", "max"} (body rectangles, probe boxes), polygons, whether a region lies inside the
 * grid, and the area that sets how many material points a body seeds. Problems are recorded as
 * "JSON-pointer: message" through the reader (case_json.h).
 */
#ifndef PORO_CASE_REGION_H
#define PORO_CASE_REGION_H

#include "case.h"
#include "case_json.h"

/* Relative to the grid extent: extent / cell_size integrality and the inside-grid tests, so that a
 * body that ends on the grid edge, written with decimal rounding, still lies inside. */
#define CASE_GRID_TOLERANCE 1e-9

/* Reads obj[key] = {"min": [x, y], "max": [x, y]} with min < max in both directions; 1 when valid. */
int case_read_box(struct case_reader *r, const json_t *obj, const char *base, const char *key, double min[2],
		  double max[2]);

/* Reads the body's region at p: exactly one of "rectangle" and "polygon" (3 to CASE_POLYGON_MAX
 * vertices, non-zero area), and sets its bounding box; 1 when valid. */
int case_read_region(struct case_reader *r, const json_t *o, const char *p, struct case_body *b);

/* Records "pointer: WHAT lies outside the grid: ..." unless [min, max] lies inside g. */
void case_check_inside_grid(struct case_reader *r, const char *pointer, const char *what, const struct case_grid *g,
			    const double min[2], const double max[2]);

/* The material points body b seeds, estimated from its area: area / h^2 cells of ppc^2 points each
 * (particles.c seeds the cells the body covers). b's region and particles_per_cell must be valid. */
double case_body_points(const struct case_grid *g, const struct case_body *b);

#endif
