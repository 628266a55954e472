/* grid.c - background grid geometry and nodal field storage (see grid.h). */
#include "grid.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum poro_status grid_init(struct grid *g, const struct case_grid *spec, struct poro_error *err)
{
	memset(g, 0, sizeof *g);
	g->origin[0] = spec->origin[0];
	g->origin[1] = spec->origin[1];
	g->h = spec->cell_size;
	g->inv_h = 1.0 / spec->cell_size;
	for (int d = 0; d < 2; d++) {
		double cells = spec->extent[d] / spec->cell_size;
		g->cells[d] = (idx_t)lround(cells);
		if (g->cells[d] < 2)   /* the loader asks each shape's own minimum (case_load.c) */
			return poro_error_set(err, PORO_EINVAL, "/grid/extent/%d: fewer than 2 cells", d);
		g->nodes[d] = g->cells[d] + 1;
	}
	g->node_count = g->nodes[0] * g->nodes[1];
	g->cell_count = g->cells[0] * g->cells[1];
	return PORO_OK;
}

idx_t grid_cell_of(const struct grid *g, const double x[2])
{
	double xi = (x[0] - g->origin[0]) * g->inv_h;
	double eta = (x[1] - g->origin[1]) * g->inv_h;
	if (!(xi >= 0 && eta >= 0 && xi <= g->cells[0] && eta <= g->cells[1]))
		return -1;
	idx_t i = (idx_t)xi, j = (idx_t)eta;
	if (i == g->cells[0])
		i--;
	if (j == g->cells[1])
		j--;
	return i + j * g->cells[0];
}

/* Every nodal array with its width and whether grid_fields_reset zeroes it (fit_moments is the
 * scratch of a kernel that zeroes it itself): one table so init, reset and release agree. */
#define GRID_DOUBLE_FIELDS(X)                                                                     \
	X(mass_s, 1, 1) X(mass_w, 1, 1) X(mass_w_points, 1, 1) X(mass_w_v, 1, 1) X(volume_s, 1, 1)      \
	X(v_s, DIM, 1) X(v_w, DIM, 1) X(v_s_old, DIM, 1) X(v_w_old, DIM, 1) X(porosity, 1, 1)           \
	X(conductivity, 1, 1) X(pressure, 1, 1) X(fit_moments, 9, 0) X(force_w, DIM, 1)                  \
	X(force, DIM, 1) X(du_s, DIM, 1)

enum poro_status grid_fields_init(struct grid_fields *f, const struct grid *g, struct poro_error *err)
{
	memset(f, 0, sizeof *f);
	size_t n = (size_t)g->node_count;
	int ok = 1;
#define ALLOC(name, width, reset) if (ok) ok = (f->name = calloc(n * (width), sizeof(double))) != NULL;
	GRID_DOUBLE_FIELDS(ALLOC)
#undef ALLOC
	if (ok)
		ok = (f->fix_s = calloc(n, 1)) && (f->fix_w = calloc(n, 1));
	if (!ok) {
		grid_fields_release(f);
		return poro_error_set(err, PORO_ENOMEM, "cannot allocate a grid of %ld nodes", (long)n);
	}
	return PORO_OK;
}

void grid_zero(double *field, size_t count)
{
	#pragma omp parallel for schedule(static)
	for (size_t i = 0; i < count; i++)
		field[i] = 0.0;
}

void grid_fields_reset(struct grid_fields *f, const struct grid *g)
{
	const size_t n = (size_t)g->node_count;
#define ZERO(name, width, reset) if (reset) grid_zero(f->name, n * (width));
	GRID_DOUBLE_FIELDS(ZERO)
#undef ZERO
}

void grid_fields_release(struct grid_fields *f)
{
	if (!f)
		return;
#define FREE(name, width, reset) free(f->name);
	GRID_DOUBLE_FIELDS(FREE)
#undef FREE
	free(f->fix_s);
	free(f->fix_w);
	memset(f, 0, sizeof *f);
}
