/*
 * point_blocks_test.c - the scatters' block order (solver/mpm/point_blocks.c) against what the
 * parallel scatters rest on, for every shape kind (linear, quadratic and cubic B-splines, uGIMP)
 * on random clouds with fixed seeds, with a simulation's blocks (strips across the grid) and with
 * blocks of 6 x 6 cells (the least the cubic B-spline allows) and 7 x 9, over grids whose block
 * counts are odd and even:
 *   - the order is a permutation of the points, each block's points in ascending index, each
 *     point in the block of the cell that holds it (grid_cell_of), and the same when one, two or
 *     three threads sort;
 *   - no node is reached, through the support of the shape cache, by the points of two blocks of
 *     one colour (brute force over every point's S x S support), so the blocks of a colour can
 *     run at once;
 *   - FOR_POINTS_BY_BLOCK visits every point once, in that order, on one thread and on two;
 *   - the blocks go stale when a point is removed (the scatters then run serially in index
 *     order), and a single-point water set riding on a soil set uses the soil set's blocks.
 */
#include <omp.h>

#include "../harness.h"
#include "point_blocks.h"
#include "shape.h"

#define CLOUD_POINTS 20000

/* 1 if no node is reached by the points of two blocks of one colour. */
static int colours_disjoint(const struct grid *g, const struct particles *p, const struct point_blocks *b)
{
	idx_t *owner = malloc(sizeof(idx_t) * (size_t)g->node_count);
	int ok = 1;
	for (int c = 0; c < POINT_BLOCK_COLOURS && ok; c++) {
		for (idx_t I = 0; I < g->node_count; I++)
			owner[I] = -1;
		for (idx_t k = b->colour_start[c]; k < b->colour_start[c + 1]; k++)
			for (idx_t r = b->start[k]; r < b->start[k + 1]; r++) {
				const idx_t q = b->order[r];
				for (int j = 0; j < p->support; j++)
					for (int i = 0; i < p->support; i++) {
						const idx_t I = p->node0[q] + i + j * g->nodes[0];
						ok &= owner[I] < 0 || owner[I] == k;
						owner[I] = k;
					}
			}
	}
	free(owner);
	return ok;
}

/* The block of the cell that holds point q. */
static idx_t block_of_point(const struct grid *g, const struct point_blocks *b, const struct particles *p, idx_t q)
{
	return b->block_of_cell[grid_cell_of(g, p->x + 2 * q)];
}

/* 1 if b's order holds every point of p once, ascending within a block, in the block of its cell. */
static int order_is_sorted(const struct grid *g, const struct particles *p, const struct point_blocks *b)
{
	char *seen = calloc((size_t)p->n, 1);
	int ok = b->start[0] == 0 && b->start[b->count] == p->n;
	for (idx_t k = 0; k < b->count && ok; k++)
		for (idx_t r = b->start[k]; r < b->start[k + 1] && ok; r++) {
			const idx_t q = b->order[r];
			ok = q >= 0 && q < p->n && !seen[q] && block_of_point(g, b, p, q) == k &&
			     (r == b->start[k] || b->order[r - 1] < q);
			seen[q] = 1;
		}
	free(seen);
	return ok;
}

/* The position in the visiting order of every point, by FOR_POINTS_BY_BLOCK on `threads` threads:
 * each point's slot gets its rank within its block plus the block's start, so the result is the
 * inverse of b->order when every point is visited once in its block's order. */
static void visit(const struct grid *g, const struct particles *p, int threads, idx_t *rank, idx_t *visits)
{
	const struct point_blocks *b = point_blocks_of(p);
	const int before = omp_get_max_threads();
	omp_set_num_threads(threads);
	memset(visits, 0, sizeof(idx_t) * (size_t)p->n);
	FOR_POINTS_BY_BLOCK(p, q, {
		const idx_t k = block_of_point(g, b, p, q);
		idx_t r = b->start[k];
		while (b->order[r] != q)
			r++;
		rank[q] = r;
		visits[q]++;
	});
	omp_set_num_threads(before);
}

static void check_kind(enum case_shape kind, const char *label, idx_t cells_x, idx_t cells_y, const idx_t size[2])
{
	const double h = 0.0389;
	struct case_grid spec = {.origin = {2.113, -0.587}, .extent = {cells_x * h, cells_y * h}, .cell_size = h};
	struct grid g;
	struct particles p;
	char name[160], label_size[96];
	grid_init(&g, &spec, NULL);
	particles_init(&p, CLOUD_POINTS, 0, NULL);
	if (size)
		point_blocks_create(&p.blocks, &g, p.n, size, NULL);
	else
		particles_add_blocks(&p, &g, NULL);
	snprintf(label_size, sizeof label_size, "%s_%ldx%ld_blocks_%ldx%ld", label, (long)cells_x, (long)cells_y,
		 (long)p.blocks->size[0], (long)p.blocks->size[1]);
	label = label_size;
	for (idx_t q = 0; q < p.n; q++) {
		const double edge = 1.1 * h;
		p.x[2 * q] = spec.origin[0] + (q % 5 == 0 ? rnd(0, edge) : q % 5 == 1 ? spec.extent[0] - rnd(0, edge) :
								       rnd(0, spec.extent[0]));
		p.x[2 * q + 1] = spec.origin[1] + (q % 7 == 2 ? rnd(0, edge) : rnd(0, spec.extent[1]));
		p.volume0[q] = rnd(0.2, 0.9) * h * h;   /* uGIMP's domains */
	}
	const int ok = shape_evaluate(&g, kind, &p, "test", NULL) == PORO_OK;
	const struct point_blocks *b = point_blocks_of(&p);
	snprintf(name, sizeof name, "%s_order_sorted_by_block", label);
	CHECK(ok && b && order_is_sorted(&g, &p, b), name, "evaluated %d, blocks %s", ok, b ? "sorted wrongly" : "stale");
	idx_t *sorted = malloc(sizeof(idx_t) * CLOUD_POINTS);
	int same = b != NULL;
	for (int threads = 1; threads <= 3 && same; threads++) {
		const int before = omp_get_max_threads();
		omp_set_num_threads(threads);
		point_blocks_sort(p.blocks, &p);
		omp_set_num_threads(before);
		if (threads == 1)
			memcpy(sorted, b->order, sizeof(idx_t) * CLOUD_POINTS);
		same = order_is_sorted(&g, &p, b) && !memcmp(sorted, b->order, sizeof(idx_t) * CLOUD_POINTS);
	}
	free(sorted);
	snprintf(name, sizeof name, "%s_order_same_sorted_on_one_two_and_three_threads", label);
	CHECK(same, name, "the order differs, or is not sorted");
	snprintf(name, sizeof name, "%s_blocks_of_a_colour_share_no_node", label);
	CHECK(b && colours_disjoint(&g, &p, b), name, "a node is reached by two blocks of one colour");

	idx_t *rank = malloc(sizeof(idx_t) * CLOUD_POINTS), *visits = malloc(sizeof(idx_t) * CLOUD_POINTS);
	for (int threads = 1; threads <= 2 && b; threads++) {
		visit(&g, &p, threads, rank, visits);
		idx_t wrong = 0;
		for (idx_t q = 0; q < p.n; q++)
			wrong += visits[q] != 1 || b->order[rank[q]] != q;
		snprintf(name, sizeof name, "%s_every_point_visited_once_on_%d_thread%s", label, threads,
			 threads > 1 ? "s" : "");
		CHECK(wrong == 0, name, "%ld points visited other than once", (long)wrong);
	}
	free(rank);
	free(visits);
	particles_release(&p);
}

/* A removed point leaves the blocks stale until the next shape evaluation; a single-point water set
 * (particles_init_alias) uses the soil set's blocks. */
static void check_stale_and_alias(void)
{
	struct case_grid spec = {.origin = {0.0, 0.0}, .extent = {23 * 0.1, 19 * 0.1}, .cell_size = 0.1};
	struct grid g;
	struct particles soil, water;
	grid_init(&g, &spec, NULL);
	particles_init(&soil, 500, 0, NULL);
	particles_init(&water, 500, 0, NULL);
	particles_add_blocks(&soil, &g, NULL);
	particles_add_blocks(&water, &g, NULL);
	for (idx_t q = 0; q < soil.n; q++) {
		soil.x[2 * q] = water.x[2 * q] = rnd(0, spec.extent[0]);
		soil.x[2 * q + 1] = water.x[2 * q + 1] = rnd(0, spec.extent[1]);
	}
	shape_evaluate(&g, SHAPE_QUADRATIC_BSPLINE, &water, "water", NULL);
	const int sorted = point_blocks_of(&water) != NULL;
	particles_remove(&water, 17);
	const int stale = point_blocks_of(&water) == NULL;
	shape_evaluate(&g, SHAPE_QUADRATIC_BSPLINE, &water, "water", NULL);
	CHECK(sorted && stale && point_blocks_of(&water) && order_is_sorted(&g, &water, point_blocks_of(&water)),
	      "point_blocks_stale_after_a_removal_until_the_next_shape_evaluation",
	      "sorted %d, stale after the removal %d, sorted again %d", sorted, stale, point_blocks_of(&water) != NULL);

	struct particles riding;
	shape_evaluate(&g, SHAPE_QUADRATIC_BSPLINE, &soil, "soil", NULL);
	particles_init_alias(&riding, &soil, NULL);
	CHECK(riding.blocks == NULL && point_blocks_of(&riding) == soil.blocks && soil.blocks,
	      "point_blocks_single_point_water_uses_the_soil_blocks", "own %p, used %p, soil's %p",
	      (void *)riding.blocks, (void *)point_blocks_of(&riding), (void *)soil.blocks);
	particles_release(&riding);
	particles_release(&soil);
	particles_release(&water);
}

int main(void)
{
	static const struct { enum case_shape kind; const char *label; } kinds[] = {
		{SHAPE_LINEAR, "linear"}, {SHAPE_QUADRATIC_BSPLINE, "quadratic_bspline"},
		{SHAPE_CUBIC_BSPLINE, "cubic_bspline"}, {SHAPE_GIMP, "gimp"}};
	static const idx_t smallest[2] = {6, 6}, uneven[2] = {7, 9};
	for (size_t k = 0; k < sizeof kinds / sizeof kinds[0]; k++) {
		check_kind(kinds[k].kind, kinds[k].label, 263, 27, NULL);     /* strips: 1 x 5 blocks */
		check_kind(kinds[k].kind, kinds[k].label, 41, 27, smallest);  /* 7 x 5 */
		check_kind(kinds[k].kind, kinds[k].label, 38, 16, uneven);    /* 6 x 2 */
	}
	check_stale_and_alias();
	HARNESS_EXIT();
}
