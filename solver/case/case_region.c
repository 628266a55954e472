/*
 * case_region.c - the geometry of a case's regions for the loader (case_region.h): boxes, polygons
 * (shoelace area, bounding box), the inside-grid test and the material-point estimate.
 *
 * A polygon may be given in either orientation; its area is the absolute shoelace sum, and one of
 * (almost) no area, below POLYGON_AREA_TOLERANCE of its bounding box, is refused, since it would
 * seed no point.
 */
#include "case_region.h"

#include <math.h>
#include <stdio.h>

#define POLYGON_VERTICES_MIN 3
#define POLYGON_AREA_TOLERANCE 1e-12      /* |area| / bounding-box area below this counts as zero */
#define REGION_SIZE (4 * CASE_NUMBER_SIZE + 16) /* "[x0, y0] to [x1, y1]" */

static const char *const box_keys[] = { "min", "max", NULL };

/* 1 when the box [min, max] lies within the grid, up to CASE_GRID_TOLERANCE of its extent. */
static int inside_grid(const struct case_grid *g, const double min[2], const double max[2])
{
	for (int d = 0; d < 2; d++) {
		double slack = CASE_GRID_TOLERANCE * g->extent[d];
		if (min[d] < g->origin[d] - slack || max[d] > g->origin[d] + g->extent[d] + slack)
			return 0;
	}
	return 1;
}

/* Writes "[x, y]" for a point (min == max), else "[x0, y0] to [x1, y1]", into dst[REGION_SIZE]. */
static const char *format_region(char *dst, const double min[2], const double max[2])
{
	char a[CASE_NUMBER_SIZE], b[CASE_NUMBER_SIZE], c[CASE_NUMBER_SIZE], d[CASE_NUMBER_SIZE];
	int n = snprintf(dst, REGION_SIZE, "[%s, %s]", case_format_number(a, min[0]),
			 case_format_number(b, min[1]));
	if (min[0] != max[0] || min[1] != max[1])
		snprintf(dst + n, REGION_SIZE - (size_t)n, " to [%s, %s]", case_format_number(c, max[0]),
			 case_format_number(d, max[1]));
	return dst;
}

void case_check_inside_grid(struct case_reader *r, const char *pointer, const char *what,
			    const struct case_grid *g, const double min[2], const double max[2])
{
	if (inside_grid(g, min, max))
		return;
	char region[REGION_SIZE], grid[REGION_SIZE];
	double top[2] = { g->origin[0] + g->extent[0], g->origin[1] + g->extent[1] };
	case_problem(r, pointer, "%s lies outside the grid: %s, grid %s", what,
		     format_region(region, min, max), format_region(grid, g->origin, top));
}

int case_read_box(struct case_reader *r, const json_t *obj, const char *base, const char *key, double min[2],
		  double max[2])
{
	char pointer[CASE_POINTER_MAX];
	const json_t *box = case_read_object(r, obj, base, key, CASE_REQUIRED);
	if (!box)
		return 0;
	case_pointer_key(pointer, base, key);
	case_check_keys(r, box, pointer, box_keys);
	int ok = case_read_vec2(r, box, pointer, "min", CASE_REQUIRED, NULL, min);
	ok &= case_read_vec2(r, box, pointer, "max", CASE_REQUIRED, NULL, max);
	if (ok && !(min[0] < max[0] && min[1] < max[1])) {
		char max_pointer[CASE_POINTER_MAX];
		case_pointer_key(max_pointer, pointer, "max");
		case_problem(r, max_pointer, "must be greater than min in both x and y");
		return 0;
	}
	return ok;
}

/* Twice the signed area of a polygon (shoelace formula). */
static double polygon_area2(const double (*v)[2], int n)
{
	double sum = 0;
	for (int i = 0, j = n - 1; i < n; j = i++)
		sum += v[j][0] * v[i][1] - v[i][0] * v[j][1];
	return sum;
}

static void bounding_box(struct case_body *b)
{
	for (int d = 0; d < 2; d++) {
		b->min[d] = b->max[d] = b->polygon[0][d];
		for (int i = 1; i < b->polygon_count; i++) {
			b->min[d] = fmin(b->min[d], b->polygon[i][d]);
			b->max[d] = fmax(b->max[d], b->polygon[i][d]);
		}
	}
}

static int read_polygon(struct case_reader *r, const json_t *o, const char *p, struct case_body *b)
{
	char pointer[CASE_POINTER_MAX], vertex[CASE_POINTER_MAX];
	size_t n;
	const json_t *a = case_read_array(r, o, p, "polygon", CASE_REQUIRED, &n);
	if (!a)
		return 0;
	case_pointer_key(pointer, p, "polygon");
	if (n < POLYGON_VERTICES_MIN || n > CASE_POLYGON_MAX) {
		case_problem(r, pointer, "must have %d to %d vertices, got %zu", POLYGON_VERTICES_MIN,
			     CASE_POLYGON_MAX, n);
		return 0;
	}
	int ok = 1;
	for (size_t i = 0; i < n; i++) {
		case_pointer_index(vertex, pointer, i);
		ok &= case_value_vec2(r, case_array_item(a, i), vertex, NULL, b->polygon[i]);
	}
	if (!ok)
		return 0;
	b->is_polygon = 1;
	b->polygon_count = (int)n;
	bounding_box(b);
	double box_area = (b->max[0] - b->min[0]) * (b->max[1] - b->min[1]);
	if (!(fabs(0.5 * polygon_area2(b->polygon, b->polygon_count)) > POLYGON_AREA_TOLERANCE * box_area)) {
		case_problem(r, pointer, "must enclose a non-zero area");
		return 0;
	}
	return 1;
}

int case_read_region(struct case_reader *r, const json_t *o, const char *p, struct case_body *b)
{
	int rectangle = case_has_key(o, "rectangle"), polygon = case_has_key(o, "polygon");
	if (rectangle == polygon) {
		case_problem(r, p, "must have exactly one of 'rectangle' and 'polygon', got %s",
			     rectangle ? "both" : "neither");
		return 0;
	}
	if (polygon)
		return read_polygon(r, o, p, b);
	return case_read_box(r, o, p, "rectangle", b->min, b->max);
}

double case_body_points(const struct case_grid *g, const struct case_body *b)
{
	double area = b->is_polygon ? 0.5 * fabs(polygon_area2(b->polygon, b->polygon_count)) :
				      (b->max[0] - b->min[0]) * (b->max[1] - b->min[1]);
	double per_cell = (double)b->particles_per_cell * b->particles_per_cell;
	return area / (g->cell_size * g->cell_size) * per_cell;
}
