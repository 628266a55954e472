/*
 * loads.c - external loads: tractions on body faces (the surface integral of 000 Eq. 54) and
 * gravity with its ramp.
 *
 * A traction acts on the soil points of the loaded face: the outermost row of points of the body
 * on that face of its bounding box, within [from, to] along it. Each such point carries its share
 * of the face, N dA = outward normal times the point spacing h / particles_per_cell, in the
 * reference configuration; the current share follows Nanson's formula da = J F^-T N dA, so a load
 * keeps acting on the material face as it deforms. The traction vector is a dead load (fixed
 * direction) scaled by its time function. It is applied at the face midpoint (see below).
 */
#include <math.h>

#include "shape.h"
#include "sim_internal.h"

void loads_init(struct sim *s)
{
	const struct case_spec *c = s->spec;
	struct particles *p = &s->soil;
	for (int l = 0; l < c->load_count; l++) {
		const struct case_load *load = &c->loads[l];
		const struct case_body *body = &c->bodies[load->body];
		const double spacing = c->grid.cell_size / body->particles_per_cell;
		const int axis = (load->face == FACE_LEFT || load->face == FACE_RIGHT) ? 0 : 1;
		const int upper = load->face == FACE_RIGHT || load->face == FACE_TOP;
		const double face = upper ? body->max[axis] : body->min[axis];
		for (idx_t q = 0; q < p->n; q++) {
			if (p->body[q] != load->body)
				continue;
			double normal_coord = p->x0[2 * q + axis], along = p->x0[2 * q + 1 - axis];
			if (fabs(normal_coord - face) >= spacing || along < load->from || along > load->to)
				continue;
			p->surface_load[q] = l;
			p->surface[2 * q + axis] = (upper ? 1.0 : -1.0) * spacing;
			p->surface[2 * q + 1 - axis] = 0.0;
		}
	}
}

/* The traction of a loaded point acts on its face, not at its centre: the face midpoint is the
 * centre plus F (N / |N|) d / 2 (d the point spacing). Mapping the load at the centre instead
 * gives the nodes beyond the surface a quarter of the load their share of the stress divergence
 * asks for, and the surplus accelerates those low-mass nodes without bound. */
void loads_add_tractions(struct sim *s, double time, double *force)
{
	const struct case_spec *c = s->spec;
	const struct particles *p = &s->soil;
	const int S = p->support, nn = S * S;
	for (idx_t q = 0; q < p->n; q++) {
		int l = p->surface_load[q];
		if (l < 0)
			continue;
		const double *F = p->F + 4 * q, *N = p->surface + 2 * q;
		/* J F^-T N in 2-D: [[F11, -F10], [-F01, F00]] N */
		double ax = F[3] * N[0] - F[2] * N[1], ay = -F[1] * N[0] + F[0] * N[1];
		double area = hypot(ax, ay) * case_time_function_value(&c->loads[l].time_function, time);
		double tx = c->loads[l].traction[0] * area, ty = c->loads[l].traction[1] * area;
		/* N has length d, so F N / 2 reaches from the centre to the face */
		double face[2] = {p->x[2 * q] + 0.5 * (F[0] * N[0] + F[1] * N[1]),
				  p->x[2 * q + 1] + 0.5 * (F[2] * N[0] + F[3] * N[1])};
		double w[SHAPE_NODES_MAX];
		idx_t node0;
		if (shape_weights_at(&s->grid, c->formulation.shape, face, &node0, w))
			continue;   /* the face left the grid: the point itself is reported by step 1 */
		for (int k = 0; k < nn; k++) {
			idx_t I = node0 + k % S + (k / S) * s->grid.nodes[0];
			force[2 * I] += w[k] * tx;
			force[2 * I + 1] += w[k] * ty;
		}
	}
}

void loads_gravity(const struct case_spec *c, double time, double b[2])
{
	double ramp = c->gravity.ramp_time > 0.0 ? fmin(time / c->gravity.ramp_time, 1.0) : 1.0;
	b[0] = c->gravity.acceleration[0] * ramp;
	b[1] = c->gravity.acceleration[1] * ramp;
}
