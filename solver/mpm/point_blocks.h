/*
 * point_blocks.h - the order in which a particle-to-grid scatter visits the points of a set, so
 * that it runs on any number of threads without races and gives the same sums, bit for bit,
 * whatever that number.
 *
 * A scatter adds each point's share into the S x S nodes of its support (S = 2, 3 or 4 per
 * direction), and neighbouring points share nodes. The points are binned by the lower-left node
 * of their support, node0 (the shape cache, particles.h), into square blocks of B x B node0
 * values, B = POINT_BLOCK_NODES, and the blocks are coloured in a 2x2 pattern,
 *     colour = (bx mod 2) + 2 (by mod 2)   for the block (bx, by).
 * A point of block bx reaches the nodes bx B .. bx B + (B - 1) + (S - 1) along x; the next block
 * of its colour begins at (bx + 2) B, so two blocks of one colour share no node when B >= S - 1
 * (B = 8 leaves room for the cubic B-spline's S = 4 and a margin of B - S + 1 nodes between them).
 * A scatter takes the four colours one after another, the blocks of one colour in parallel, and
 * the points of a block one after another in ascending index. A node is then reached by at most
 * one block of each colour, and receives its contributions colour by colour, and within a colour
 * in index order: an order fixed by the points' node0 and indices, which neither the thread count
 * nor the schedule changes (one thread visits the same order). The order is not the plain index
 * order of a serial loop, so results differ from a serial scatter's in the last bits.
 *
 * Why this and not the alternatives. Per-thread copies of the nodal arrays summed afterwards
 * make each node's sum depend on the thread count, or, with a fixed number of copies, multiply
 * the memory traffic of a phase that is bound by it (docs/performance.md). Atomic additions make
 * the order depend on timing. Letting each node gather its points in index order needs a list of
 * S^2 (node, point) pairs a point, sorted every step: nine times the work of this binning. The
 * binning is a counting sort by block, O(n) in two passes over node0, into arrays sized when the
 * set is made (STYLE rule 3); the scatter loops themselves are unchanged, only the order of q.
 * Blocks of B = 8 keep a block's nodes in the first-level cache and still give a 25 m x 10 m
 * grid of 0.1 m cells 100 blocks a colour to share among threads; docs/performance.md has the
 * block sizes measured.
 *
 * Validity. shape_evaluate sorts a set that has blocks each time it fills the shape cache, so
 * the order always matches node0. A set without blocks, or whose blocks are stale (a double-point
 * water point was removed since: particles_remove), is scattered serially in index order. The
 * single-point water set rides on the soil set's shape cache and uses its blocks.
 */
#ifndef PORO_POINT_BLOCKS_H
#define PORO_POINT_BLOCKS_H

#include "grid.h"

#define POINT_BLOCK_NODES 8     /* B: node0 values per block side; >= SHAPE_SUPPORT_MAX - 1 */
#define POINT_BLOCK_COLOURS 4   /* the 2x2 pattern; 3-D would take 8 */

struct point_blocks {
	idx_t blocks[2];          /* blocks per direction: ceil(nodes / B) */
	idx_t count;              /* blocks[0] blocks[1] */
	idx_t colour_start[POINT_BLOCK_COLOURS + 1]; /* the blocks of colour c are numbered
						       colour_start[c] .. colour_start[c + 1] - 1 */
	idx_t *block_of_node;     /* [node_count] the number of the block a point with this node0
				     falls in */
	idx_t *start;             /* [count + 1] the points of block k are order[start[k]] ..
				     order[start[k + 1] - 1] */
	idx_t *order;             /* [capacity] point indices, block by block, ascending in a block */
	idx_t capacity;           /* points the order has room for */
	idx_t n;                  /* points sorted at the last point_blocks_sort, -1 when stale */
};

/* Allocates the blocks of grid g for a set of up to capacity points; nothing is sorted yet.
 * Returns PORO_ENOMEM with *out NULL on failure. Free with point_blocks_destroy. */
enum poro_status point_blocks_create(struct point_blocks **out, const struct grid *g, idx_t capacity,
				     struct poro_error *err);

/* Frees b (NULL is fine) and clears the pointer. */
void point_blocks_destroy(struct point_blocks **b);

/* Sorts p's points into the blocks by their node0 (a stable counting sort: ascending index within
 * a block). p->n must not exceed the capacity, and p->support must be at most B + 1. */
void point_blocks_sort(struct point_blocks *b, const struct particles *p);

/* The blocks of p if they are sorted for its current shape cache, else NULL. */
static inline const struct point_blocks *point_blocks_of(const struct particles *p)
{
	const struct point_blocks *b = (p->alias_of ? p->alias_of : p)->blocks;
	return b && b->n == p->n ? b : NULL;
}

/* Runs the statement block that follows (__VA_ARGS__) for every point q of p in the scatter order
 * of the file comment: the colours in turn, the blocks of a colour shared among the threads, the
 * points of a block in index order. The body may write the nodes of q's support and q's own
 * per-point values; anything else it writes is shared among the threads and races (sums over the
 * points belong after the loop). `continue` skips to the next point. Without sorted blocks
 * (point_blocks_of) the points run on the calling thread in index order. */
#define FOR_POINTS_BY_BLOCK(p, q, ...)                                                           \
	do {                                                                                     \
		const struct point_blocks *pb_ = point_blocks_of(p);                             \
		const idx_t whole_[2] = {0, (p)->n}, one_block_[POINT_BLOCK_COLOURS + 1] = {0, 1, 1, 1, 1}; \
		const idx_t *colours_ = pb_ ? pb_->colour_start : one_block_;                     \
		const idx_t *start_ = pb_ ? pb_->start : whole_, *order_ = pb_ ? pb_->order : NULL; \
		_Pragma("omp parallel if (pb_ != 0)")                                            \
		for (int c_ = 0; c_ < POINT_BLOCK_COLOURS; c_++) {                               \
			_Pragma("omp for schedule(dynamic, 1)")                                  \
			for (idx_t k_ = colours_[c_]; k_ < colours_[c_ + 1]; k_++)               \
				for (idx_t r_ = start_[k_]; r_ < start_[k_ + 1]; r_++) {         \
					const idx_t q = order_ ? order_[r_] : r_;                \
					__VA_ARGS__                                              \
				}                                                                \
		}                                                                                \
	} while (0)

#endif
