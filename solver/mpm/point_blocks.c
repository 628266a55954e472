/* point_blocks.c - the scatters' block order of a point set (see point_blocks.h). */
#include "point_blocks.h"

#include <assert.h>
#include <stdlib.h>
#include <string.h>

_Static_assert(POINT_BLOCK_NODES >= SHAPE_SUPPORT_MAX - 1, "blocks of one colour would share nodes");
_Static_assert(POINT_BLOCK_COLOURS == 4, "FOR_POINTS_BY_BLOCK's one-block table has four colours");

enum poro_status point_blocks_create(struct point_blocks **out, const struct grid *g, idx_t capacity,
				     struct poro_error *err)
{
	const idx_t B = POINT_BLOCK_NODES;
	struct point_blocks *b = calloc(1, sizeof *b);
	*out = NULL;
	if (b) {
		b->blocks[0] = (g->nodes[0] + B - 1) / B;
		b->blocks[1] = (g->nodes[1] + B - 1) / B;
		b->count = b->blocks[0] * b->blocks[1];
		b->capacity = capacity;
		b->n = -1;
		b->block_of_node = malloc(sizeof(idx_t) * (size_t)g->node_count);
		b->start = malloc(sizeof(idx_t) * (size_t)(b->count + 1));
		b->order = malloc(sizeof(idx_t) * (size_t)(capacity > 0 ? capacity : 1));
	}
	if (!b || !b->block_of_node || !b->start || !b->order) {
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
	for (idx_t j = 0; j < g->nodes[1]; j++)
		for (idx_t i = 0; i < g->nodes[0]; i++) {
			const idx_t bx = i / B, by = j / B, per_row = (b->blocks[0] - bx % 2 + 1) / 2;
			b->block_of_node[grid_node(g, i, j)] = number[by % 2][bx % 2] + (by / 2) * per_row + bx / 2;
		}
	*out = b;
	return PORO_OK;
}

void point_blocks_destroy(struct point_blocks **pb)
{
	struct point_blocks *b = pb ? *pb : NULL;
	if (!b)
		return;
	free(b->block_of_node);
	free(b->start);
	free(b->order);
	free(b);
	*pb = NULL;
}

void point_blocks_sort(struct point_blocks *b, const struct particles *p)
{
	assert(p->n <= b->capacity && p->support <= POINT_BLOCK_NODES + 1);
	idx_t *start = b->start;
	const idx_t *block = b->block_of_node;
	memset(start, 0, sizeof(idx_t) * (size_t)(b->count + 1));
	for (idx_t q = 0; q < p->n; q++)
		start[block[p->node0[q]] + 1]++;
	for (idx_t k = 0; k < b->count; k++)
		start[k + 1] += start[k];
	/* start[k] is block k's first slot; placing a point advances it, to block k + 1's first */
	for (idx_t q = 0; q < p->n; q++)
		b->order[start[block[p->node0[q]]]++] = q;
	memmove(start + 1, start, sizeof(idx_t) * (size_t)b->count);
	start[0] = 0;
	b->n = p->n;
}
