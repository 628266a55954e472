/*
 * oscillation.h - the oscillation index of the soil's mean effective stress (or of any point field,
 * such as the pore pressure): a measure of the
 * point-to-point stress noise that volumetric locking leaves (000 §4.4.2, App. A, Fig. 12), for
 * tests and reports; and the two-cell pattern index, which finds a pattern of period two cells
 * whatever its phase against the cells.
 *
 * Definition (docs/numerics.md). Points are neighbours when their reference positions x0 are one
 * seeding spacing apart along x or along y (the lattice sim.c seeds). With p'_i =
 * (sigma'_xx + sigma'_yy + sigma'_zz) / 3, each point i that has both neighbours a, b along a
 * direction contributes its overshoot
 *     e = max(0, p'_i - max(p'_a, p'_b), min(p'_a, p'_b) - p'_i),
 * the amount by which it sticks out of its neighbours' range, and
 *     index = sqrt(mean e^2) / sqrt(mean_i p'_i^2).
 * A field that is monotone along every lattice line scores 0 however coarse: smooth fields and the
 * piecewise-constant fields of patch averaging (Eq. 83) alike, apart from their true extrema
 * (O(h^2)). A checkerboard of amplitude A on a mean P scores about 2 A / P. The index measures
 * noise, not resolution.
 *
 * At the scale of cells. A field averaged cell-wise (App. A's h_patch = h) is constant inside each
 * cell, so with 2x2 points per cell every point equals one of its two neighbours along each line
 * and the point-level index is 0 however the cells jump. oscillation_index_blocks() applies the
 * same overshoot rule to the means of p' over blocks of block x block lattice sites (block =
 * particles_per_cell: the cells the points were seeded in), each block against its neighbouring
 * blocks, normalised by the RMS of the block means. block = 1 is oscillation_index().
 *
 * A pattern of period two cells centred on the nodes. A nodal pressure alternating from node to
 * node, p_I = (-1)^i A, interpolated by the quadratic B-splines, is A (1/2 - 2 s^2) (-1)^i at
 * s cells from node i (|s| <= 1/2): with 2x2 points per cell the two points either side of a node
 * carry 3A/8 of the same sign, with 4x4 the four carry 0.22, 0.47, 0.47, 0.22 A. Each point then
 * equals a neighbour along x (point index 0), and each cell holds as much high as low pressure
 * (cell means equal: block index 0), while the field swings by 3A/4 over one cell. This is the
 * pressure mode the consistent projection cannot see (pressure.c; docs/numerics.md, "A pressure
 * pattern of period two cells"). oscillation_index_pattern() applies the block rule to blocks
 * of block x block sites laid at each of the block x block offsets of their lattice (0 .. block-1
 * sites along x and along y), counting only blocks with a point at every site (a partial block's
 * mean is its points' centroid's value, not its centre's, and a row of them along a sloping
 * surface can zigzag), and takes the largest of the block^2 indices: the blocks centred on the
 * nodes see the pattern above at 2 (3A/8) / P with 2x2 points, the blocks on the cells see a
 * checkerboard of cells, and a smooth field or a cell-wise constant monotone one (patch
 * averaging, Eq. 83) scores 0 at every offset, apart from true extrema.
 */
#ifndef PORO_OSCILLATION_H
#define PORO_OSCILLATION_H

#include "case.h"
#include "particles.h"

/* Computes the index of the soil set p, seeded on the grid g at `spacing` metres (cell_size /
 * particles_per_cell), into *index. Points that share a lattice site with an earlier point are
 * left out. Allocates and frees its own work space (it is a report, not part of a step).
 * Returns PORO_OK; PORO_ENOMEM; PORO_EINVAL for a non-positive spacing, when no point has two
 * neighbours along a line, or when the mean effective stress is zero everywhere (*index is then 0). */
enum poro_status oscillation_index(const struct case_grid *g, const struct particles *p, double spacing,
				   double *index, struct poro_error *err);

/* The same over blocks of block x block lattice sites (see above); PORO_EINVAL also for block < 1. */
enum poro_status oscillation_index_blocks(const struct case_grid *g, const struct particles *p, double spacing,
					  int block, double *index, struct poro_error *err);

/* The same index of any per-point scalar field of p (value[n]; NULL: the mean effective stress),
 * e.g. the pore pressure, whose checkerboard 002 §4.2 shows without its stabilisations (Fig. 10b).
 * "Zero" then refers to that field. */
enum poro_status oscillation_index_of(const struct case_grid *g, const struct particles *p, double spacing,
				      int block, const double *value, double *index, struct poro_error *err);

/* The two-cell pattern index of value[n] (NULL: the mean effective stress) over blocks of
 * block x block sites (block = particles_per_cell: the cells), the largest over the placements of
 * the blocks (above). PORO_EINVAL as above when no placement has a full block between two full
 * ones along a line or the field is zero. */
enum poro_status oscillation_index_pattern(const struct case_grid *g, const struct particles *p, double spacing,
					   int block, const double *value, double *index, struct poro_error *err);

#endif
