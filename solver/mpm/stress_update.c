/*
 * stress_update.c - the soil points' stress update through the material interface (000 step 10,
 * Eqs. 69-76), with the gravity-loading stages of 000 App. B.4, shared by every scheme.
 */
#include "phases.h"

/* Step 10: stress update through the material interface (Eqs. 69-76). The points are independent;
 * they are shared among the threads in small dynamic chunks (a plastic return costs several times an
 * elastic one, and plastic points cluster). Every point is updated, and the failure reported is the
 * lowest-numbered failing point's, as a serial loop would report it, whatever the thread count. */
enum poro_status stress_update(struct sim *s)
{
	struct particles *p = &s->soil;
	const int stage = loads_gravity_loading_stage(s);
	idx_t first_failure = p->n;
	/* 000 Eqs. 96-97: Nor-Sand's specific volume from J mapped to the nodes and back (step 9's
	 * node-wise averaging, on the total J^{t+1}); the stress keeps the point's own J */
	const double *J_v = NULL;
	if (s->spec->formulation.specific_volume == SPECIFIC_VOLUME_NODAL_AVERAGE) {
		#pragma omp parallel for schedule(static)
		for (idx_t q = 0; q < p->n; q++)
			s->soil_scalar[q] = p->volume[q] / p->volume0[q];
		point_map_average_nodewise(s, s->soil_scalar, s->soil_coef);
		J_v = s->soil_coef;
	}
	#pragma omp parallel
	{
		struct poro_error err;   /* filled by the thread's first failure only */
		idx_t failed = p->n;
		#pragma omp for schedule(dynamic, 64)
		for (idx_t q = 0; q < p->n; q++) {
			const struct material *m = &s->materials[s->spec->bodies[p->body[q]].material];
			const double *dF = p->dF + 4 * q;
			if (stage == 2) {   /* the volume is already this step's: J at the end of the ramp is J / dJ */
				const double J_ramp = p->volume[q] / p->volume0[q] / (dF[0] * dF[3] - dF[1] * dF[2]);
				material_reset_reference(m, p->stress + 4 * q, p->Be + 4 * q, J_ramp,
							 p->state + STATE_MAX * q);
				p->plastic_strain[q] = 0.0;
			}
			struct stress_update u = {
				.dF = dF,
				.dF_zz = p->dF_zz ? p->dF_zz[q] : 0.0,
				.J = p->volume[q] / p->volume0[q],
				.J_v = J_v ? J_v[q] : 0.0,
				.stress = p->stress + 4 * q,
				.Be = p->Be + 4 * q,
				.state = p->state + STATE_MAX * q,
				.plastic_strain = p->plastic_strain + q,
				.elastic_only = stage == 1,
			};
			/* a thread takes its chunks in increasing order: its first failure is its lowest */
			if (material_update(m, &u, failed < p->n ? NULL : &err) != PORO_OK && failed == p->n)
				failed = q;
		}
		#pragma omp critical(stress_update_failure)
		if (failed < first_failure) {
			first_failure = failed;
			s->err = err;
		}
	}
	return first_failure < p->n ? s->err.code : PORO_OK;
}
