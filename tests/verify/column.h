/*
 * column.h - helpers shared by the one-dimensional column tests: the reference (material) height
 * of a current height, read off the soil points of one vertical line.
 *
 * Consolidation theories are written in the soil's reference coordinate. A pressure point at
 * current height y is compared at the reference height of the soil there: the soil points on the
 * line x0 = x0 of point 0 are ordered in y, and y0 is interpolated linearly between the two that
 * bracket y (extrapolated below the lowest with y0/y = const, and the top of the column above the
 * highest).
 *
 * And the mean total vertical stress of the soil, compression positive, which a body pressed by a
 * load or a plate carries through every horizontal section in equilibrium.
 */
#ifndef PORO_TEST_COLUMN_H
#define PORO_TEST_COLUMN_H

#include <math.h>
#include <stdlib.h>

#include "figures.h"
#include "poro.h"

static inline double soil_reference_height(const struct sim *s, double y, double top0)
{
	return figure_reference_height(sim_soil(s), y, top0);   /* the solver's figures use the same */
}

/* Mean over the soil points of the total vertical stress, compression positive: the effective
 * stress volume-averaged, less the mean of the pore pressure over its points (both tension
 * positive inside the solver). */
static inline double mean_total_vertical_compression(const struct sim *s)
{
	const struct particles *p = sim_soil(s);
	double sum = 0.0, volume = 0.0, pressure = 0.0;
	for (idx_t q = 0; q < p->n; q++)
		sum += p->volume[q] * p->stress[4 * q + 1], volume += p->volume[q];
	idx_t n = sim_pressure_point_count(s);
	double *pp = malloc(sizeof(double) * (size_t)n);
	sim_pore_pressure(s, pp, NULL);
	for (idx_t i = 0; i < n; i++)
		pressure += pp[i] / n;
	free(pp);
	return pressure - sum / volume;
}

#endif
