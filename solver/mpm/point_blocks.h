/*
 * point_blocks.h - the order in which a particle-to-grid scatter visits the points of a set, so
 * that it runs on any number of threads without races and gives the same sums, bit for bit,
 * whatever that number.
 *
 * A scatter adds each point's share into the S x S nodes of its support (S = 2, 3 or 4 per
 * direction), and neighbouring points share nodes. After the shape functions of a step are
 * evaluated, the points are binned by the cell that holds them into blocks of Bx x By cells, and
 * the blocks are coloured in a 2x2 pattern,
 *     colour = (bx mod 2) + 2 (by mod 2)   for the block (bx, by).
 * A point lies inside its support (the weights are non-negative and reproduce linear fields, so x
 * is the weighted mean of its support nodes): along x its cell i and its first support node i0
 * satisfy i0 <= i <= i0 + S - 1, so a point of block bx reaches the nodes bx Bx - (S - 1) ..
 * bx Bx + Bx - 1 + (S - 1). The next block of its colour, bx + 2, reaches down to
 * (bx + 2) Bx - (S - 1) only, so two blocks of one colour share no node when Bx >= 2 S - 2, and
 * likewise along y (the blocks' sizes allow the cubic B-spline, S = 4). A scatter takes the four
 * colours one after another, the blocks of one colour in parallel, and the points of a block one
 * after another in ascending index. A node is then reached by at most one block of each colour,
 * and receives its contributions colour by colour, and within a colour in index order: an order
 * fixed by the points' positions and indices, which neither the thread count nor the schedule
 * changes (one thread visits the same order). It is not the plain index order of a serial loop,
 * so results differ from a serial scatter's in the last bits.
 *
 * Why this and not the alternatives. Per-thread copies of the nodal arrays summed afterwards
 * make each node's sum depend on the thread count, or, with a fixed number of copies, multiply
 * the memory traffic of phases that are bound by it (docs/performance.md). Atomic additions make
 * the order depend on timing. Letting each node gather its points in index order needs a list of
 * S^2 (node, point) pairs a point, sorted every step: nine times the work of this binning. The
 * binning is a stable counting sort by block, O(n) in two passes that the threads share, into
 * arrays sized when the set is made (STYLE rule 3); the scatter loops themselves are unchanged,
 * only the order of q.
 *
 * Why blocks of cells, and strips across the grid. The scatters stream the points' arrays and
 * are bound by memory, and points are seeded cell row by cell row, a cell's points together
 * (sim.c), so a block's points are runs of consecutive indices, one per cell row Bx cells long.
 * Every run restarts the streams of the point arrays and of the node rows it writes, which costs
 * a memory latency each. On the benchmark block (bench/solver_bench.c, one thread, CPU time, the
 * serial index order = 1): square blocks of 8 x 8 node0 values took 1.6 times as long in
 * particle-to-grid, 2.1 in the predictors' internal forces; binned by node0, the quadratic
 * B-spline also puts the lower and upper halves of a cell row into different rows of node0, so
 * every block boundary splits cell rows into alternating pairs of points. Blocks of 64 x 6 cells
 * took 1.13 and 1.25, strips across the grid (here Bx = 1024) 1.05 and 1.05, the whole step 1.03
 * (docs/performance.md, "Parallel scatters"). Strips 6 cells high, the least the cubic B-spline
 * allows, give the 25 m x 10 m benchmark grid of 0.1 m cells 17 strips, 9 and 8 a colour, which
 * bounds the threads that can share a scatter on that grid; a grid wider than Bx, or a smaller Bx
 * for many threads on a small grid, uses the 2x2 colouring as it stands.
 *
 * Validity. shape_evaluate sorts a set that has blocks each time it fills the shape cache, from
 * the same positions, so the order always matches node0. A set without blocks, or whose blocks
 * are stale (a double-point water point was removed since: particles_remove), is scattered
 * serially in index order. The single-point water set rides on the soil set's shape cache and
 * uses its blocks.
 */
#ifndef PORO_POINT_BLOCKS_H
#define PORO_POINT_BLOCKS_H

#include "grid.h"

#define POINT_BLOCK_CELLS_X 1024  /* Bx of a simulation's sets (particles_add_blocks): cells per
				     block along x, wider than the grids run so far (strips) */
#define POINT_BLOCK_CELLS_Y 6     /* By: along y, 2 SHAPE_SUPPORT_MAX - 2 */
#define POINT_BLOCK_COLOURS 4     /* the 2x2 pattern; 3-D would take 8 */
#define POINT_BLOCK_RANGES_MAX 64 /* threads the sort uses at most */

struct point_blocks {
	idx_t size[2];            /* cells per block along x and y */
	idx_t blocks[2];          /* blocks per direction: ceil(cells / size) */
	idx_t count;              /* blocks[0] blocks[1] */
	idx_t colour_start[POINT_BLOCK_COLOURS + 1]; /* the blocks of colour c are numbered
						       colour_start[c] .. colour_start[c + 1] - 1 */
	double origin[2], inv_h;  /* the grid's origin, m, and inverse cell size, 1/m */
	idx_t cells[2];           /* the grid's cells per direction */
	idx_t *block_of_cell;     /* [cell_count] the number of the block that holds the cell */
	idx_t *start;             /* [count + 1] the points of block k are order[start[k]] ..
				     order[start[k + 1] - 1] */
	idx_t *order;             /* [capacity] point indices, block by block, ascending in a block */
	idx_t *key;               /* [capacity] scratch of the sort: each point's block */
	idx_t capacity;           /* points the order has room for */
	idx_t n;                  /* points sorted at the last point_blocks_sort, -1 when stale */
	int ranges_max;           /* index ranges the sort counts in parallel, one a thread: the
				     machine's processors at create, at most POINT_BLOCK_RANGES_MAX */
	idx_t *range_count;       /* [ranges_max count] each range's points in each block, then the
				     slot of the range's next point in the block */
};

/* Allocates the blocks of size[0] x size[1] cells of grid g for a set of up to capacity points
 * (each size at least 2 SHAPE_SUPPORT_MAX - 2); nothing is sorted yet. Returns PORO_ENOMEM with
 * *out NULL on failure. Free with point_blocks_destroy. */
enum poro_status point_blocks_create(struct point_blocks **out, const struct grid *g, idx_t capacity,
				     const idx_t size[2], struct poro_error *err);

/* Frees b (NULL is fine) and clears the pointer. */
void point_blocks_destroy(struct point_blocks **b);

/* Sorts p's points into the blocks of the cells that hold them (a stable counting sort: ascending
 * index within a block), on the calling team's threads: each counts a range of indices, and the
 * ranges' points go into each block range after range, so the order is the one a serial stable
 * sort gives, whatever the number of threads. Every point must lie in the grid (shape_evaluate
 * has placed it), p->n must not exceed the capacity, and 2 p->support - 2 must not exceed a
 * block's size. */
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
