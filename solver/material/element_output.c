/*
 * element_output.c - the single-element driver's file (element.h): element.csv, one row per step.
 * The pictures of it (q against p, q and the volumetric strain against the axial strain) are
 * poro-plot's (cli/poro_plot.py), drawn with a plotting library: the hand-drawn SVG this file wrote
 * before clipped its caption at both edges.
 */
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "element.h"

#define PATH_SIZE 4096

static enum poro_status write_csv(const struct element_result *r, const char *path, struct poro_error *err)
{
	FILE *f = fopen(path, "w");
	if (!f)
		return poro_error_set(err, PORO_EIO, "cannot create '%s': %s", path, strerror(errno));
	fprintf(f, "axial_strain,p,q,volumetric_strain");
	for (int k = 0; k < r->output_count; k++)
		fprintf(f, ",%s", r->output_names[k]);
	fprintf(f, "\n");
	for (int i = 0; i < r->rows; i++) {
		const struct element_row *w = &r->row[i];
		fprintf(f, "%.12g,%.12g,%.12g,%.12g", w->axial_strain, w->p, w->q, w->volumetric_strain);
		for (int k = 0; k < r->output_count; k++)
			fprintf(f, ",%.12g", w->outputs[k]);
		fprintf(f, "\n");
	}
	if (fclose(f))
		return poro_error_set(err, PORO_EIO, "cannot write '%s': %s", path, strerror(errno));
	return PORO_OK;
}

enum poro_status element_write(const struct element_case *c, const struct element_result *r, const char *dir,
			       struct poro_error *err)
{
	char path[PATH_SIZE];
	if (mkdir(dir, 0777) && errno != EEXIST)
		return poro_error_set(err, PORO_EIO, "cannot create output directory '%s': %s", dir, strerror(errno));
	if (snprintf(path, sizeof path, "%s/element.csv", dir) >= (int)sizeof path)
		return poro_error_set(err, PORO_EIO, "output directory name too long: '%s'", dir);
	return write_csv(r, path, err);
}
