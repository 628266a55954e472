/*
 * oscillation.c - oscillation index of the mean effective stress or of any point field, and the
 * two-cell pattern index (definitions in oscillation.h).
 *
 * Points are placed on a dense table of lattice sites by their reference positions (site
 * floor((x0 - origin) / spacing) per direction), one point per site, and summed into blocks of
 * block x block sites (one site per block for the point-level index), so each block finds its
 * four neighbours in O(1). The pattern index lays the blocks at every offset of their lattice over
 * the same table of sites.
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

/* The points' values on their lattice sites: value[site], taken[site] = 1 where a point lies (the
 * first point of a site; later ones are left out). */
struct lattice {
	long sites[2];
	char *taken;
	double *value;
};

static void lattice_release(struct lattice *l)
{
	free(l->taken);
	free(l->value);
}

static enum poro_status lattice_fill(struct lattice *l, const struct case_grid *g, const struct particles *p,
				     double spacing, int block, const double *value, struct poro_error *err)
{
	*l = (struct lattice){0};
	if (!(spacing > 0.0) || block < 1)
		return poro_error_set(err, PORO_EINVAL, "oscillation index: spacing must be positive and the block at "
				      "least one site, got %g and %d", spacing, block);
	for (int d = 0; d < 2; d++)
		l->sites[d] = (long)ceil(g->extent[d] / spacing - 1e-9);
	const size_t count = (size_t)(l->sites[0] * l->sites[1]);
	l->taken = calloc(count ? count : 1, 1);
	l->value = calloc(count ? count : 1, sizeof *l->value);
	if (!l->taken || !l->value) {
		lattice_release(l);
		return poro_error_set(err, PORO_ENOMEM, "cannot allocate the oscillation index work space");
	}
	for (idx_t i = 0; i < p->n; i++) {
		long u = (long)floor((p->x0[2 * i] - g->origin[0]) / spacing);
		long v = (long)floor((p->x0[2 * i + 1] - g->origin[1]) / spacing);
		if (u < 0 || v < 0 || u >= l->sites[0] || v >= l->sites[1] || l->taken[u + v * l->sites[0]])
			continue;
		l->taken[u + v * l->sites[0]] = 1;
		l->value[u + v * l->sites[0]] = value ? value[i] : mean_effective_stress(p, i);
	}
	return PORO_OK;
}

/* The sums of one placement of the blocks: overshoots squared and their count, block means squared
 * and the blocks counted. */
struct block_sums {
	double sum_e2, sum_p2;
	long terms, filled;
};

/* Blocks of block x block sites, site (u, v) in block ((u + shift[0]) / block, (v + shift[1]) /
 * block); a block counts when it holds at least `need` points. mean and count: work space of
 * (sites[d] / block + 2) per direction. */
static struct block_sums block_sums(const struct lattice *l, int block, const int shift[2], long need, double *mean,
				    long *count)
{
	long blocks[2];
	for (int d = 0; d < 2; d++)
		blocks[d] = (l->sites[d] + shift[d] + block - 1) / block;
	const long block_count = blocks[0] * blocks[1];
	for (long k = 0; k < block_count; k++)
		mean[k] = 0.0, count[k] = 0;
	for (long v = 0; v < l->sites[1]; v++)
		for (long u = 0; u < l->sites[0]; u++)
			if (l->taken[u + v * l->sites[0]]) {
				long k = (u + shift[0]) / block + ((v + shift[1]) / block) * blocks[0];
				mean[k] += l->value[u + v * l->sites[0]];
				count[k]++;
			}
	for (long k = 0; k < block_count; k++) {
		mean[k] = count[k] ? mean[k] / (double)count[k] : 0.0;
		if (count[k] < need)
			count[k] = 0;   /* not counted: neither judged nor a neighbour */
	}
	struct block_sums s = {0};
	for (long v = 0; v < blocks[1]; v++)
		for (long u = 0; u < blocks[0]; u++) {
			long k = u + v * blocks[0];
			if (!count[k])
				continue;
			s.sum_p2 += mean[k] * mean[k];
			s.filled++;
			long a = u > 0 ? k - 1 : -1, b = u + 1 < blocks[0] ? k + 1 : -1;
			long c = v > 0 ? k - blocks[0] : -1, d = v + 1 < blocks[1] ? k + blocks[0] : -1;
			if (a >= 0 && b >= 0 && count[a] && count[b]) {
				double e = overshoot(mean[k], mean[a], mean[b]);
				s.sum_e2 += e * e, s.terms++;
			}
			if (c >= 0 && d >= 0 && count[c] && count[d]) {
				double e = overshoot(mean[k], mean[c], mean[d]);
				s.sum_e2 += e * e, s.terms++;
			}
		}
	return s;
}

/* The index of one placement, PORO_EINVAL where it is undefined. */
static enum poro_status index_of(const struct block_sums *s, const double *value, double *index,
				 struct poro_error *err)
{
	if (s->terms == 0 || !(s->sum_p2 > 0.0))
		return poro_error_set(err, PORO_EINVAL, "oscillation index: %s",
				      s->terms == 0 ? "no soil point has two lattice neighbours" :
				      value ? "the field is zero" : "the mean effective stress is zero");
	*index = sqrt(s->sum_e2 / (double)s->terms) / sqrt(s->sum_p2 / (double)s->filled);
	return PORO_OK;
}

/* The lattice of the points and work space for the blocks of any placement. */
struct work {
	struct lattice l;
	double *mean;
	long *count;
};

static void work_release(struct work *w)
{
	free(w->mean);
	free(w->count);
	lattice_release(&w->l);
}

static enum poro_status work_init(struct work *w, const struct case_grid *g, const struct particles *p,
				  double spacing, int block, const double *value, struct poro_error *err)
{
	w->mean = NULL, w->count = NULL;
	enum poro_status st = lattice_fill(&w->l, g, p, spacing, block, value, err);
	if (st)
		return st;
	const size_t n = (size_t)((w->l.sites[0] / block + 2) * (w->l.sites[1] / block + 2));
	w->mean = malloc(n * sizeof *w->mean);
	w->count = malloc(n * sizeof *w->count);
	if (w->mean && w->count)
		return PORO_OK;
	work_release(w);
	return poro_error_set(err, PORO_ENOMEM, "cannot allocate the oscillation index work space");
}

enum poro_status oscillation_index_of(const struct case_grid *g, const struct particles *p, double spacing,
				      int block, const double *value, double *index, struct poro_error *err)
{
	*index = 0.0;
	struct work w;
	enum poro_status st = work_init(&w, g, p, spacing, block, value, err);
	if (st)
		return st;
	const struct block_sums s = block_sums(&w.l, block, (const int[2]){0, 0}, 1, w.mean, w.count);
	st = index_of(&s, value, index, err);
	work_release(&w);
	return st;
}

enum poro_status oscillation_index_pattern(const struct case_grid *g, const struct particles *p, double spacing,
					   int block, const double *value, double *index, struct poro_error *err)
{
	*index = 0.0;
	struct work w;
	enum poro_status st = work_init(&w, g, p, spacing, block, value, err);
	if (st)
		return st;
	int defined = 0;
	struct poro_error undefined = {0};
	for (int sv = 0; sv < block; sv++)
		for (int su = 0; su < block; su++) {
			const struct block_sums s = block_sums(&w.l, block, (const int[2]){su, sv}, (long)block * block,
							       w.mean, w.count);
			double placed = 0.0;
			if (index_of(&s, value, &placed, &undefined))
				continue;   /* this placement has no full block between two others */
			*index = defined ? fmax(*index, placed) : placed;
			defined = 1;
		}
	work_release(&w);
	if (defined)
		return PORO_OK;
	*err = undefined;   /* the last placement's reason */
	return undefined.code;
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
