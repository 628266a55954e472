/*
 * report_csv.c - a report's two tables as CSV (report.h): one header line, then one line per frame
 * or per line sample, numbers with 12 significant digits and NaN written "nan" (what Python's
 * float(), numpy and pandas read back as NaN).
 */
#include "report.h"

#include <errno.h>
#include <string.h>

/* Writes v[n] comma-separated, then `end`. */
static void put(FILE *f, const double *v, int n, const char *end)
{
	for (int i = 0; i < n; i++) {
		if (isnan(v[i]))
			fputs("nan", f);
		else
			fprintf(f, "%.12g", v[i]);
		fputs(i + 1 < n ? "," : end, f);
	}
}

/* Flushes f; PORO_EIO naming it when anything written to it failed. */
static enum poro_status finish(FILE *f, const char *name, struct poro_error *err)
{
	if (fflush(f) != 0 || ferror(f))
		return poro_error_set(err, PORO_EIO, "cannot write '%s': %s", name, strerror(errno));
	return PORO_OK;
}

enum poro_status report_frames_write(FILE *f, const char *name, const struct report_row *rows, long count,
				     struct poro_error *err)
{
	fputs("time,toe_x,runout,front_x,bulk_front_x,crest_settlement,max_gap,max_gap_x,oscillation_index,"
	      "pressure_pattern_index\n", f);
	for (const struct report_row *r = rows; r < rows + count; r++)
		put(f, (const double[]){r->time, r->toe_x, r->runout, r->front_x, r->bulk_front_x, r->crest_settlement,
					r->max_gap, r->max_gap_x, r->oscillation_index, r->pressure_pattern_index}, 10,
		    "\n");
	return finish(f, name, err);
}

enum poro_status report_line_write(FILE *f, const char *name, const struct report_sample *samples, int count,
				   struct poro_error *err)
{
	fputs("distance,x,y,pore_pressure,points\n", f);
	for (const struct report_sample *s = samples; s < samples + count; s++) {
		put(f, (const double[]){s->distance, s->x, s->y, s->pore_pressure}, 4, ",");
		fprintf(f, "%d\n", s->points);
	}
	return finish(f, name, err);
}
