/*
 * free_surface.c - where the pore pressure is zero (000 §4.5 step 5b): the free water surface
 * and drained faces, and the two ways the pressure solve holds p^{t+1} = 0 there
 * (formulation.free_surface).
 *
 * Where the surface is. A cell is full (below the free surface) when the volumes of the water
 * points in it reach FREE_SURFACE_FILL of it (after Kularathna and Soga, cited in 000 step 5b; a
 * water point's volume is that of the mixture it fills, Eq. 36, so a saturated cell is full). In
 * double point a cell is also full when its soil points fill it and it lies below a cell full of
 * water in its column: the soil is saturated up to the top of its water (000 §2), so cells that
 * water points have left inside the soil (next to a drained face, where they flow out, or where
 * they gather into rows) still count, while soil above the water's top (the gap of 000 Figs.
 * 9-10, where water has drained out of the top of a slope) does not, and the water's own surface
 * is the free surface. Counting all soil as saturated held that water up by suction (down to
 * -4.9 kPa under the landslides' crest, docs/examples.md); counting no soil opened free-surface
 * nodes inside the Xie-Leo column where its water points gather. Counting merely occupied cells is
 * not enough: a single expelled water point in the cell above the soil would move the free
 * surface a whole cell up. Beyond a grid face where the water is unconstrained lies open air, so
 * the cells there count as dry; beyond a wall, they do not count. The soil of a dry body
 * ("saturated": false) holds no water and never counts: its cells are full only where water that
 * seeped into it fills them, so the nodes next to it are held at p = 0 like those of a free
 * surface, and a saturated body drains into it (docs/numerics.md, "Dry bodies").
 *
 * How p = 0 is held there.
 *  - "nodes" (default, the paper's step 5b): every node next to a cell that is not full gets
 *    p^{t+1} = 0, as do the nodes of drained faces. With the Laplacian a cell is full only at
 *    FREE_SURFACE_FILL_NODES_LAPLACIAN: a cell counted full at a half puts p = 0 half a cell
 *    beyond the surface, and the column under it diverged (docs/numerics.md, "Columns whose top
 *    cuts a cell").
 *  - "interpolated" (consistent projection only): the nodes on a face between a full cell and a
 *    dry one become unknowns, and the interpolated pressure sum_J S_J(x) p^{t+1}_J is driven to
 *    zero at points x on the surface by a penalty in the energy the projection minimises,
 *        (beta / 2) sum_x (sum_J S_J(x) p^{t+1}_J)^2,   beta = free_surface_penalty_factor * mean A_II,
 *    which keeps the matrix symmetric positive definite for CHOLMOD. Why: B-splines do not
 *    interpolate, so with the surface node at 0 the field itself still stands at about an
 *    eighth of the interior pressure at the surface (quadratic: 1 - 3/4 - 1/8 of it). The
 *    pressure force sum_p V_p S_Ip grad p(x_p) integrates the drop between the interior and the
 *    surface exactly (midpoint rule on a linear gradient), so it sees only that part of the drop,
 *    and the interior pressure rises until the part seen carries the load: the middle half of
 *    the k = 1e-9 m/s Terzaghi column stands at 1.15-1.28 q over 2,000 steps under the
 *    consistent projection, at 0.997-1.003 q with the condition (docs/numerics.md, "Free
 *    surface"). Nodes farther out stay at 0.
 *    The surface points: two Gauss points on each such face, moved along its normal to where the
 *    two cells' fill puts a surface parallel to it: a full cell next to one filled to f puts it
 *    f h beyond the face, a cell filled to f_wet < 1 next to an empty one (1 - f_wet) h inside;
 *    in general (f_wet + f_dry - 1) h, kept within half a cell. Drained grid faces keep their
 *    nodes at 0 and get no surface points (the B-splines interpolate at the grid edge).
 *  - "weak" (consistent projection only): the pressure is zero beyond the surface, not on it, and
 *    the material's pressure need not drop inside it. The gradient operator of the projection,
 *    G_IJ = sum_p V_p S_Ip grad S_Jp, is the pressure force integrated by parts with the
 *    pressure's push on the surface left out; the condition puts that push back,
 *        G_IJ -= sum_x a_x n_x S_I(x) S_J(x)
 *    over the same surface points (a_x n_x: the point's share of its face, outward), so that G p
 *    is the divergence form -int p grad S_I with p = 0 outside. A pressure that stays at q up to
 *    the surface then carries a load q on it, as the undrained column needs, where the nodal and
 *    interpolated conditions need a drop within a cell that the points sample only in part (the
 *    overshoot of docs/numerics.md). G^T becomes the divergence without the surface flux, so
 *    water leaves through the surface as the drag lets it. The push acts on a phase's nodes only
 *    where its nodal mass is not negligible (BOUNDARY_MASS_FLOOR), and the force stays a
 *    point-quadrature sum elsewhere, so nearly empty nodes stay bounded as in the gradient form,
 *    unlike the divergence form over the points (docs/numerics.md). Every node that points of
 *    full cells can reach is an unknown, including ghost nodes beyond the surface; the second
 *    difference penalty on the grid lines through them (pressure_stabilisation.c) extends the
 *    field inside smoothly to them (Burman's ghost penalty for cut cells); farther nodes are 0.
 */
#include <assert.h>
#include <math.h>
#include <string.h>

#include "shape.h"
#include "semi_implicit.h"

/* A cell is full (below the free surface) when its points' volumes reach this fraction of it. */
#define FREE_SURFACE_FILL 0.5
/* The same under the nodal condition with the Laplacian (000 Eq. 61): there a full cell next to a
 * dry one puts p = 0 on nodes (1 - f) h beyond the surface of a cell filled to f, and the pressure
 * field keeps a share of the interior pressure at the surface that the pressure force does not
 * see (quadratic B-splines: (1.5 - f)^2 / 2, an eighth at f = 1, a half at f = 1/2); the interior
 * rises until the part it sees carries the load, and the Laplacian, which over-corrects short
 * waves, amplifies that rise step after step. Measured on a column whose top fills its cell to f
 * (docs/numerics.md, "Columns whose top cuts a cell"): counted full at f = 1/2 and 3/4 it
 * diverges (interior 3.7 q after one step), at f = 0.8 on the softer columns tried; at 0.85 to 1
 * it stays within 1.2-1.47 q. Counted not full, the cell's lower nodes take p = 0, f h inside the
 * surface: a drained skin, whose error the threshold keeps below 0.9 h. */
#define FREE_SURFACE_FILL_NODES_LAPLACIAN 0.9
/* The weak condition's boundary term acts on a node's phase only where that phase's nodal mass
 * reaches this fraction of the largest: a surface point may lie beyond the points' reach, and its
 * push on a node they barely touch would be divided by a mass near zero. */
#define BOUNDARY_MASS_FLOOR 1e-3

/* fill[c] = the summed volumes of the points of p in cell c (points outside the grid left out). */
static void cell_volumes(const struct grid *g, const struct particles *p, double *fill)
{
	memset(fill, 0, sizeof(double) * (size_t)g->cell_count);
	for (idx_t q = 0; q < p->n; q++) {
		idx_t c = grid_cell_of(g, p->x + 2 * q);
		if (c >= 0)
			fill[c] += p->volume[q];
	}
}

/* Node (i, j) lies on a grid face the case drains. */
static int on_drained_face(const struct sim *s, idx_t i, idx_t j)
{
	const struct case_boundary *bc = s->spec->boundaries;
	const struct grid *g = &s->grid;
	return (i == 0 && bc[FACE_LEFT].drainage == DRAINAGE_DRAINED) ||
	       (i == g->cells[0] && bc[FACE_RIGHT].drainage == DRAINAGE_DRAINED) ||
	       (j == 0 && bc[FACE_BOTTOM].drainage == DRAINAGE_DRAINED) ||
	       (j == g->cells[1] && bc[FACE_TOP].drainage == DRAINAGE_DRAINED);
}

/* si->cell_wet; si->cell_fill (water) and, double point, si->cell_fill_soil hold the volumes. */
static void mark_full_cells(struct sim *s)
{
	struct semi_implicit *si = semi_implicit_of(s);
	const struct grid *g = &s->grid;
	const struct case_formulation *form = &s->spec->formulation;
	const int nodes_laplacian = form->free_surface == FREE_SURFACE_NODES &&
				    form->pressure_projection == PROJECTION_LAPLACIAN;
	const double full = (nodes_laplacian ? FREE_SURFACE_FILL_NODES_LAPLACIAN : FREE_SURFACE_FILL) * g->h * g->h;
	cell_volumes(g, &s->water, si->cell_fill);
	#pragma omp parallel for schedule(static)
	for (idx_t c = 0; c < g->cell_count; c++)
		si->cell_wet[c] = si->cell_fill[c] >= full;
	if (!s->double_point)
		return;
	/* saturated soil fills a cell below the top of its column's water (file comment) */
	const struct particles wet = semi_implicit_wet_soil(s);
	cell_volumes(g, &wet, si->cell_fill_soil);
	#pragma omp parallel for schedule(static)
	for (idx_t ci = 0; ci < g->cells[0]; ci++) {
		int below_water = 0;
		for (idx_t cj = g->cells[1] - 1; cj >= 0; cj--) {
			idx_t c = ci + cj * g->cells[0];
			below_water |= si->cell_wet[c];
			si->cell_wet[c] |= below_water && si->cell_fill_soil[c] >= full;
		}
	}
}

/* Cell (ci, cj) lies inside the grid and is full. */
static int cell_full(const struct sim *s, idx_t ci, idx_t cj)
{
	struct semi_implicit *si = semi_implicit_of(s);
	const struct grid *g = &s->grid;
	return ci >= 0 && cj >= 0 && ci < g->cells[0] && cj < g->cells[1] && si->cell_wet[ci + cj * g->cells[0]];
}

/* Cell (ci, cj), inside the grid or beyond a face, counts as dry: not full, or open air. */
static int cell_dry(const struct sim *s, const int open[FACE_COUNT], idx_t ci, idx_t cj)
{
	const struct grid *g = &s->grid;
	if (ci >= 0 && cj >= 0 && ci < g->cells[0] && cj < g->cells[1])
		return !cell_full(s, ci, cj);
	return (ci < 0 && open[FACE_LEFT]) || (ci >= g->cells[0] && open[FACE_RIGHT]) ||
	       (cj < 0 && open[FACE_BOTTOM]) || (cj >= g->cells[1] && open[FACE_TOP]);
}

/* How far cell (ci, cj) is filled, at most 1 (0 beyond the grid): by water, or for a full cell
 * in double point by water or soil, whichever fills more. */
static double cell_fraction(const struct sim *s, idx_t ci, idx_t cj)
{
	struct semi_implicit *si = semi_implicit_of(s);
	const struct grid *g = &s->grid;
	if (ci < 0 || cj < 0 || ci >= g->cells[0] || cj >= g->cells[1])
		return 0.0;
	const idx_t c = ci + cj * g->cells[0];
	double v = si->cell_fill[c];
	if (s->double_point && si->cell_wet[c] && si->cell_fill_soil[c] > v)
		v = si->cell_fill_soil[c];
	return fmin(v / (g->h * g->h), 1.0);
}

/* The interpolated condition's surface points on the face between full cell (ci, cj) and its dry
 * neighbour in direction (dx, dy), and the face's two nodes taken from the prescribed set. */
static void add_surface_face(struct sim *s, idx_t ci, idx_t cj, int dx, int dy)
{
	struct semi_implicit *si = semi_implicit_of(s);
	const struct grid *g = &s->grid;
	struct pressure_system *ps = &si->ps;
	double d = cell_fraction(s, ci, cj) + cell_fraction(s, ci + dx, cj + dy) - 1.0;
	d = fmax(-0.5, fmin(0.5, d));
	const double cx = g->origin[0] + ((double)ci + 0.5 + 0.5 * dx + d * dx) * g->h;
	const double cy = g->origin[1] + ((double)cj + 0.5 + 0.5 * dy + d * dy) * g->h;
	const double gauss = g->h / (2.0 * sqrt(3.0));   /* two-point Gauss rule along the face */
	for (int e = 0; e < 2; e++) {
		assert(ps->sample_count < ps->sample_max);
		double *x = ps->samples + 2 * ps->sample_count, *nw = ps->sample_normal + 2 * ps->sample_count;
		ps->sample_count++;
		const double t = e ? gauss : -gauss;
		x[0] = cx + (dx == 0 ? t : 0.0);
		x[1] = cy + (dy == 0 ? t : 0.0);
		nw[0] = 0.5 * g->h * dx, nw[1] = 0.5 * g->h * dy;
	}
	if (s->spec->formulation.free_surface == FREE_SURFACE_WEAK)
		return;
	for (int e = 0; e < 2; e++) {
		const idx_t i = ci + (dx ? dx > 0 : e), j = cj + (dy ? dy > 0 : e);
		const idx_t I = grid_node(g, i, j);
		if (si->dirichlet[I] && !on_drained_face(s, i, j)) {
			si->dirichlet[I] = 0;
			si->surface[I] = SURFACE_ON;
		}
	}
}

/* Places the interpolated condition on every face between a full cell and a dry one, except on
 * drained grid faces. */
static void place_surface(struct sim *s, const int open[FACE_COUNT])
{
	struct semi_implicit *si = semi_implicit_of(s);
	const struct grid *g = &s->grid;
	static const int dir[FACE_COUNT][2] = {{-1, 0}, {1, 0}, {0, -1}, {0, 1}};   /* enum grid_face order */
	for (idx_t cj = 0; cj < g->cells[1]; cj++)
		for (idx_t ci = 0; ci < g->cells[0]; ci++) {
			if (!si->cell_wet[ci + cj * g->cells[0]])
				continue;
			for (int k = 0; k < FACE_COUNT; k++) {
				const idx_t ai = ci + dir[k][0], aj = cj + dir[k][1];
				const int beyond = ai < 0 || aj < 0 || ai >= g->cells[0] || aj >= g->cells[1];
				if (!cell_dry(s, open, ai, aj) ||
				    (beyond && s->spec->boundaries[k].drainage == DRAINAGE_DRAINED))
					continue;
				add_surface_face(s, ci, cj, dir[k][0], dir[k][1]);
			}
		}
}

/* Node (i, j) under the nodal and interpolated conditions: prescribed when a cell next to it is
 * dry. */
static int node_dry(const struct sim *s, const int open[FACE_COUNT], idx_t i, idx_t j)
{
	int dry = on_drained_face(s, i, j);
	for (idx_t cj = j - 1; cj <= j; cj++)
		for (idx_t ci = i - 1; ci <= i; ci++)
			dry |= cell_dry(s, open, ci, cj);
	return dry;
}

/* Node (i, j) under the weak condition: -1 prescribed (on a drained face, or no point of a full
 * cell can reach it: cells i-S+1..i+1 by j-S+1..j+1 for support S), else its enum surface_node:
 * on the surface (next to full and dry cells), a ghost node (next to no full cell), or none. */
static int weak_node(const struct sim *s, const int open[FACE_COUNT], idx_t i, idx_t j, int S)
{
	int reached = 0, wet_next = 0;
	for (idx_t cj = j - S + 1; cj <= j + 1; cj++)
		for (idx_t ci = i - S + 1; ci <= i + 1; ci++)
			reached |= cell_full(s, ci, cj);
	if (!reached || on_drained_face(s, i, j))
		return -1;
	for (idx_t cj = j - 1; cj <= j; cj++)
		for (idx_t ci = i - 1; ci <= i; ci++)
			wet_next |= cell_full(s, ci, cj);
	return !wet_next ? SURFACE_GHOST : node_dry(s, open, i, j) ? SURFACE_ON : SURFACE_NONE;
}

void free_surface_mark(struct sim *s)
{
	struct semi_implicit *si = semi_implicit_of(s);
	const struct grid *g = &s->grid;
	const struct case_boundary *bc = s->spec->boundaries;
	/* beyond a face where water moves freely is open air (dry); beyond a wall, nothing */
	const int open[FACE_COUNT] = {bc[FACE_LEFT].water == CONSTRAINT_FREE, bc[FACE_RIGHT].water == CONSTRAINT_FREE,
				      bc[FACE_BOTTOM].water == CONSTRAINT_FREE, bc[FACE_TOP].water == CONSTRAINT_FREE};
	const int weak = s->spec->formulation.free_surface == FREE_SURFACE_WEAK;
	const int S = shape_support(s->spec->formulation.shape);
	mark_full_cells(s);
	#pragma omp parallel for schedule(static)
	for (idx_t j = 0; j < g->nodes[1]; j++)
		for (idx_t i = 0; i < g->nodes[0]; i++) {
			const idx_t I = grid_node(g, i, j);
			if (weak) {
				const int k = weak_node(s, open, i, j, S);
				si->dirichlet[I] = (signed char)(k < 0);
				si->surface[I] = (signed char)(k < 0 ? SURFACE_NONE : k);
			} else {
				si->dirichlet[I] = (signed char)node_dry(s, open, i, j);
				si->surface[I] = SURFACE_NONE;
			}
		}
	si->ps.sample_count = 0;
	if (s->spec->formulation.free_surface != FREE_SURFACE_NODES)
		place_surface(s, open);
}

/* The weak condition's boundary term: G_IJ -= sum_x a_x n_x S_I(x) S_J(x) over the surface
 * points, into a gradient operator laid out as pressure.c's (row I, offsets of J within radius). */
void free_surface_add_boundary_term(const struct sim *s, const double *mass, double *G)
{
	struct semi_implicit *si = semi_implicit_of(s);
	const struct grid *g = &s->grid;
	const struct pressure_system *ps = &si->ps;
	const enum case_shape kind = s->spec->formulation.shape;
	const int S = shape_support(kind), W = ps->g_width, R = ps->g_radius;
	double floor_mass = 0.0;
	for (idx_t I = 0; I < g->node_count; I++)
		floor_mass = fmax(floor_mass, mass[I]);
	floor_mass *= BOUNDARY_MASS_FLOOR;
	for (idx_t k = 0; k < ps->sample_count; k++) {
		idx_t node0;
		double w[SHAPE_NODES_MAX];
		if (shape_weights_at(g, kind, ps->samples + 2 * k, &node0, w))
			continue;
		const double *nw = ps->sample_normal + 2 * k;
		for (int a = 0; a < S * S; a++) {
			const idx_t I = node0 + a % S + (a / S) * g->nodes[0];
			if (mass[I] < floor_mass)
				continue;
			double *row = G + (size_t)I * W * W * 2;
			for (int b = 0; b < S * S; b++) {
				const int off = (b % S - a % S + R) + (b / S - a / S + R) * W;
				row[2 * off] -= nw[0] * w[a] * w[b];
				row[2 * off + 1] -= nw[1] * w[a] * w[b];
			}
		}
	}
}

void free_surface_add_penalty(struct sim *s, double scale)
{
	struct semi_implicit *si = semi_implicit_of(s);
	if (s->spec->formulation.free_surface != FREE_SURFACE_INTERPOLATED)
		return;
	const struct grid *g = &s->grid;
	struct grid_fields *f = &s->f;
	struct pressure_system *ps = &si->ps;
	const enum case_shape kind = s->spec->formulation.shape;
	const int S = shape_support(kind), W = ps->width, R = ps->radius;
	const double beta = s->spec->formulation.free_surface_penalty_factor * scale;
	for (idx_t k = 0; k < ps->sample_count; k++) {
		idx_t node0;
		double w[SHAPE_NODES_MAX];
		if (shape_weights_at(g, kind, ps->samples + 2 * k, &node0, w))
			continue;   /* a surface point beyond the grid's edge: the edge nodes hold it */
		/* prescribed nodes are 0 at t+1: only the unknowns enter the interpolated p^{t+1} */
		double p_old = 0.0;
		for (int a = 0; a < S * S; a++) {
			const idx_t I = node0 + a % S + (a / S) * g->nodes[0];
			if (ps->unknown[I] < 0)
				w[a] = 0.0;
			p_old += w[a] * f->pressure[I];
		}
		/* (beta/2) (w . (p^t + dp))^2: beta w w^T into the matrix, -beta w (w . p^t) into b */
		for (int a = 0; a < S * S; a++) {
			if (w[a] == 0.0)
				continue;
			const idx_t I = node0 + a % S + (a / S) * g->nodes[0];
			si->rhs[I] -= beta * w[a] * p_old;
			double *row = ps->stencil + (size_t)I * W * W;
			for (int b = 0; b < S * S; b++)
				row[(b % S - a % S + R) + (b / S - a / S + R) * W] += beta * w[a] * w[b];
		}
	}
}
