/*
 * pressure_stabilisation.c - the second-difference penalty on the pore pressure
 * (formulation.pressure_stabilisation "second_difference"), for the consistent projection.
 *
 * Why. With equal-order B-splines for velocity and pressure the projection matrix
 * A = G^T K^-1 G (pressure.c) is nearly blind to a nodal pressure that alternates from node to
 * node (period 2h): G of that pattern almost vanishes at symmetric point layouts, so the solve
 * leaves it to round-off and to whatever small part of the right-hand side points that way. Where
 * the permeability is low it then grows: +-0.13 q on the k = 1e-9 m/s Terzaghi column, +-90 kPa
 * under the crest of the k = 1e-7 m/s slope, and in the double-point Xie-Leo column it stalled
 * the consolidation from U = 0.5 on (docs/numerics.md, "Pressure stabilisation").
 *
 * What. For every line of three nodes (J - e, J, J + e) along x and along y, the energy the
 * projection minimises gets the term
 *     (factor / 6) A_JJ (p_{J-e} - 2 p_J + p_{J+e})^2
 * on the total pressure p^{t+1} = p^t + dp (the unknown is dp, so p^t moves to the right-hand
 * side). A node-to-node alternation has second differences of 4 times its amplitude and is held
 * down at once; a pressure linear along the line (hydrostatic, or any smooth field over three
 * nodes) contributes nothing, and the extra volume flux the term allows at a node is the line's
 * fourth difference, zero for fields up to cubic. The 1/6 makes a unit-weight line add its
 * A_JJ-scaled share (1 + 4 + 1 = 6) to the diagonal; factor is the case's
 * pressure_stabilisation_factor.
 *
 * Where. Only lines whose three nodes lie at least support - 1 nodes (the shape functions' reach)
 * inside the pressure unknowns: next to the free surface, a drained face or the edge of the
 * water, nodal pressures are projections from one-sided point clouds and the pressure itself may
 * drop over a cell; penalising those lines lets water through (an earlier penalty on the whole
 * field consolidated the k = 1e-9 column by a further 2-4% of the load in 2,000 steps). A grid face is not
 * an edge of the water: nodes beyond it do not exist and are not asked for.
 *
 * Ghost nodes. With the weak free-surface condition (free_surface.c) the nodes just beyond the
 * surface are unknowns that only the tails of the shape functions and the surface points see;
 * every line of three unknowns through one of them is penalised, whatever the case's
 * pressure_stabilisation, so that the field beyond the surface is the smooth continuation of the
 * field inside (a ghost penalty: it vanishes for pressures linear along the line). A ghost node
 * no such line reaches is held at zero.
 */
#include "semi_implicit.h"

/* Node K is a pressure unknown: active (positive diagonal) and not prescribed. */
static int is_unknown(const struct sim *s, const double *diagonal, idx_t K)
{
	struct semi_implicit *si = semi_implicit_of(s);
	return diagonal[K] > 0.0 && !si->dirichlet[K];
}

/* Marks the nodes whose neighbourhood of radius `margin` (inside the grid) holds only pressure
 * unknowns away from the surface: active (positive diagonal), not prescribed, and not holding the
 * interpolated free-surface condition (free_surface.c), where the pressure drops to zero within
 * a cell as it does next to a prescribed node. */
static void mark_interior(const struct sim *s, const double *diagonal, int margin, signed char *interior)
{
	struct semi_implicit *si = semi_implicit_of(s);
	const struct grid *g = &s->grid;
	const idx_t nx = g->nodes[0], ny = g->nodes[1];
	for (idx_t K = 0; K < g->node_count; K++) {
		const idx_t i = K % nx, j = K / nx;
		int inside = 1;
		for (idx_t b = j - margin; inside && b <= j + margin; b++)
			for (idx_t a = i - margin; inside && a <= i + margin; a++)
				if (a >= 0 && a < nx && b >= 0 && b < ny)
					inside = is_unknown(s, diagonal, a + b * nx) && !si->surface[a + b * nx];
		interior[K] = (signed char)inside;
	}
}

void pressure_stabilise(struct sim *s)
{
	struct semi_implicit *si = semi_implicit_of(s);
	const struct case_formulation *form = &s->spec->formulation;
	const int weak = form->free_surface == FREE_SURFACE_WEAK;
	const int inner = form->pressure_stabilisation == PRESSURE_STABILISATION_SECOND_DIFFERENCE;
	if (!inner && !weak)
		return;
	const struct grid *g = &s->grid;
	struct grid_fields *f = &s->f;
	struct pressure_system *ps = &si->ps;
	const int W = ps->width, centre = ps->radius + ps->radius * W;
	const idx_t nx = g->nodes[0], ny = g->nodes[1];
	for (idx_t K = 0; K < g->node_count; K++)   /* A's diagonal before any penalty */
		ps->diagonal[K] = ps->stencil[(size_t)K * W * W + centre];
	mark_interior(s, ps->diagonal, ps->g_radius, ps->interior);
	static const double c[3] = {1.0, -2.0, 1.0};
	for (idx_t J = 0; J < g->node_count; J++) {
		const idx_t i = J % nx, j = J / nx;
		for (int d = 0; d < 2; d++) {
			const idx_t step = d == 0 ? 1 : nx;
			const int offset = d == 0 ? 1 : W;   /* of the next node in a stencil row */
			if (d == 0 ? i == 0 || i == nx - 1 : j == 0 || j == ny - 1)
				continue;
			const idx_t line[3] = {J - step, J, J + step};
			const int ghost = weak && (si->surface[line[0]] >= SURFACE_GHOST ||
						   si->surface[line[1]] >= SURFACE_GHOST ||
						   si->surface[line[2]] >= SURFACE_GHOST) &&
					  is_unknown(s, ps->diagonal, line[0]) && is_unknown(s, ps->diagonal, line[1]) &&
					  is_unknown(s, ps->diagonal, line[2]);
			for (int a = 0; ghost && a < 3; a++)
				if (si->surface[line[a]] == SURFACE_GHOST)
					si->surface[line[a]] = SURFACE_GHOST_TIED;
			const int interior = inner && ps->interior[line[0]] && ps->interior[line[1]] &&
					     ps->interior[line[2]];
			if (!ghost && !interior)
				continue;
			const double w = form->pressure_stabilisation_factor * ps->diagonal[J] / 6.0;
			const double d2 = f->pressure[line[0]] - 2.0 * f->pressure[line[1]] + f->pressure[line[2]];
			for (int a = 0; a < 3; a++) {
				si->rhs[line[a]] -= w * c[a] * d2;   /* the p^t part of p^t + dp */
				double *row = ps->stencil + (size_t)line[a] * W * W + centre;
				for (int b = 0; b < 3; b++)
					row[(b - a) * offset] += w * c[a] * c[b];
			}
		}
	}
	for (idx_t K = 0; weak && K < g->node_count; K++)
		if (si->surface[K] == SURFACE_GHOST)   /* no line ties it to the field: held at zero */
			si->dirichlet[K] = 1;
}
