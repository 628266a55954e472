/*
 * oscillation.c - oscillation index of the mean effective stress or of any point field (definition in
 * oscillation.h).
 *
 * Points are placed on a dense table of lattice sites by their reference positions (site
 * floor((x0 - origin) / spacing) per direction), one point per site, and summed into blocks of
 * block x block sites (one site per block for the point-level index), so each block finds its
 * four neighbours in O(1).
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

enum poro_status oscillation_index_of(const struct case_grid *g, const struct particles *p, double spacing,
				      int block, const double *value, double *index, struct poro_error *err)
{
	*index = 0.0;
	if (!(spacing > 0.0) || block < 1)
		return poro_error_set(err, PORO_EINVAL, "oscillation index: spacing must be positive and the block at "
				      "least one site, got %g and %d", spacing, block);
	long sites[2], blocks[2];
	for (int d = 0; d < 2; d++) {
		sites[d] = (long)ceil(g->extent[d] / spacing - 1e-9);
		blocks[d] = (sites[d] + block - 1) / block;
	}
	const long site_count = sites[0] * sites[1], block_count = blocks[0] * blocks[1];
	char *taken = calloc((size_t)site_count, 1);
	double *sum = calloc((size_t)block_count, sizeof *sum);
	long *count = calloc((size_t)block_count, sizeof *count);
	if (!taken || !sum || !count) {
		free(taken), free(sum), free(count);
		return poro_error_set(err, PORO_ENOMEM, "cannot allocate the oscillation index work space");
	}
	for (idx_t i = 0; i < p->n; i++) {
		long u = (long)floor((p->x0[2 * i] - g->origin[0]) / spacing);
		long v = (long)floor((p->x0[2 * i + 1] - g->origin[1]) / spacing);
		if (u < 0 || v < 0 || u >= sites[0] || v >= sites[1] || taken[u + v * sites[0]])
			continue;
		taken[u + v * sites[0]] = 1;
		long k = u / block + (v / block) * blocks[0];
		sum[k] += value ? value[i] : mean_effective_stress(p, i);
		count[k]++;
	}
	for (long k = 0; k < block_count; k++)
		sum[k] = count[k] ? sum[k] / (double)count[k] : 0.0;   /* now the block means */
	double sum_e2 = 0.0, sum_p2 = 0.0;
	long terms = 0, filled = 0;
	for (long v = 0; v < blocks[1]; v++)
		for (long u = 0; u < blocks[0]; u++) {
			long k = u + v * blocks[0];
			if (!count[k])
				continue;
			sum_p2 += sum[k] * sum[k];
			filled++;
			long l = u > 0 ? k - 1 : -1, r = u + 1 < blocks[0] ? k + 1 : -1;
			long b = v > 0 ? k - blocks[0] : -1, t = v + 1 < blocks[1] ? k + blocks[0] : -1;
			if (l >= 0 && r >= 0 && count[l] && count[r]) {
				double e = overshoot(sum[k], sum[l], sum[r]);
				sum_e2 += e * e, terms++;
			}
			if (b >= 0 && t >= 0 && count[b] && count[t]) {
				double e = overshoot(sum[k], sum[b], sum[t]);
				sum_e2 += e * e, terms++;
			}
		}
	free(taken), free(sum), free(count);
	if (terms == 0 || !(sum_p2 > 0.0))
		return poro_error_set(err, PORO_EINVAL, "oscillation index: %s",
				      terms == 0 ? "no soil point has two lattice neighbours" :
				      value ? "the field is zero" : "the mean effective stress is zero");
	*index = sqrt(sum_e2 / (double)terms) / sqrt(sum_p2 / (double)filled);
	return PORO_OK;
}

enum poro_status oscillation_index_blocks(const struct case_grid *g, const struct particles *p, double spacing,
					  int block, double *index, struct poro_error *err)
{
	return oscillation_index_of(g, p, spacing, block, NULL, index, err);
}

enum poro_status oscillation_index(const struct case_grid *g, const struct particles *p, double spacing,
				   double *index, struct poro_error *err)
{
	return oscillation_index_blocks(g, p, spacing, 1, index, err);
}
