/*
 * probes.c - named time series a case asks for (DESIGN §3): pore pressure at the pressure point
 * nearest to a location, displacement of the soil point nearest to a location (both chosen once,
 * at the start, and followed as they move), and the average of a field over the points inside a
 * box at the time of sampling.
 */
#include <float.h>
#include <math.h>

#include "sim_internal.h"

static int nearest_point(const struct particles *p, const double at[2])
{
	int best = -1;
	double best_d2 = DBL_MAX;
	for (idx_t q = 0; q < p->n; q++) {
		double dx = p->x[2 * q] - at[0], dy = p->x[2 * q + 1] - at[1];
		if (dx * dx + dy * dy < best_d2) {
			best_d2 = dx * dx + dy * dy;
			best = (int)q;
		}
	}
	return best;
}

void probes_init(struct sim *s)
{
	for (int i = 0; i < s->spec->probe_count; i++) {
		const struct case_probe *pr = &s->spec->probes[i];
		s->probe_point[i] = -1;
		if (pr->kind == PROBE_PORE_PRESSURE)
			s->probe_point[i] = nearest_point(&s->water, pr->point);
		else if (pr->kind == PROBE_DISPLACEMENT)
			s->probe_point[i] = nearest_point(&s->soil, pr->point);
	}
}

static double field_value(const struct sim *s, enum probe_field field, idx_t q, int water)
{
	const struct particles *p = water ? &s->water : &s->soil;
	switch (field) {
	case FIELD_PORE_PRESSURE: return -p->pressure[q];
	case FIELD_STRESS_XX: return s->soil.stress[4 * q];
	case FIELD_STRESS_YY: return s->soil.stress[4 * q + 1];
	case FIELD_STRESS_XY: return s->soil.stress[4 * q + 2];
	case FIELD_DISPLACEMENT_X: return p->x[2 * q] - p->x0[2 * q];
	case FIELD_DISPLACEMENT_Y: return p->x[2 * q + 1] - p->x0[2 * q + 1];
	}
	return 0.0;
}

double sim_probe_value(const struct sim *s, int i)
{
	const struct case_probe *pr = &s->spec->probes[i];
	int q = s->probe_point[i];
	switch (pr->kind) {
	case PROBE_PORE_PRESSURE:
		return q >= 0 ? -s->water.pressure[q] : NAN;   /* its point drained out of the grid */
	case PROBE_DISPLACEMENT:
		return s->soil.x[2 * q + pr->component] - s->soil.x0[2 * q + pr->component];
	case PROBE_AVERAGE: {
		int water = pr->field == FIELD_PORE_PRESSURE;
		const struct particles *p = water ? &s->water : &s->soil;
		double sum = 0.0;
		long count = 0;
		for (idx_t k = 0; k < p->n; k++) {
			const double *x = p->x + 2 * k;
			if (x[0] >= pr->box_min[0] && x[0] <= pr->box_max[0] && x[1] >= pr->box_min[1] && x[1] <= pr->box_max[1]) {
				sum += field_value(s, pr->field, k, water);
				count++;
			}
		}
		return count ? sum / count : 0.0;
	}
	}
	return 0.0;
}
