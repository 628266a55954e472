/*
 * report_internal.h - the report object shared by report.c (opening, settings), report_frames.c
 * (the per-frame table) and report_line.c (the line samples). Not public: report.h is the manual.
 */
#ifndef PORO_REPORT_INTERNAL_H
#define PORO_REPORT_INTERNAL_H

#include "case.h"
#include "report.h"
#include "results_read.h"

struct report {
	char *path;                       /* the file as given, for messages */
	struct results *results;
	struct case_spec *spec;           /* the case stored in the file */
	struct report_settings settings;  /* in effect: every field finite */
	double h;                         /* grid cell_size, m */
	double spacing;                   /* seeding spacing of the first body, m (oscillation indices) */
	int particles_per_cell;           /* of the first body: the sites of a cell along x and y */
	int double_point;                 /* the case's formulation has water points */
	long frames;
	long columns;                     /* gap columns of width h across the grid */
	double *top_soil, *top_water;     /* [columns] scratch of report_frames(), m */
};

/* Reads dataset `name` of point set `set` of a frame (results_frame_read()) and checks it has
 * `width` columns (PORO_EIO naming the dataset otherwise). *values is malloc'd, NULL on failure. */
enum poro_status report_read(struct report *rep, long frame, const char *set, const char *name, int width,
			     double **values, long *rows, struct poro_error *err);

#endif
