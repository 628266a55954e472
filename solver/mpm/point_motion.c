/*
 * point_motion.c - the grid-to-particle motion every scheme shares (000 §4.5 step 7a-b): the
 * points' velocity update (FLIP blended with PIC, APIC or AFLIP), their positions, the water
 * attached to the soil during a gravity ramp (000 §5.4), and water points leaving the domain
 * through faces where water moves freely.
 */
#include "phases.h"
#include "transfer.h"

/* x_p += dt v_p for every point of the set; returns how many then lie beyond a grid face. */
static idx_t advance_positions(const struct sim *s, struct particles *p)
{
	idx_t beyond = 0;   /* a count: the same in any order */
	#pragma omp parallel for schedule(static) reduction(+ : beyond)
	for (idx_t q = 0; q < p->n; q++) {
		p->x[2 * q] += s->dt * p->v[2 * q];
		p->x[2 * q + 1] += s->dt * p->v[2 * q + 1];
		beyond += grid_beyond_face(&s->grid, p->x + 2 * q);
	}
	return beyond;
}

/* Step 7a-b for one set: the velocity update, FLIP blended with PIC by flip_fraction (000 §4.5),
 * APIC, or AFLIP (the FLIP blend, and APIC's affine velocity gathered beside it; transfer.h), and
 * the position update x += dt sum S v^{t+1}. v_old is overwritten with the nodal increment.
 * Returns how many moved points lie beyond a grid face (0 if the positions stay). */
idx_t point_motion_update(struct sim *s, struct particles *p, const double *v_new, double *v_old, int move_positions)
{
	if (s->spec->formulation.velocity_update == VELOCITY_UPDATE_APIC) {
		point_gather_velocity(s, p, v_new, p->v);   /* APIC's point velocity is the PIC one */
		return move_positions ? advance_positions(s, p) : 0;
	}
	#pragma omp parallel for schedule(static)
	for (idx_t I = 0; I < 2 * s->grid.node_count; I++)
		v_old[I] = v_new[I] - v_old[I];
	const idx_t beyond = g2p_flip_update(&s->grid, p, v_new, v_old, s->spec->formulation.flip_fraction, s->dt,
					     move_positions);
	if (s->spec->formulation.velocity_update == VELOCITY_UPDATE_AFLIP)
		g2p_affine_velocity(&s->grid, p, v_new, NULL, p->C);
	return beyond;
}

/* 000 §5.4's initialisation with gravity.water_attached: the water points take the soil's nodal
 * velocity (PIC) and move with it, so the loading causes no seepage between the point sets; the
 * pressure solve still carries the water's weight. Single point: the positions are the soil's. */
idx_t point_motion_attach_water(struct sim *s)
{
	struct particles *w = &s->water;
	point_gather_velocity(s, w, s->f.v_s, w->v);
	return s->double_point ? advance_positions(s, w) : 0;
}

/* Water points that crossed a grid face where water moves freely (a drained face, or open air)
 * have left the domain: they are removed and their mass booked as outflow, so the water balance
 * stays checkable (double point only: the single-point water has no points of its own). Point
 * probes following a removed point stop. Crossing a wall is an error reported by step 1. The
 * search is skipped when step 7 found no water point beyond a face (beyond: its count). */
void point_motion_remove_outflow(struct sim *s, idx_t beyond)
{
	struct particles *w = &s->water;
	const struct case_boundary *bc = s->spec->boundaries;
	if (!s->double_point || beyond == 0)
		return;
	for (idx_t q = w->n - 1; q >= 0; q--) {
		const int face = grid_face_beyond(&s->grid, w->x + 2 * q);
		if (face < 0 || bc[face].water != CONSTRAINT_FREE)
			continue;
		s->water_outflow_mass += w->mass[q];
		for (int i = 0; i < s->spec->probe_count; i++) {
			if (s->spec->probes[i].kind != PROBE_PORE_PRESSURE)
				continue;
			if (s->probe_point[i] == q)
				s->probe_point[i] = -1;
			else if (s->probe_point[i] == w->n - 1)
				s->probe_point[i] = (int)q;
		}
		particles_remove(w, q);
	}
}
