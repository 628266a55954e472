/*
 * frames_export.c - frames.bin and frames.json from a result.h5 (frames_export.h, docs/web.md).
 *
 * Reads each frame through results_read.h, derives the fields the dashboard colours by (p' from
 * the effective stress, |u| from the displacement), writes them as 32-bit floats and keeps the
 * index in a jansson tree written last. Each file is written to a temporary name and renamed, so a
 * reader never finds half of one. Symbols: s' the effective stress (xx, yy, xy, zz, tension
 * positive, schemas/results.md), p' = -(s'xx + s'yy + s'zz) / 3, u the displacement.
 */
#include "frames_export.h"

#include <errno.h>
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "case.h"
#include "report.h"
#include "results_read.h"

#define SETS_MAX 2
#define ARRAYS_MAX 8
#define PATH_LEN 4200

enum field { F_PORE_PRESSURE, F_MEAN_EFFECTIVE_STRESS, F_PLASTIC_STRAIN, F_DISPLACEMENT, F_COUNT };

static const struct {
	const char *name, *label, *unit;
} FIELDS[F_COUNT] = {
	{ "pore_pressure", "pore pressure", "Pa" },
	{ "mean_effective_stress", "mean effective stress p'", "Pa" },
	{ "plastic_strain", "deviatoric plastic strain", "1" },
	{ "displacement", "displacement |u|", "m" },
};

/* An array of a set: position x or y (field < 0, component 0 or 1), or a field. */
struct array {
	int field;
	int component;
};

struct set {
	const char *name;
	struct array arrays[ARRAYS_MAX];
	int count;
};

struct range {
	double lo, hi;                 /* +inf, -inf while empty */
};

struct exporter {
	struct results *res;
	FILE *bin;
	long long offset;              /* bytes written to frames.bin */
	float *buf;
	long buf_len;
	struct set sets[SETS_MAX];
	int set_count;
	struct range global[F_COUNT];
};

static void range_reset(struct range *r, int n)
{
	for (int i = 0; i < n; i++)
		r[i] = (struct range){ INFINITY, -INFINITY };
}

static void range_add(struct range *r, double v)
{
	if (!isfinite(v))
		return;
	if (v < r->lo)
		r->lo = v;
	if (v > r->hi)
		r->hi = v;
}

static json_t *range_json(const struct range *r)
{
	if (!(r->lo <= r->hi))
		return json_null();
	return json_pack("[f, f]", r->lo, r->hi);
}

/* A double as JSON: null when not finite (JSON has no NaN). */
static json_t *number(double v)
{
	return isfinite(v) ? json_real(v) : json_null();
}

/* The arrays of each set: double point has a water set carrying the pore pressure; single point
 * keeps it on the soil points (schemas/results.md). */
static void plan_sets(struct exporter *e, int double_point)
{
	struct set *soil = &e->sets[0];
	*soil = (struct set){ .name = "soil" };
	soil->arrays[soil->count++] = (struct array){ -1, 0 };
	soil->arrays[soil->count++] = (struct array){ -1, 1 };
	if (!double_point)
		soil->arrays[soil->count++] = (struct array){ F_PORE_PRESSURE, 0 };
	soil->arrays[soil->count++] = (struct array){ F_MEAN_EFFECTIVE_STRESS, 0 };
	soil->arrays[soil->count++] = (struct array){ F_PLASTIC_STRAIN, 0 };
	soil->arrays[soil->count++] = (struct array){ F_DISPLACEMENT, 0 };
	e->set_count = 1;
	if (double_point) {
		struct set *water = &e->sets[e->set_count++];
		*water = (struct set){ .name = "water" };
		water->arrays[water->count++] = (struct array){ -1, 0 };
		water->arrays[water->count++] = (struct array){ -1, 1 };
		water->arrays[water->count++] = (struct array){ F_PORE_PRESSURE, 0 };
		water->arrays[water->count++] = (struct array){ F_DISPLACEMENT, 0 };
	}
}

static const char *array_name(const struct array *a)
{
	return a->field < 0 ? (a->component ? "y" : "x") : FIELDS[a->field].name;
}

/* Reads dataset name of a set of a frame with the expected width; *values NULL when absent. */
static enum poro_status read_rows(struct exporter *e, long frame, const char *set, const char *name, int want_width,
			     double **values, long n, struct poro_error *err)
{
	long rows = 0;
	int width = 0;
	enum poro_status st = results_frame_read(e->res, frame, set, name, values, &rows, &width, err);
	if (st)
		return st;
	if (rows != n || width != want_width) {
		free(*values);
		*values = NULL;
		return poro_error_set(err, PORO_EINVAL, "frame %ld: '%s/%s' has %ld rows of %d, expected %ld of %d", frame,
				      set, name, rows, width, n, want_width);
	}
	return PORO_OK;
}

/* Writes one set of one frame; *n gets its point count. */
static enum poro_status write_set(struct exporter *e, long frame, const struct set *s, long *n, struct range *ranges,
				  struct poro_error *err)
{
	double *x = NULL, *u = NULL, *p = NULL, *stress = NULL, *eps = NULL;
	long rows = 0;
	int width = 0;
	*n = 0;
	int has = results_frame_has_set(e->res, frame, s->name, err);
	if (has < 0)
		return err->code;
	if (!has)
		return PORO_OK;
	enum poro_status st = results_frame_read(e->res, frame, s->name, "x", &x, &rows, &width, err);
	if (!st && width != 2)
		st = poro_error_set(err, PORO_EINVAL, "frame %ld: '%s/x' has %d columns, expected 2", frame, s->name, width);
	for (int i = 0; !st && i < s->count; i++) {
		int f = s->arrays[i].field;
		if (f == F_DISPLACEMENT && !u)
			st = read_rows(e, frame, s->name, "displacement", 2, &u, rows, err);
		else if (f == F_PORE_PRESSURE && !p)
			st = read_rows(e, frame, s->name, "pore_pressure", 1, &p, rows, err);
		else if (f == F_MEAN_EFFECTIVE_STRESS && !stress)
			st = read_rows(e, frame, s->name, "stress", 4, &stress, rows, err);
		else if (f == F_PLASTIC_STRAIN && !eps)
			st = read_rows(e, frame, s->name, "plastic_strain", 1, &eps, rows, err);
	}
	if (!st && rows > e->buf_len) {
		float *grown = realloc(e->buf, (size_t)rows * sizeof *grown);
		if (!grown)
			st = poro_error_set(err, PORO_ENOMEM, "no memory for %ld points", rows);
		else {
			e->buf = grown;
			e->buf_len = rows;
		}
	}
	for (int i = 0; !st && i < s->count; i++) {
		const struct array *a = &s->arrays[i];
		for (long k = 0; k < rows; k++) {
			double v;
			switch (a->field) {
			case F_PORE_PRESSURE: v = p[k]; break;
			case F_MEAN_EFFECTIVE_STRESS: v = -(stress[4 * k] + stress[4 * k + 1] + stress[4 * k + 3]) / 3.0; break;
			case F_PLASTIC_STRAIN: v = eps[k]; break;
			case F_DISPLACEMENT: v = hypot(u[2 * k], u[2 * k + 1]); break;
			default: v = x[2 * k + a->component]; break;
			}
			e->buf[k] = isfinite(v) ? (float)v : NAN;
			if (a->field >= 0) {
				range_add(&ranges[a->field], v);
				range_add(&e->global[a->field], v);
			}
		}
		if (rows && fwrite(e->buf, sizeof(float), (size_t)rows, e->bin) != (size_t)rows)
			st = poro_error_set(err, PORO_EIO, "cannot write frames.bin: %s", strerror(errno));
		e->offset += (long long)rows * (long long)sizeof(float);
	}
	free(x), free(u), free(p), free(stress), free(eps);
	*n = rows;
	return st;
}

static enum poro_status write_frame(struct exporter *e, long frame, json_t *frames, struct poro_error *err)
{
	double time = 0;
	enum poro_status st = results_frame_time(e->res, frame, &time, err);
	struct range ranges[F_COUNT];
	range_reset(ranges, F_COUNT);
	long long start = e->offset;
	json_t *counts = json_object();
	for (int i = 0; !st && i < e->set_count; i++) {
		long n = 0;
		st = write_set(e, frame, &e->sets[i], &n, ranges, err);
		json_object_set_new(counts, e->sets[i].name, json_integer(n));
	}
	if (st) {
		json_decref(counts);
		return st;
	}
	json_t *r = json_object();
	for (int f = 0; f < F_COUNT; f++)
		json_object_set_new(r, FIELDS[f].name, range_json(&ranges[f]));
	json_array_append_new(frames, json_pack("{s:I, s:o, s:I, s:I, s:o, s:o}", "index", (json_int_t)frame, "time",
						number(time), "offset", (json_int_t)start, "length",
						(json_int_t)(e->offset - start), "counts", counts, "ranges", r));
	return PORO_OK;
}

/* The report's rows of a slope or landslide (polygon bodies), else null: report_open() refuses
 * other cases, which is no error here. */
static json_t *report_json(const char *path)
{
	struct report *rep = NULL;
	struct report_settings set = REPORT_SETTINGS_DEFAULT;
	struct poro_error err = { 0 };
	struct report_row *rows = NULL;
	long n = 0;
	if (report_open(&rep, path, &set, &err) || report_frames(rep, &rows, &n, &err)) {
		report_close(&rep);
		return json_null();
	}
	json_t *t = json_array(), *runout = json_array(), *toe = json_array(), *crest = json_array();
	for (long i = 0; i < n; i++) {
		json_array_append_new(t, number(rows[i].time));
		json_array_append_new(runout, number(rows[i].runout));
		json_array_append_new(toe, number(rows[i].toe_x));
		json_array_append_new(crest, number(rows[i].crest_settlement));
	}
	free(rows);
	report_close(&rep);
	return json_pack("{s:o, s:o, s:o, s:o}", "time", t, "runout", runout, "toe_x", toe, "crest_settlement", crest);
}

static json_t *index_json(const struct exporter *e, const struct case_spec *c, long long job, long long attempt,
			  json_t *frames, json_t *report)
{
	json_t *sets = json_object(), *fields = json_array();
	for (int i = 0; i < e->set_count; i++) {
		json_t *names = json_array();
		for (int k = 0; k < e->sets[i].count; k++)
			json_array_append_new(names, json_string(array_name(&e->sets[i].arrays[k])));
		json_object_set_new(sets, e->sets[i].name, names);
	}
	for (int f = 0; f < F_COUNT; f++) {
		json_t *in = json_array();
		for (int i = 0; i < e->set_count; i++)
			for (int k = 0; k < e->sets[i].count; k++)
				if (e->sets[i].arrays[k].field == f)
					json_array_append_new(in, json_string(e->sets[i].name));
		json_array_append_new(fields, json_pack("{s:s, s:s, s:s, s:o, s:o}", "name", FIELDS[f].name, "label",
							FIELDS[f].label, "unit", FIELDS[f].unit, "sets", in, "range",
							range_json(&e->global[f])));
	}
	const struct case_grid *g = &c->grid;
	json_t *grid = json_pack("{s:[f, f], s:[f, f], s:f}", "origin", g->origin[0], g->origin[1], "extent",
				 g->extent[0], g->extent[1], "cell_size", g->cell_size);
	return json_pack("{s:s, s:I, s:I, s:I, s:o, s:o, s:o, s:o, s:o}", "format", FRAMES_EXPORT_FORMAT, "job",
			 (json_int_t)job, "attempt", (json_int_t)attempt, "bin_bytes", (json_int_t)e->offset, "grid",
			 grid, "sets", sets, "fields", fields, "frames", frames, "report", report);
}

static enum poro_status finish_file(const char *tmp, const char *final, struct poro_error *err)
{
	if (rename(tmp, final) != 0)
		return poro_error_set(err, PORO_EIO, "cannot rename '%s' to '%s': %s", tmp, final, strerror(errno));
	return PORO_OK;
}

enum poro_status frames_export(const char *path, const char *dir, long long job, long long attempt,
			       struct poro_error *err)
{
	char bin_tmp[PATH_LEN], bin[PATH_LEN], index_tmp[PATH_LEN], index[PATH_LEN];
	snprintf(bin, sizeof bin, "%s/" FRAMES_EXPORT_BIN, dir);
	snprintf(bin_tmp, sizeof bin_tmp, "%s/." FRAMES_EXPORT_BIN ".tmp", dir);
	snprintf(index, sizeof index, "%s/" FRAMES_EXPORT_INDEX, dir);
	snprintf(index_tmp, sizeof index_tmp, "%s/." FRAMES_EXPORT_INDEX ".tmp", dir);
	struct exporter e = { 0 };
	struct case_spec *c = NULL;
	json_t *frames = json_array(), *doc = NULL;
	range_reset(e.global, F_COUNT);
	enum poro_status st = results_check_file(path, err);
	if (!st)
		st = results_open(&e.res, path, err);
	if (!st)
		st = case_load_string(results_case_json(e.res), &c, err);
	if (!st && !(e.bin = fopen(bin_tmp, "wb")))
		st = poro_error_set(err, PORO_EIO, "cannot create '%s': %s", bin_tmp, strerror(errno));
	long count = st ? 0 : results_frame_count(e.res);
	if (!st)
		plan_sets(&e, c->formulation.phases == PHASES_DOUBLE_POINT);
	for (long i = 0; !st && i < count; i++)
		st = write_frame(&e, i, frames, err);
	if (e.bin && fclose(e.bin) != 0 && !st)
		st = poro_error_set(err, PORO_EIO, "cannot write '%s': %s", bin_tmp, strerror(errno));
	if (!st) {
		doc = index_json(&e, c, job, attempt, frames, report_json(path));
		frames = NULL;
		if (!doc)
			st = poro_error_set(err, PORO_ENOMEM, "no memory for the frames' index");
	}
	if (!st && json_dump_file(doc, index_tmp, JSON_COMPACT | JSON_REAL_PRECISION(9)) != 0)
		st = poro_error_set(err, PORO_EIO, "cannot write '%s'", index_tmp);
	if (!st)
		st = finish_file(bin_tmp, bin, err);
	if (!st)
		st = finish_file(index_tmp, index, err);
	if (st) {
		remove(bin_tmp), remove(index_tmp);
		remove(bin), remove(index);
	}
	json_decref(frames);
	json_decref(doc);
	free(e.buf);
	case_destroy(&c);
	results_close(&e.res);
	return st;
}
