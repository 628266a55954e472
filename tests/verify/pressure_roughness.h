/*
 * pressure_roughness.h - the pore-pressure roughness the 002 examples' tests compare with and
 * without stabilisation (Fig. 10 and Fig. 16 show a checkerboard without): the RMS over the points
 * that have all four lattice neighbours (by reference position, `spacing` apart) of p_i minus the
 * mean of those four, divided by max |p|. A checkerboard scores O(1), a smooth field O(h^2), a
 * cell-wise constant field (the explicit scheme's, one pressure per cell) the steps between cells.
 * O(n^2) in the points: for the reduced test cases only.
 */
#ifndef PORO_TEST_PRESSURE_ROUGHNESS_H
#define PORO_TEST_PRESSURE_ROUGHNESS_H

#include <math.h>

#include "particles.h"

static inline double pressure_roughness(const struct particles *w, double spacing)
{
	double sum = 0, pmax = 0;
	long count = 0;
	for (idx_t i = 0; i < w->n; i++)
		pmax = fmax(pmax, fabs(w->pressure[i]));
	for (idx_t i = 0; i < w->n; i++) {
		double acc = 0;
		int k = 0;
		for (idx_t j = 0; j < w->n; j++) {
			double dx = w->x0[2 * j] - w->x0[2 * i], dy = w->x0[2 * j + 1] - w->x0[2 * i + 1];
			if (fabs(hypot(dx, dy) - spacing) < 1e-6 * spacing)
				acc += w->pressure[j], k++;
		}
		if (k == 4) {
			double e = w->pressure[i] - acc / 4;
			sum += e * e;
			count++;
		}
	}
	return count && pmax > 0 ? sqrt(sum / count) / pmax : 1.0;
}

#endif
