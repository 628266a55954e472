/*
 * cavitation.c - the pore water's tension limit (case keys fluid.cavitation_pressure and
 * fluid.cavitated_bulk_modulus; not in 000, whose water takes any tension).
 *
 * Why. Water under a suction beyond about one atmosphere boils: its pressure cannot fall much
 * below p_cav (gauge, about -100 kPa), and where the soil skeleton opens further the pores fill
 * with vapour instead. Without the limit, soil that dilates faster than water can reach it is
 * tied back by any suction the solve needs: behind the crest of the k = 1e-7 m/s slope of 000
 * §5.3 down to -1.9 MPa (docs/examples.md), which holds the sliding mass back.
 *
 * What. A water point whose pressure has reached p_cav holds vapour, and the water-vapour mix is
 * given a small bulk modulus K_c: Eq. 32 gains the storage term (n / K_c) dp/dt at that point, so
 * the mixture may open there at almost constant pressure, and the pressure sinks below p_cav by
 * K_c e_v / n as the vapour volume e_v (per unit volume) grows. That spring is the vapour's
 * memory: when the skeleton closes again the pressure rises back through p_cav, the point stops
 * being compliant, and the water is incompressible again. Weakly, the term is
 * sum_p S_Ip V_p n_p / K_c (dp_I / dt) in row I; the system is the projection divided by dt
 * (pressure.c), so row I's diagonal gains C_I / dt^2 with C_I = sum_p S_Ip V_p n_p / K_c over the
 * water points at or beyond p_cav at the start of the step (lumped: the storage of row I is
 * taken at node I). The matrix stays SPD.
 *
 * Why not an exact bound. p >= p_cav at every pressure unknown, as a primal-dual active set on
 * the solve, was tried first: a node held at the bound may dilate, the others keep the weak
 * continuity of their B-spline supports. The nodes of the layer under a free surface stay above
 * the bound and must then offset the dilation of the cavitating cells their supports overlap;
 * with a stiff skeleton they jam (a k = 1e-9 column pulled past the bound carried 218.6 of
 * 300 kPa at E = 100 MPa, pore pressures to +580 kPa in that layer). Storage at the points
 * reaches every node whose support holds a cavitating point, in proportion, and the same column
 * carries its load (tests/verify/cavitation_test.c, docs/numerics.md "Cavitation").
 */
#include "point_blocks.h"
#include "semi_implicit.h"

void cavitation_add_storage(struct sim *s)
{
	struct semi_implicit *si = semi_implicit_of(s);
	const struct case_spec *c = s->spec;
	if (c->fluid.cavitation_pressure == 0.0)   /* no limit (the loader allows only < 0 otherwise) */
		return;
	const struct particles *w = &s->water;   /* the pressure carriers, single point too */
	struct pressure_system *ps = &si->ps;
	const int W = ps->width, centre = ps->radius + ps->radius * W, S = w->support;
	const idx_t nx = s->grid.nodes[0];
	const double boiling = -c->fluid.cavitation_pressure;   /* internal sign: tension positive */
	const double per_volume = 1.0 / (c->fluid.cavitated_bulk_modulus * s->dt * s->dt);
	FOR_POINTS_BY_BLOCK(w, q, {   /* rows of q's support nodes only: in parallel (point_blocks.h) */
		if (w->pressure[q] < boiling)
			continue;
		const struct shape_factors f = particle_shape(w, q);
		const double storage = w->volume[q] * w->porosity[q] * per_volume;
		for (int b = 0; b < S; b++)
			for (int a = 0; a < S; a++) {
				const idx_t I = w->node0[q] + a + b * nx;
				ps->stencil[(size_t)I * W * W + centre] += storage * (f.wx[a] * f.wy[b]);
			}
	});
}
