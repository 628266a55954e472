/*
 * report_frames.c - the per-frame table of a report (report.h): toe, run-out and slide front,
 * crest settlement, the largest gap between the soil and water surfaces, the oscillation index
 * of the mean effective stress and the two-cell pattern index of the pore pressure, from each
 * frame's soil (and water) points. Definitions in report.h and docs/report.md; each quantity is
 * one pass over a frame's points.
 *
 * The oscillation index is oscillation_index() itself (oscillation.h), given a read-only view of
 * the frame's soil points: their reference positions x0 = x - displacement (the seeding lattice
 * it places points on; the subtraction undoes the writer's x - x0 to round-off, far inside the
 * half spacing that floor() in oscillation.c tolerates) and their stress. The pattern index is
 * oscillation_index_pattern() on a view of the points that carry the pore pressure (the water
 * points in double point, which are seeded on the soil's lattice, and the soil points in single
 * point), placed the same way.
 */
#include "report_internal.h"

#include <stdlib.h>

#include "oscillation.h"
#include "particles.h"

/* Largest x of the points x[n] whose `at`[n] (their position, or their reference position) lies
 * above `level`; NaN when none does. */
static double front(const double *x, const double *at, long n, double level)
{
	double front_x = -INFINITY;
	for (long i = 0; i < n; i++)
		if (at[2 * i + 1] > level && x[2 * i] > front_x)
			front_x = x[2 * i];
	return isinf(front_x) ? NAN : front_x;
}

struct mass_at_x {
	double x, mass;
};

static int by_x_descending(const void *a, const void *b)
{
	const double xa = ((const struct mass_at_x *)a)->x, xb = ((const struct mass_at_x *)b)->x;
	return (xa < xb) - (xa > xb);
}

/* The x beyond which lies `fraction` of the mass of the points x[n] (masses mass[n]) whose reference
 * positions `at` lie above `level`: walking from the front back, the x of the point at which the
 * mass passed reaches that share. NaN when no point lies above `level`. */
static enum poro_status bulk_front(const double *x, const double *at, const double *mass, long n, double level,
				   double fraction, double *front_x, struct poro_error *err)
{
	struct mass_at_x *p = malloc(sizeof *p * (size_t)(n > 0 ? n : 1));
	if (!p)
		return poro_error_set(err, PORO_ENOMEM, "cannot allocate %ld points for the bulk front", n);
	long m = 0;
	double total = 0.0;
	for (long i = 0; i < n; i++)
		if (at[2 * i + 1] > level) {
			p[m++] = (struct mass_at_x){x[2 * i], mass[i]};
			total += mass[i];
		}
	qsort(p, (size_t)m, sizeof *p, by_x_descending);
	*front_x = NAN;
	double passed = 0.0;
	for (long k = 0; k < m; k++) {
		passed += p[k].mass;
		if (passed >= fraction * total) {
			*front_x = p[k].x;
			break;
		}
	}
	free(p);
	return PORO_OK;
}

/* Surface height at `at`: the largest y of the points within `half` of it in x, NaN when none is. */
static double surface(const double *x, long n, double at, double half)
{
	double top = -INFINITY;
	for (long i = 0; i < n; i++)
		if (fabs(x[2 * i] - at) <= half && x[2 * i + 1] > top)
			top = x[2 * i + 1];
	return isinf(top) ? NAN : top;
}

/* top[i] = the largest y of the points in column i, -INFINITY for an empty column. */
static void column_tops(const struct report *rep, const double *x, long n, double *top)
{
	const double origin = rep->spec->grid.origin[0];
	for (long i = 0; i < rep->columns; i++)
		top[i] = -INFINITY;
	for (long q = 0; q < n; q++) {
		long i = (long)floor((x[2 * q] - origin) / rep->h);
		i = i < 0 ? 0 : i >= rep->columns ? rep->columns - 1 : i;   /* a point on the grid's right edge */
		if (x[2 * q + 1] > top[i])
			top[i] = x[2 * q + 1];
	}
}

/* The largest soil-over-water gap among the columns holding both sets, and its column's centre. */
static void largest_gap(struct report *rep, const double *soil, long ns, const double *water, long nw,
			struct report_row *row)
{
	column_tops(rep, soil, ns, rep->top_soil);
	column_tops(rep, water, nw, rep->top_water);
	row->max_gap = row->max_gap_x = NAN;
	for (long i = 0; i < rep->columns; i++) {
		if (isinf(rep->top_soil[i]) || isinf(rep->top_water[i]))
			continue;
		double gap = rep->top_soil[i] - rep->top_water[i];
		if (isnan(row->max_gap) || gap > row->max_gap) {
			row->max_gap = gap;
			row->max_gap_x = rep->spec->grid.origin[0] + (i + 0.5) * rep->h;
		}
	}
}

/* The reference positions x0 = x - displacement of the points x[n] of point set `set` of a frame
 * (heap, the caller frees). */
static enum poro_status reference_positions(struct report *rep, long frame, const char *set, const double *x, long n,
					    double **x0, struct poro_error *err)
{
	long rows = 0;
	enum poro_status st = report_read(rep, frame, set, "displacement", 2, x0, &rows, err);
	if (!st && rows != n)
		st = poro_error_set(err, PORO_EIO, "frame %ld of '%s': %ld %s positions but %ld displacements",
				    frame, rep->path, n, set, rows);
	if (!st)
		for (long k = 0; k < 2 * n; k++)
			(*x0)[k] = x[k] - (*x0)[k];
	return st;
}

/* The oscillation index of the soil points of a frame at reference positions x0[n]; NaN where
 * oscillation_index() finds it undefined (PORO_EINVAL: zero stress, no point with two lattice
 * neighbours). */
static enum poro_status oscillation(struct report *rep, long frame, double *x0, long n, double *index,
				    struct poro_error *err)
{
	double *stress = NULL;
	long rows_s = 0;
	enum poro_status st = report_read(rep, frame, "soil", "stress", 4, &stress, &rows_s, err);
	if (!st && rows_s != n)
		st = poro_error_set(err, PORO_EIO, "frame %ld of '%s': %ld soil positions but %ld stresses", frame,
				    rep->path, n, rows_s);
	if (!st) {
		const struct particles view = {.n = (idx_t)n, .x0 = x0, .stress = stress};
		struct poro_error undefined = {0};
		st = oscillation_index(&rep->spec->grid, &view, rep->spacing, index, &undefined);
		if (st == PORO_EINVAL)
			*index = NAN, st = PORO_OK;
		else if (st)
			*err = undefined;
	}
	free(stress);
	return st;
}

/* The two-cell pattern index of a frame's pore pressure on the points of `set` at positions x[n]
 * (x0: their reference positions when already known, else NULL); NaN where
 * oscillation_index_pattern() finds it undefined. */
static enum poro_status pressure_pattern(struct report *rep, long frame, const char *set, const double *x,
					 const double *x0, long n, double *index, struct poro_error *err)
{
	double *p = NULL, *own = NULL;
	long rows = 0;
	enum poro_status st = x0 ? PORO_OK : reference_positions(rep, frame, set, x, n, &own, err);
	if (!st)
		st = report_read(rep, frame, set, "pore_pressure", 1, &p, &rows, err);
	if (!st && rows != n)
		st = poro_error_set(err, PORO_EIO, "frame %ld of '%s': %ld %s positions but %ld pore pressures", frame,
				    rep->path, n, set, rows);
	if (!st) {
		const struct particles view = {.n = (idx_t)n, .x0 = (double *)(x0 ? x0 : own)};
		struct poro_error undefined = {0};
		st = oscillation_index_pattern(&rep->spec->grid, &view, rep->spacing, rep->particles_per_cell, p, index,
					       &undefined);
		if (st == PORO_EINVAL)
			*index = NAN, st = PORO_OK;
		else if (st)
			*err = undefined;
	}
	free(p);
	free(own);
	return st;
}

/* One frame's row but for the differences to the first frame (runout, crest_settlement), and the
 * surface height at the crest in *top. */
static enum poro_status frame_row(struct report *rep, long frame, struct report_row *row, double *top,
				  struct poro_error *err)
{
	const struct report_settings *set = &rep->settings;
	double *soil = NULL, *soil0 = NULL, *water = NULL, *mass = NULL;
	long ns = 0, nw = 0, nm = 0;
	enum poro_status st = results_frame_time(rep->results, frame, &row->time, err);
	if (!st)
		st = report_read(rep, frame, "soil", "x", 2, &soil, &ns, err);
	if (!st)
		st = reference_positions(rep, frame, "soil", soil, ns, &soil0, err);
	if (!st) {
		row->toe_x = front(soil, soil, ns, set->ground + set->tolerance);
		row->front_x = front(soil, soil0, ns, set->ground + set->tolerance);
		st = report_read(rep, frame, "soil", "mass", 1, &mass, &nm, err);
	}
	if (!st && nm != ns)
		st = poro_error_set(err, PORO_EIO, "frame %ld of '%s': %ld soil positions but %ld masses", frame,
				    rep->path, ns, nm);
	if (!st)
		st = bulk_front(soil, soil0, mass, ns, set->ground + set->tolerance, REPORT_BULK_FRACTION,
				&row->bulk_front_x, err);
	if (!st) {
		*top = surface(soil, ns, set->crest, REPORT_CREST_HALF_WIDTH * rep->h);
		row->max_gap = row->max_gap_x = NAN;
	}
	if (!st && rep->double_point && !(st = report_read(rep, frame, "water", "x", 2, &water, &nw, err)))
		largest_gap(rep, soil, ns, water, nw, row);
	if (!st)
		st = oscillation(rep, frame, soil0, ns, &row->oscillation_index, err);
	if (!st)
		st = rep->double_point ? pressure_pattern(rep, frame, "water", water, NULL, nw, &row->pressure_pattern_index,
							  err)
				       : pressure_pattern(rep, frame, "soil", soil, soil0, ns, &row->pressure_pattern_index,
							  err);
	free(soil);
	free(soil0);
	free(water);
	free(mass);
	return st;
}

enum poro_status report_frames(struct report *rep, struct report_row **out, long *count, struct poro_error *err)
{
	*out = NULL;
	*count = 0;
	struct report_row *rows = calloc((size_t)rep->frames, sizeof *rows);
	double *top = calloc((size_t)rep->frames, sizeof *top);
	enum poro_status st = rows && top ? PORO_OK :
		poro_error_set(err, PORO_ENOMEM, "cannot allocate %ld report rows", rep->frames);
	for (long k = 0; !st && k < rep->frames; k++)
		st = frame_row(rep, k, &rows[k], &top[k], err);
	for (long k = 0; !st && k < rep->frames; k++) {
		rows[k].runout = rows[k].front_x - rows[0].front_x;   /* report.h: the slope's own soil */
		rows[k].crest_settlement = top[0] - top[k];
	}
	free(top);
	if (st) {
		free(rows);
		return st;
	}
	*out = rows;
	*count = rep->frames;
	return PORO_OK;
}
