/* point_blocks.c - the scatters' block order of a point set (see point_blocks.h). */
#include "point_blocks.h"

#include <assert.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

_Static_assert(POINT_BLOCK_COLOURS == 4, "FOR_POINTS_BY_BLOCK's one-block table has four colours");

enum poro_status point_blocks_create(struct point_blocks **out, const struct grid *g, idx_t capacity,
				     const idx_t size[2], struct poro_error *err)
{
	assert(size[0] >= 2 * SHAPE_SUPPORT_MAX - 2 && size[1] >= 2 * SHAPE_SUPPORT_MAX - 2);
	struct point_blocks *b = calloc(1, sizeof *b);
	*out = NULL;
	if (b) {
		b->size[0] = size[0], b->size[1] = size[1];
		for (int d = 0; d < 2; d++) {
			b->origin[d] = g->origin[d];
			b->cells[d] = g->cells[d];
			b->blocks[d] = (g->cells[d] + b->size[d] - 1) / b->size[d];
		}
		b->inv_h = g->inv_h;
		b->count = b->blocks[0] * b->blocks[1];
		b->capacity = capacity;
		b->n = -1;
		const int procs = omp_get_num_procs();
		b->ranges_max = procs < 1 ? 1 : procs > POINT_BLOCK_RANGES_MAX ? POINT_BLOCK_RANGES_MAX : procs;
		b->block_of_cell = malloc(sizeof(idx_t) * (size_t)g->cell_count);
		b->start = malloc(sizeof(idx_t) * (size_t)(b->count + 1));
		b->order = malloc(sizeof(idx_t) * (size_t)(capacity > 0 ? capacity : 1));
		b->key = malloc(sizeof(idx_t) * (size_t)(capacity > 0 ? capacity : 1));
		b->range_count = malloc(sizeof(idx_t) * (size_t)b->ranges_max * (size_t)b->count);
	}
	if (!b || !b->block_of_cell || !b->start || !b->order || !b->key || !b->range_count) {
		point_blocks_destroy(&b);
		return poro_error_set(err, PORO_ENOMEM, "cannot allocate the scatter blocks of %ld points",
				      (long)capacity);
	}
	/* number the blocks colour by colour, row by row within a colour */
	idx_t number[2][2] = {{0}}, next = 0;
	for (int c = 0; c < POINT_BLOCK_COLOURS; c++) {
		b->colour_start[c] = next;
		const int cx = c % 2, cy = c / 2;
		number[cy][cx] = next;
		next += ((b->blocks[0] - cx + 1) / 2) * ((b->blocks[1] - cy + 1) / 2);
	}
	b->colour_start[POINT_BLOCK_COLOURS] = next;
	assert(next == b->count);
	for (idx_t j = 0; j < g->cells[1]; j++)
		for (idx_t i = 0; i < g->cells[0]; i++) {
			const idx_t bx = i / b->size[0], by = j / b->size[1], per_row = (b->blocks[0] - bx % 2 + 1) / 2;
			b->block_of_cell[i + j * g->cells[0]] = number[by % 2][bx % 2] + (by / 2) * per_row + bx / 2;
		}
	*out = b;
	return PORO_OK;
}

void point_blocks_destroy(struct point_blocks **pb)
{
	struct point_blocks *b = pb ? *pb : NULL;
	if (!b)
		return;
	free(b->block_of_cell);
	free(b->start);
	free(b->order);
	free(b->key);
	free(b->range_count);
	free(b);
	*pb = NULL;
}

/* The block of the cell that holds x (grid_cell_of's cell: a point on the far edge belongs to the
 * last cell). x lies in the grid: shape_evaluate has just placed it. */
static inline idx_t block_of(const struct point_blocks *b, const double *x)
{
	idx_t c[2];
	for (int d = 0; d < 2; d++) {
		const idx_t i = (idx_t)((x[d] - b->origin[d]) * b->inv_h);
		c[d] = i < 0 ? 0 : i >= b->cells[d] ? b->cells[d] - 1 : i;
	}
	return b->block_of_cell[c[0] + c[1] * b->cells[0]];
}

void point_blocks_sort(struct point_blocks *b, const struct particles *p)
{
	assert(p->n <= b->capacity && 2 * p->support - 2 <= b->size[0] && 2 * p->support - 2 <= b->size[1]);
	const idx_t n = p->n, count = b->count;
	const int threads = omp_get_max_threads();
	#pragma omp parallel num_threads(threads < b->ranges_max ? threads : b->ranges_max)
	{
		const int T = omp_get_num_threads(), t = omp_get_thread_num();
		const idx_t first = (idx_t)((int64_t)n * t / T), end = (idx_t)((int64_t)n * (t + 1) / T);
		idx_t *next = b->range_count + (size_t)t * (size_t)count;
		memset(next, 0, sizeof(idx_t) * (size_t)count);
		/* consecutive points mostly share a block: counting a run in a register instead of
		 * incrementing next[k] for each point keeps the loop off a store-to-load chain */
		idx_t current = first < end ? block_of(b, p->x + 2 * first) : 0, run = 0;
		for (idx_t q = first; q < end; q++) {
			const idx_t k = b->key[q] = block_of(b, p->x + 2 * q);
			if (k != current)
				next[current] += run, current = k, run = 0;
			run++;
		}
		next[current] += run;
		#pragma omp barrier
		#pragma omp single
		{   /* block by block, range by range: each range's first slot in each block */
			idx_t slot = 0;
			for (idx_t k = 0; k < count; k++) {
				b->start[k] = slot;
				for (int r = 0; r < T; r++) {
					idx_t *c = b->range_count + (size_t)r * (size_t)count + k;
					const idx_t points = *c;
					*c = slot;
					slot += points;
				}
			}
			b->start[count] = slot;
		}
		current = first < end ? b->key[first] : 0;
		idx_t slot = next[current];
		for (idx_t q = first; q < end; q++) {
			const idx_t k = b->key[q];
			if (k != current)
				next[current] = slot, current = k, slot = next[k];
			b->order[slot++] = q;
		}
	}
	b->n = n;
}
