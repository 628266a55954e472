/*
 * step_health.c - the likely cause of a failed step, and the run's small-strain warning
 * (step_health.h).
 */
#include "step_health.h"

#include <math.h>
#include <stdio.h>

#include "material.h"
#include "stable_dt.h"

/* The soil point of a small-strain material (one whose stress comes from the small-strain
 * increment without the finite kinematics of 000 Eqs. 69-76, material.h) whose |J - 1| is
 * largest, -1 if none; *J its J. */
static idx_t worst_small_strain_point(const struct sim *s, double *J)
{
	const struct particles *p = &s->soil;
	idx_t worst = -1;
	double excess = 0.0;
	int any = 0;
	for (int i = 0; i < s->spec->material_count; i++)
		any |= !material_is_finite_strain(&s->materials[i]);
	if (!any)   /* finite-strain cases skip the loop over the points */
		return -1;
	for (idx_t q = 0; q < p->n; q++) {
		if (material_is_finite_strain(&s->materials[s->spec->bodies[p->body[q]].material]))
			continue;
		const double Jq = p->volume[q] / p->volume0[q];
		if (fabs(Jq - 1.0) > excess)
			excess = fabs(Jq - 1.0), worst = q, *J = Jq;
	}
	return worst;
}

/* The largest value a load's time function takes. */
static double time_function_peak(const struct case_time_function *f)
{
	return f->kind == TIME_SINUSOID ? fabs(f->mean) + fabs(f->amplitude) : 1.0;
}

double step_health_load_strain(const struct case_spec *c, int *body)
{
	double worst = 0.0;
	*body = -1;
	const double g = hypot(c->gravity.acceleration[0], c->gravity.acceleration[1]);
	for (int i = 0; i < c->body_count; i++) {
		const struct case_body *b = &c->bodies[i];
		double stress = fabs(stable_dt_effective_density(c, i)) * g * (b->max[1] - b->min[1]);
		for (int l = 0; l < c->load_count; l++)
			if (c->loads[l].body == i)
				stress += hypot(c->loads[l].traction[0], c->loads[l].traction[1]) *
					  time_function_peak(&c->loads[l].time_function);
		const double strain = stress / stable_dt_modulus(c, i);
		if (strain > worst)
			worst = strain, *body = i;
	}
	return worst;
}

void step_health_explain(struct sim *s)
{
	const struct stable_dt *e = &s->stable;
	if (e->body >= 0 && e->scheme == SCHEME_EXPLICIT) {
		char bound[STABLE_DT_DESCRIPTION_SIZE];
		stable_dt_describe(e, s->spec, bound, sizeof bound);
		const double ratio = s->dt / e->cfl;
		poro_error_append(&s->err, "likely cause: %s: dt = %.6g s is %.3g of %s",
				  ratio > STEP_HEALTH_EXPLICIT_DT_SUSPECT ? "a time step near or above the stability limit, "
				  "take a smaller dt" : "not the time step, which is inside the stability limit",
				  s->dt, ratio, bound);
	} else if (e->body >= 0) {
		const double ratio = s->dt / e->cfl;
		poro_error_append(&s->err, "likely cause: %s: dt = %.6g s is %.3g times the soil skeleton's CFL step "
				  "h / c_p = %.6g s (c_p = %.6g m/s in body '%s'); the Terzaghi column's measured limit "
				  "is 0.87-2.5 h / c_p depending on the permeability and the formulation "
				  "(docs/numerics.md \"Stable time step\")",
				  ratio > STEP_HEALTH_DT_SUSPECT ? "a time step near or above the stability limit, take a smaller dt"
				  : "not the time step, which is well inside the stability limit",
				  s->dt, ratio, e->cfl, e->wave_speed, s->spec->bodies[e->body].name);
	}
	int body;
	const double strain = step_health_load_strain(s->spec, &body);
	if (strain > STEP_HEALTH_SMALL_STRAIN_LIMIT / 2)
		poro_error_append(&s->err, "and a material soft for its load: the loads and the weight of body '%s' "
				  "strain its skeleton by about %.3g (their stress over its constrained modulus %.4g Pa)",
				  s->spec->bodies[body].name, strain, stable_dt_modulus(s->spec, body));
	if (s->warning[0])
		poro_error_append(&s->err, "warning before the failure: %s", s->warning);
}

void step_health_watch(struct sim *s)
{
	if (s->warning[0])
		return;
	double J = 1.0;
	const idx_t q = worst_small_strain_point(s, &J);
	if (q < 0 || !(fabs(J - 1.0) > STEP_HEALTH_SMALL_STRAIN_LIMIT))
		return;
	const struct particles *p = &s->soil;
	const struct case_material *m = &s->spec->materials[s->spec->bodies[p->body[q]].material];
	snprintf(s->warning, sizeof s->warning,
		 "soil point %ld of material '%s' at (%.6g, %.6g) m reached a volume ratio J = %.4g at step %ld "
		 "(t = %.6g s): its small-strain model is used beyond |J - 1| = %g, outside its validity; a "
		 "finite-strain model (\"hencky\", or \"strain\": \"finite\") or a stiffer material is needed",
		 (long)q, m->name, p->x[2 * q], p->x[2 * q + 1], J, s->step, s->time, STEP_HEALTH_SMALL_STRAIN_LIMIT);
}
