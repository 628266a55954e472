/*
 * loads.c - external loads: tractions on body faces (the surface integral of 000 Eq. 54) and
 * gravity with its ramp.
 *
 * A traction acts on the loaded face of a body: the outermost row of points of the body on that
 * face of its bounding box, within [from, to] along it. The traction vector t is a dead load
 * (fixed direction) scaled by its time function. Its nodal forces f_I = int_face S_I t da are
 * integrated in one of two ways.
 *
 * Through the body's points (every body at least LOAD_DEPTH_SUPPORTS shape-function supports
 * thick along the face's normal N). With a weight phi that is 1 on the loaded face and falls
 * linearly with the reference depth d to 0 on the far side (phi = 1 - d / D, D the body's
 * thickness), the divergence theorem over the strip of the body under the loaded points (the
 * points whose reference coordinate along the face lies within the loaded points' extent) gives
 *     int_face S_I t (N . n) da = int_strip div(S_I phi t (x) N) dV
 *                               ~ t sum_p V_p (phi_p N . grad S_I(x_p) + S_I(x_p) N . grad phi_p).
 * The point sum is the quadrature the internal force uses (f_int = -sum_p V_p sigma_p grad S_I),
 * so near the face, where phi ~ 1, a stress equal to the traction (sigma N = t) nearly balances
 * the load wherever the face lies in its cell, and the total load is exact: sum_I of the forces
 * is t sum_p V_p N . grad phi = t sum_p V0_p (N . cof F N) / D, the face's projected area for
 * any deformation uniform along the strip. Evaluating the load at the faces instead balances it
 * only when the face lies on a grid line or a cell's middle (there the points' midpoint rule
 * integrates the B-splines' piecewise-linear gradients exactly); elsewhere the nodes just beyond
 * the surface, which carry a few per cent of a full node's mass, take a load that their share of
 * the stress divergence does not match, and they strain the top row until it does: the Xie-Leo
 * column's top row was compressed 2.4% beyond its final strain and the column settled 4.0%
 * (double point) and 1.1% (single point) ahead of Eq. 87 at U = 0.25 (docs/numerics.md,
 * "Tractions"; tests/solver/loads_test.c measures the mismatch both ways). Summing only over
 * the nodes next to the face (phi = 1 there, 0 beyond) balances those nodes exactly but leaves
 * the total to the midpoint rule where the weight drops: 3.5% short to 2.5% over in the Xie-Leo
 * column as it compresses, which its final settlement followed. The load is per area projected
 * on the face's reference plane ((N . n) da), the current area while the face keeps its
 * orientation. D is the thickness of the body's bounding box: a polygon whose far side under the
 * loaded span lies inside the box (an overhang) would take the part of the load that phi leaves
 * there on that side, so such spans want the box's full depth of material under them.
 *
 * At the point faces (thinner bodies: there phi would fall to 0 within a few cells, and the
 * smeared part S_I N . grad phi would outweigh the part that balances the stress). Each loaded
 * point carries its share of the face, N dA = outward normal times the point's width along the
 * face (h / particles_per_cell, or its volume over its thickness where the face cuts its row), in
 * the reference configuration; the current share follows Nanson's
 * formula da = J F^-T N dA, so the load keeps acting on the material face as it deforms. It is
 * applied at the face midpoint, centre + F N d / 2: mapping it at the centre gives the nodes
 * beyond the surface a quarter of the load their share of the stress divergence asks for, and
 * the surplus accelerates those low-mass nodes without bound.
 */
#include <math.h>

#include "point_blocks.h"
#include "shape.h"
#include "sim_internal.h"

/* A body takes the integration through its points when it is at least this many shape-function
 * supports thick along the loaded face's normal (quadratic B-splines: 6 cells), so that phi stays
 * above about one half over the supports of the nodes next to the face. */
#define LOAD_DEPTH_SUPPORTS 2

void loads_init(struct sim *s)
{
	const struct case_spec *c = s->spec;
	struct particles *p = &s->soil;
	const double h = c->grid.cell_size;
	for (int l = 0; l < c->load_count; l++) {
		const struct case_load *load = &c->loads[l];
		const struct case_body *body = &c->bodies[load->body];
		/* a rectangle's outermost row has its centres within 3/4 of a spacing of the face (a
		 * row the face cuts is 1/2 to 3/2 spacings thick, sim.c), the next row a spacing or
		 * more; a polygon's points keep the sub-grid, its outermost row within a spacing */
		const double spacing = h / body->particles_per_cell;
		const double outermost = body->is_polygon ? spacing : 0.875 * spacing;
		struct load_band *band = &s->load_bands[l];
		const int axis = band->axis = (load->face == FACE_LEFT || load->face == FACE_RIGHT) ? 0 : 1;
		const int upper = load->face == FACE_RIGHT || load->face == FACE_TOP;
		band->sign = upper ? 1.0 : -1.0;
		band->face = upper ? body->max[axis] : body->min[axis];
		band->depth = body->max[axis] - body->min[axis];
		band->through_points = band->depth >= LOAD_DEPTH_SUPPORTS * shape_support(c->formulation.shape) * h;
		band->along[0] = INFINITY, band->along[1] = -INFINITY;
		for (idx_t q = 0; q < p->n; q++) {
			if (p->body[q] != load->body)
				continue;
			double normal_coord = p->x0[2 * q + axis], along = p->x0[2 * q + 1 - axis];
			if (fabs(normal_coord - band->face) >= outermost || along < load->from || along > load->to)
				continue;
			/* a rectangle's point reaches from its centre to the face: its share of the face
			 * is its volume over that thickness (one spacing, unless the face cuts its row) */
			const double thickness = body->is_polygon ? spacing : 2.0 * fabs(band->face - normal_coord);
			const double width = p->volume0[q] / thickness;
			p->surface_load[q] = l;
			p->surface[2 * q + axis] = band->sign * width;
			p->surface[2 * q + 1 - axis] = 0.0;
			/* the strip under a loaded point is its column of points, as wide as its share */
			band->along[0] = fmin(band->along[0], along - 0.5 * width);
			band->along[1] = fmax(band->along[1], along + 0.5 * width);
		}
	}
}

/* Load l at the midpoints of its points' faces (file comment). Serial, in index order: a face
 * midpoint's support is not its point's, so the block order of the parallel scatters
 * (point_blocks.h) does not keep two threads off its nodes; the loop touches only the loaded
 * points' nodes. */
static void add_at_faces(struct sim *s, int l, double scale, double *force)
{
	const struct case_spec *c = s->spec;
	const struct particles *p = &s->soil;
	const int S = p->support, nn = S * S;
	const double tx = c->loads[l].traction[0] * scale, ty = c->loads[l].traction[1] * scale;
	for (idx_t q = 0; q < p->n; q++) {
		if (p->surface_load[q] != l)
			continue;
		const double *F = p->F + 4 * q, *N = p->surface + 2 * q;
		/* J F^-T N in 2-D: [[F11, -F10], [-F01, F00]] N */
		double area = hypot(F[3] * N[0] - F[2] * N[1], -F[1] * N[0] + F[0] * N[1]);
		/* N has the length of the point's share of the face, V0 / |N| its thickness, so
		 * F N V0 / (2 |N|^2) reaches from the centre to the face */
		const double reach = 0.5 * p->volume0[q] / (N[0] * N[0] + N[1] * N[1]);
		double face[2] = { p->x[2 * q] + reach * (F[0] * N[0] + F[1] * N[1]),
				   p->x[2 * q + 1] + reach * (F[2] * N[0] + F[3] * N[1]) };
		double w[SHAPE_NODES_MAX];
		idx_t node0;
		if (shape_weights_at(&s->grid, c->formulation.shape, face, &node0, w))
			continue;   /* the face left the grid: the point itself is reported by step 1 */
		for (int k = 0; k < nn; k++) {
			idx_t I = node0 + k % S + (k / S) * s->grid.nodes[0];
			force[2 * I] += w[k] * tx * area;
			force[2 * I + 1] += w[k] * ty * area;
		}
	}
}

/* Load l through the points of the strip under it (file comment):
 *     f_I = t sum_p V_p (phi_p N . grad S_I(x_p) + S_I(x_p) N . grad phi_p),
 * phi = 1 - d / D falling from the loaded face (reference depth d = 0) to the far side (d = D). */
static void add_through_points(struct sim *s, int l, double scale, double *force)
{
	const struct case_load *load = &s->spec->loads[l];
	const struct load_band *band = &s->load_bands[l];
	const struct particles *p = &s->soil;
	const int S = p->support, nn = S * S, axis = band->axis;
	const idx_t nx = s->grid.nodes[0];
	const double sign = band->sign, face = band->face, D = band->depth;
	const double tx = load->traction[0] * scale, ty = load->traction[1] * scale;
	FOR_POINTS_BY_BLOCK(p, q, {   /* a scatter from the points' own supports (point_blocks.h) */
		const double along = p->x0[2 * q + 1 - axis];
		if (p->body[q] != load->body || along < band->along[0] || along > band->along[1])
			continue;
		const double phi = 1.0 - sign * (face - p->x0[2 * q + axis]) / D;
		if (!(phi > 0.0))
			continue;
		/* N . grad phi = N . F^-T N / D in the current configuration: F_xx / J for a face
		 * normal to y, F_yy / J for one normal to x */
		const double *F = p->F + 4 * q;
		const double N_grad_phi = (axis == 1 ? F[0] : F[3]) / ((F[0] * F[3] - F[1] * F[2]) * D);
		const struct shape_factors f = particle_shape(p, q);
		for (int k = 0; k < nn; k++) {
			const int a = k % S, b = k / S;
			const idx_t I = p->node0[q] + a + b * nx;
			const double gradient = axis == 0 ? f.dx[a] * f.wy[b] : f.wx[a] * f.dy[b];
			const double g = p->volume[q] * (phi * sign * gradient + f.wx[a] * f.wy[b] * N_grad_phi);
			force[2 * I] += tx * g;
			force[2 * I + 1] += ty * g;
		}
	});
}

void loads_add_tractions(struct sim *s, double time, double *force)
{
	const struct case_spec *c = s->spec;
	for (int l = 0; l < c->load_count; l++) {
		const double scale = case_time_function_value(&c->loads[l].time_function, time);
		if (s->load_bands[l].through_points)
			add_through_points(s, l, scale, force);
		else
			add_at_faces(s, l, scale, force);
	}
}

void loads_gravity(const struct case_spec *c, double time, double b[2])
{
	double ramp = c->gravity.ramp_time > 0.0 ? fmin(time / c->gravity.ramp_time, 1.0) : 1.0;
	b[0] = c->gravity.acceleration[0] * ramp;
	b[1] = c->gravity.acceleration[1] * ramp;
}

/* Time t is at or before the end of the gravity ramp; steps are compared within a billionth of dt,
 * so the step that lands on the ramp's end by rounding still counts as inside it. */
static int by_ramp_end(const struct sim *s, double t)
{
	return t <= s->spec->gravity.ramp_time + 1e-9 * s->dt;
}

int loads_in_gravity_ramp(const struct sim *s)
{
	return s->spec->gravity.ramp_time > 0 && by_ramp_end(s, s->time + s->dt);
}

int loads_gravity_loading_stage(const struct sim *s)
{
	if (!s->spec->gravity.elastic_loading)
		return 0;
	if (loads_in_gravity_ramp(s))
		return 1;
	return by_ramp_end(s, s->time) ? 2 : 0;
}
