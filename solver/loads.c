/*
 * loads.c - external loads: tractions on body faces (the surface integral of 000 Eq. 54) and
 * gravity with its ramp.
 *
 * A traction acts on the soil points of the loaded face: the outermost row of points of the body
 * on that face of its bounding box, within [from, to] along it. Each such point carries its share
 * of the face, N dA = outward normal times the point spacing h / particles_per_cell, in the
 * reference configuration; the current share follows Nanson's formula da = J F^-T N dA, so a load
 * keeps acting on the material face as it deforms. The traction vector is a dead load (fixed
 * direction) scaled by its time function.
 */
#include <math.h>

#include "sim_internal.h"
#include "transfer.h"

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

void loads_add_tractions(struct sim *s, double time, double *force)
{
	const struct case_spec *c = s->spec;
	const struct particles *p = &s->soil;
	double *traction = s->soil_grad;   /* per-point force, N/m; scratch is free during step 4 */
	for (idx_t q = 0; q < p->n; q++) {
		int l = p->surface_load[q];
		traction[2 * q] = traction[2 * q + 1] = 0.0;
		if (l < 0)
			continue;
		const double *F = p->F + 4 * q, *N = p->surface + 2 * q;
		/* J F^-T N in 2-D: [[F11, -F10], [-F01, F00]] N */
		double ax = F[3] * N[0] - F[2] * N[1], ay = -F[1] * N[0] + F[0] * N[1];
		double area = hypot(ax, ay) * case_time_function_value(&c->loads[l].time_function, time);
		traction[2 * q] = c->loads[l].traction[0] * area;
		traction[2 * q + 1] = c->loads[l].traction[1] * area;
	}
	p2g_vector(&s->grid, p, NULL, traction, force);
}

void loads_gravity(const struct case_spec *c, double time, double b[2])
{
	double ramp = c->gravity.ramp_time > 0.0 ? fmin(time / c->gravity.ramp_time, 1.0) : 1.0;
	b[0] = c->gravity.acceleration[0] * ramp;
	b[1] = c->gravity.acceleration[1] * ramp;
}
