/*
 * report.c - opening a result file for a report (report.h): the file checked and opened through
 * results_read.h, the case stored in it loaded, and the settings settled, the ones the user gave
 * checked and the others derived from the case's polygon bodies (the rules are in report.h and
 * docs/report.md). The per-frame table is report_frames.c, the line samples report_line.c.
 */
#include "report_internal.h"

#include <stdlib.h>
#include <string.h>

#define GEOMETRY_EPS 1e-9   /* vertices this many cells apart count as level, or on the grid's edge */

/* ---- the settings ------------------------------------------------------------------------------ */

/* PORO_EINVAL naming the first body that is not a polygon, when `what` is to be derived. */
static enum poro_status require_polygons(const struct case_spec *c, const char *what, const char *option,
					 struct poro_error *err)
{
	for (int b = 0; b < c->body_count; b++)
		if (!c->bodies[b].is_polygon)
			return poro_error_set(err, PORO_EINVAL,
					      "cannot derive the %s: body '%s' is a rectangle, not a polygon; give %s",
					      what, c->bodies[b].name, option);
	return PORO_OK;
}

/* The lowest vertex not on the grid's bottom edge: the ground level (report.h). */
static double derive_ground(const struct case_spec *c)
{
	const double eps = GEOMETRY_EPS * c->grid.cell_size, bottom = c->grid.origin[1];
	double ground = INFINITY;
	for (int b = 0; b < c->body_count; b++)
		for (int v = 0; v < c->bodies[b].polygon_count; v++)
			if (c->bodies[b].polygon[v][1] > bottom + eps)
				ground = fmin(ground, c->bodies[b].polygon[v][1]);
	return ground;
}

/* The x of the highest vertex, the largest x among equally high ones: the crest edge (report.h). */
static double derive_crest(const struct case_spec *c)
{
	const double eps = GEOMETRY_EPS * c->grid.cell_size;
	double top = -INFINITY, crest = NAN;
	for (int b = 0; b < c->body_count; b++)
		for (int v = 0; v < c->bodies[b].polygon_count; v++) {
			const double *p = c->bodies[b].polygon[v];
			if (p[1] > top + eps)
				top = p[1], crest = p[0];
			else if (p[1] >= top - eps && p[0] > crest)
				crest = p[0];
		}
	return crest;
}

/* A quarter of the finest seeding spacing (report.h). */
static double derive_tolerance(const struct case_spec *c)
{
	int finest = 1;
	for (int b = 0; b < c->body_count; b++)
		if (c->bodies[b].particles_per_cell > finest)
			finest = c->bodies[b].particles_per_cell;
	return REPORT_TOLERANCE_SPACINGS * c->grid.cell_size / finest;
}

static enum poro_status check_given(const char *name, double value, struct poro_error *err)
{
	if (!isfinite(value))
		return poro_error_set(err, PORO_EINVAL, "%s %g is not a finite number", name, value);
	return PORO_OK;
}

static enum poro_status settle(struct report *rep, const struct report_settings *given, struct poro_error *err)
{
	const struct case_spec *c = rep->spec;
	struct report_settings *s = &rep->settings;
	enum poro_status st;
	*s = *given;
	if (isnan(s->ground)) {
		if ((st = require_polygons(c, "ground level", "--ground Y", err)))
			return st;
		s->ground = derive_ground(c);
	}
	if (isnan(s->crest)) {
		if ((st = require_polygons(c, "crest", "--crest X", err)))
			return st;
		s->crest = derive_crest(c);
	}
	if (isnan(s->tolerance))
		s->tolerance = derive_tolerance(c);
	if ((st = check_given("ground", s->ground, err)) || (st = check_given("crest", s->crest, err)) ||
	    (st = check_given("tolerance", s->tolerance, err)))
		return st;
	if (s->tolerance < 0)
		return poro_error_set(err, PORO_EINVAL, "tolerance %g is negative", s->tolerance);
	return PORO_OK;
}

/* ---- opening ----------------------------------------------------------------------------------- */

static enum poro_status load(struct report *rep, const char *path, const struct report_settings *given,
			     struct poro_error *err)
{
	enum poro_status st = results_check_file(path, err);
	if (!st)
		st = results_open(&rep->results, path, err);
	if (st)
		return st;
	rep->frames = results_frame_count(rep->results);
	if (rep->frames < 1)
		return poro_error_set(err, PORO_EINVAL, "'%s' holds no frames", path);
	struct poro_error case_err = {0};
	if (case_load_string(results_case_json(rep->results), &rep->spec, &case_err))
		return poro_error_set(err, PORO_EINVAL, "the case stored in '%s' does not load:\n%s", path,
				      case_err.message);
	const struct case_spec *c = rep->spec;
	rep->h = c->grid.cell_size;
	rep->particles_per_cell = c->bodies[0].particles_per_cell;
	rep->spacing = rep->h / rep->particles_per_cell;
	rep->double_point = c->formulation.phases == PHASES_DOUBLE_POINT;
	rep->columns = lround(c->grid.extent[0] / rep->h);
	if (rep->columns < 1)
		rep->columns = 1;
	rep->top_soil = malloc(sizeof(double) * (size_t)rep->columns);
	rep->top_water = malloc(sizeof(double) * (size_t)rep->columns);
	if (!rep->top_soil || !rep->top_water)
		return poro_error_set(err, PORO_ENOMEM, "cannot allocate the report's columns");
	return settle(rep, given, err);
}

enum poro_status report_open(struct report **out, const char *path, const struct report_settings *settings,
			     struct poro_error *err)
{
	*out = NULL;
	if (!path)
		return poro_error_set(err, PORO_EINVAL, "cannot report: no result file");
	struct report *rep = calloc(1, sizeof *rep);
	if (!rep || !(rep->path = malloc(strlen(path) + 1))) {
		free(rep);
		return poro_error_set(err, PORO_ENOMEM, "cannot allocate the report");
	}
	strcpy(rep->path, path);
	enum poro_status st = load(rep, path, settings, err);
	if (st)
		report_close(&rep);
	*out = rep;
	return st;
}

void report_close(struct report **rp)
{
	if (!rp || !*rp)
		return;
	struct report *rep = *rp;
	results_close(&rep->results);
	case_destroy(&rep->spec);
	free(rep->top_soil);
	free(rep->top_water);
	free(rep->path);
	free(rep);
	*rp = NULL;
}

const struct report_settings *report_settings_used(const struct report *rep)
{
	return &rep->settings;
}

enum poro_status report_read(struct report *rep, long frame, const char *set, const char *name, int width,
			     double **values, long *rows, struct poro_error *err)
{
	int cols = 0;
	enum poro_status st = results_frame_read(rep->results, frame, set, name, values, rows, &cols, err);
	if (st || cols == width || *rows == 0)
		return st;
	free(*values);
	*values = NULL;
	return poro_error_set(err, PORO_EIO, "cannot use '%s/%s' of frame %ld in '%s': %d columns, expected %d", set,
			      name, frame, rep->path, cols, width);
}
