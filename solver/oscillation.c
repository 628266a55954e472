/*
 * oscillation.c - oscillation index of the mean effective stress (definition in oscillation.h).
 *
 * Points are placed on a dense table of lattice sites by their reference positions (site
 * floor((x0 - origin) / spacing) per direction), so each point finds its four lattice neighbours
 * in O(1).
 */
#include "oscillation.h"

#include <math.h>
#include <stdlib.h>

static double mean_effective_stress(const struct particles *p, idx_t i)
{
	const double *s = p->stress + 4 * i;
	return (s[0] + s[1] + s[3]) / 3.0;
}

/* Overshoot of value v out of the range of its two neighbours a and b. */
static double overshoot(double v, double a, double b)
{
	double hi = a > b ? a : b, lo = a < b ? a : b;
	return v > hi ? v - hi : v < lo ? lo - v : 0.0;
}

enum poro_status oscillation_index(const struct case_grid *g, const struct particles *p, double spacing,
				   double *index, struct poro_error *err)
{
	*index = 0.0;
	if (!(spacing > 0.0))
		return poro_error_set(err, PORO_EINVAL, "oscillation index: spacing must be positive, got %g", spacing);
	long sites[2];
	for (int d = 0; d < 2; d++)
		sites[d] = (long)ceil(g->extent[d] / spacing - 1e-9);
	idx_t *at = malloc((size_t)sites[0] * (size_t)sites[1] * sizeof *at);
	if (!at)
		return poro_error_set(err, PORO_ENOMEM, "cannot allocate the oscillation index work space");
	for (long k = 0; k < sites[0] * sites[1]; k++)
		at[k] = -1;
	for (idx_t i = 0; i < p->n; i++) {
		long u = (long)floor((p->x0[2 * i] - g->origin[0]) / spacing);
		long v = (long)floor((p->x0[2 * i + 1] - g->origin[1]) / spacing);
		if (u >= 0 && v >= 0 && u < sites[0] && v < sites[1] && at[u + v * sites[0]] < 0)
			at[u + v * sites[0]] = i;
	}
	double sum_e2 = 0.0, sum_p2 = 0.0;
	long terms = 0, points = 0;
	for (long v = 0; v < sites[1]; v++)
		for (long u = 0; u < sites[0]; u++) {
			idx_t i = at[u + v * sites[0]];
			if (i < 0)
				continue;
			double pi = mean_effective_stress(p, i);
			sum_p2 += pi * pi;
			points++;
			idx_t l = u > 0 ? at[u - 1 + v * sites[0]] : -1, r = u + 1 < sites[0] ? at[u + 1 + v * sites[0]] : -1;
			idx_t b = v > 0 ? at[u + (v - 1) * sites[0]] : -1, t = v + 1 < sites[1] ? at[u + (v + 1) * sites[0]] : -1;
			if (l >= 0 && r >= 0) {
				double e = overshoot(pi, mean_effective_stress(p, l), mean_effective_stress(p, r));
				sum_e2 += e * e, terms++;
			}
			if (b >= 0 && t >= 0) {
				double e = overshoot(pi, mean_effective_stress(p, b), mean_effective_stress(p, t));
				sum_e2 += e * e, terms++;
			}
		}
	free(at);
	if (terms == 0 || !(sum_p2 > 0.0))
		return poro_error_set(err, PORO_EINVAL, "oscillation index: %s",
				      terms == 0 ? "no soil point has two lattice neighbours" :
						   "the mean effective stress is zero");
	*index = sqrt(sum_e2 / (double)terms) / sqrt(sum_p2 / (double)points);
	return PORO_OK;
}
