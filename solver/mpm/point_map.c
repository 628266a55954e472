/*
 * point_map.c - the two-phase particle-to-grid phases every scheme shares (000 §4.5 steps 1-2):
 * the shape functions of both point sets, the soil's nodal mass, velocity, porosity, volume and
 * conductivity (Eqs. 44-47), the water's nodal mass, velocity and pressure (Eqs. 50-51, 77), the
 * momentum and velocity transfers with APIC's affine part when the points carry one, and the
 * node-wise mapping and remapping of a point scalar (Eq. 80).
 *
 * Single point: the water set rides on the soil points (same positions, volumes and porosity),
 * so every formula serves both variants.
 */
#include <math.h>
#include <string.h>

#include "phases.h"
#include "shape.h"
#include "transfer.h"

/* Step 1: shape functions and gradients of soil and (double point) water points. */
enum poro_status point_map_shapes(struct sim *s)
{
	enum case_shape kind = s->spec->formulation.shape;
	TRY(shape_evaluate(&s->grid, kind, &s->soil, "soil", &s->err));
	if (s->double_point)
		TRY(shape_evaluate(&s->grid, kind, &s->water, "water", &s->err));
	return PORO_OK;
}

/* Divides a nodal field (width 1 or 2) by a nodal weight where the weight is positive. */
void point_map_normalise(idx_t nodes, double *field, int width, const double *weight)
{
	#pragma omp parallel for schedule(static)
	for (idx_t I = 0; I < nodes; I++)
		for (int c = 0; c < width; c++)
			field[width * I + c] = weight[I] > 0.0 ? field[width * I + c] / weight[I] : 0.0;
}

/* The points carry APIC's affine velocity C_p ("apic" and "aflip", transfer.h). */
static int affine_velocities(const struct sim *s)
{
	return s->spec->formulation.velocity_update != VELOCITY_UPDATE_FLIP;
}

/* The point velocities' two transfers, with the affine part when the points carry one:
 * map_momentum adds out_I += sum_p S_Ip m_p v_p; gather_velocity sets v_p = sum_I S_Ip node_I
 * (PIC) and, with the affine part, the points' affine velocities C_p. */
void point_map_momentum(const struct sim *s, const struct particles *p, double *out)
{
	if (affine_velocities(s))
		p2g_affine_momentum(&s->grid, p, p->mass, p->v, p->C, out);
	else
		p2g_vector(&s->grid, p, p->mass, p->v, out);
}

void point_gather_velocity(const struct sim *s, struct particles *p, const double *node, double *v)
{
	if (affine_velocities(s))
		g2p_affine_velocity(&s->grid, p, node, v, p->C);
	else
		g2p_vector(&s->grid, p, node, v);
}

/* Eq. 47 where saturated and dry soil meet (a case with "saturated": false bodies): the water at a
 * node that a saturated body's points reach is that body's and flows through its pores, so k_I
 * there is the mass-weighted conductivity of the saturated points alone; a dry body's conductivity
 * acts only where none reaches, on water that has seeped into it. Mixing the two drained the clay
 * under a dry fill 100 times more permeable 5% of q (RMS) faster than Terzaghi's layer; 0.4%
 * without the mix (docs/numerics.md, "Dry bodies"). fit_moments is free until the water's mapping,
 * whose fit zeroes it again. */
static void conductivity_of_saturated_soil(struct sim *s)
{
	const struct particles *p = &s->soil;
	struct particles wet = *p;
	const idx_t nodes = s->grid.node_count;
	double *mass = s->f.fit_moments, *mass_k = mass + nodes;
	wet.n = s->saturated_soil;
	memset(mass, 0, 2 * sizeof(double) * (size_t)nodes);
	p2g_scalar(&s->grid, &wet, NULL, p->mass, mass);
	p2g_scalar(&s->grid, &wet, p->mass, p->conductivity, mass_k);
	for (idx_t I = 0; I < nodes; I++)
		if (mass[I] > 0.0)
			s->f.conductivity[I] = mass_k[I] / mass[I];
}

/* Step 2a-d: soil mass (Eq. 44), velocity (Eq. 45), porosity (Eq. 46), conductivity (Eq. 47). */
void point_map_soil(struct sim *s)
{
	const struct particles *p = &s->soil;
	struct grid_fields *f = &s->f;
	const int affine = affine_velocities(s);
	const struct p2g_batch b = {
		.scalars = 4,
		.scalar = {{NULL, p->mass, f->mass_s}, {p->mass, p->porosity, f->porosity},
			   {NULL, p->volume, f->volume_s}, {p->mass, p->conductivity, f->conductivity}},
		.vector = {p->mass, p->v, affine ? NULL : f->v_s},   /* the affine momentum: point_map_momentum */
	};
	p2g_batch(&s->grid, p, &b);
	if (affine)
		point_map_momentum(s, p, f->v_s);
	s->mapped_mass_s = 0.0;
	for (idx_t q = 0; q < p->n; q++)
		s->mapped_mass_s += p->mass[q];
	idx_t nodes = s->grid.node_count;
	point_map_normalise(nodes, f->v_s, 2, f->mass_s);
	point_map_normalise(nodes, f->conductivity, 1, f->mass_s);
	if (s->saturated_soil < p->n)
		conductivity_of_saturated_soil(s);
	const double k_loading = s->spec->gravity.loading_conductivity;
	const int loading = k_loading > 0.0 && loads_in_gravity_ramp(s);
	#pragma omp parallel for schedule(static)
	for (idx_t I = 0; I < nodes; I++) {
		const double Ms = f->mass_s[I];
		f->porosity[I] = Ms > 0.0 ? f->porosity[I] / Ms : 1.0;   /* no soil: the pores are all water */
		if (loading)   /* 000 §5.4: drain the loading's excess pressure */
			f->conductivity[I] = Ms > 0.0 ? k_loading : 0.0;
	}
	memcpy(f->v_s_old, f->v_s, 2 * sizeof(double) * (size_t)nodes);
}

/* Step 2e-f: water mass (Eq. 50), water velocity (Eq. 51) and the nodal pressure p^t, in one
 * loop over the water points (as the mass-weighted mean of Eq. 77, or as its linear fit after the
 * loop: phases.h, enum nodal_pressure). Double point
 * first takes steps 8h-8i of the last step at each point, from the nodal porosity just mapped (so
 * they use the points' current positions): the soil porosity seen by the water point (Eq. 48) and
 * its volume V_wp = n0 / n V0 (Eq. 36). Single-point water shares the soil points' porosity and
 * volume. */
void point_map_water(struct sim *s, enum nodal_pressure nodal)
{
	struct particles *w = &s->water;
	struct grid_fields *f = &s->f;
	const idx_t nodes = s->grid.node_count;
	const int affine = affine_velocities(s);
	const int mean_pressure = nodal == NODAL_PRESSURE_MEAN;   /* the fit comes after the loop */
	const struct p2g_batch b = {
		.scalars = mean_pressure ? 3 : 2,
		.scalar = {{NULL, w->volume, f->mass_w_v}, {NULL, w->mass, f->mass_w_points},
			   {w->mass, w->pressure, f->pressure}},
		.vector = {w->mass, w->v, affine ? NULL : f->v_w},   /* the affine momentum: point_map_momentum */
	};
	const int double_point = s->double_point;
	const double rho_w = s->rho_w;
	FOR_POINTS_BY_BLOCK(w, q, {
		if (double_point) {
			w->porosity[q] = g2p_scalar_point(&s->grid, w, q, f->porosity);
			w->volume[q] = w->porosity0[q] / w->porosity[q] * w->volume0[q];
		}
		/* n rho_w V: constant n0 rho_w V0 in double point (Eq. 37) */
		w->mass[q] = w->porosity[q] * rho_w * w->volume[q];
		p2g_batch_point(&s->grid, w, q, &b);
	});
	s->mapped_mass_w = 0.0;   /* in index order after the loop: the same sum at any thread count */
	for (idx_t q = 0; q < w->n; q++)
		s->mapped_mass_w += w->mass[q];
	if (affine)
		point_map_momentum(s, w, f->v_w);
	point_map_normalise(nodes, f->v_w, 2, f->mass_w_points);
	if (mean_pressure)
		point_map_normalise(nodes, f->pressure, 1, f->mass_w_points);
	else   /* nodes no water point reaches keep the reset's 0, as the mean gives them */
		p2g_scalar_linear_fit(&s->grid, w, w->mass, w->pressure, f->fit_moments, f->pressure);
	#pragma omp parallel for schedule(static)
	for (idx_t I = 0; I < nodes; I++)   /* Eq. 50: grid porosity times sum S rho_w V_wp */
		f->mass_w[I] = f->porosity[I] * s->rho_w * f->mass_w_v[I];
	memcpy(f->v_w_old, f->v_w, 2 * sizeof(double) * (size_t)nodes);
}

/* Node-wise mapping and remapping of a soil-point scalar (000 Eq. 80, steps 9b-9c):
 * avg_p = sum_I S_Ip (sum_q S_Iq m_q value_q / M_sI). The nodal pressure array holds the nodal
 * average: a scheme calls this only once the step no longer needs f->pressure. */
void point_map_average_nodewise(struct sim *s, const double *value, double *avg)
{
	struct particles *p = &s->soil;
	double *nodal = s->f.pressure;
	memset(nodal, 0, sizeof(double) * (size_t)s->grid.node_count);
	p2g_scalar(&s->grid, p, p->mass, value, nodal);
	point_map_normalise(s->grid.node_count, nodal, 1, s->f.mass_s);
	g2p_scalar(&s->grid, p, nodal, avg);
}
