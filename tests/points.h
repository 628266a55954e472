/*
 * points.h - finding material points in a test: the point of a set nearest to a place, by its
 * reference (initial) position, so that a test follows one piece of soil however far it moves.
 */
#ifndef PORO_TEST_POINTS_H
#define PORO_TEST_POINTS_H

#include <math.h>

#include "particles.h"

static inline idx_t test_nearest_point(const struct particles *p, double x, double y)
{
	idx_t best = 0;
	for (idx_t q = 1; q < p->n; q++)
		if (hypot(p->x0[2 * q] - x, p->x0[2 * q + 1] - y) < hypot(p->x0[2 * best] - x, p->x0[2 * best + 1] - y))
			best = q;
	return best;
}

#endif
