/*
 * fbar.c - the soil-phase stabilisations of 000 §4.4.2 (formulation.soil_stabilisation): F-bar
 * on the deformation-gradient increment (Eqs. 79-80) and the modified F-bar's patch-wise average
 * of the elastic Jacobian (Eqs. 81-83), on fixed patches laid out once per run.
 */
#include <math.h>
#include <string.h>

#include "phases.h"

/* The patch of point q in the fixed tiling laid out by fbar_patches_init. */
static idx_t patch_of(const struct sim *s, idx_t q)
{
	idx_t ij[2];
	for (int d = 0; d < 2; d++) {
		double u = (s->soil.x[2 * q + d] - s->grid.origin[d]) / s->patch_width[d];
		idx_t i = (idx_t)floor(u);
		ij[d] = i < 0 ? 0 : i >= s->patches[d] ? s->patches[d] - 1 : i;
	}
	return ij[0] + ij[1] * s->patches[0];
}

/* Patch-wise mass average of a soil-point scalar (000 Eq. 83): every point of a patch gets
 * sum_{q in patch} m_q value_q / sum_{q in patch} m_q. The patch sums stay serial, in index
 * order (the same at any thread count): two additions a point, and a patch is found from the
 * point's position, not its node0, so the scatters' block order (point_blocks.h) does not apply. */
static void average_patchwise(struct sim *s, const double *value, double *avg)
{
	const struct particles *p = &s->soil;
	const idx_t count = s->patches[0] * s->patches[1];
	memset(s->patch_mass, 0, sizeof(double) * (size_t)count);
	memset(s->patch_mass_Je, 0, sizeof(double) * (size_t)count);
	for (idx_t q = 0; q < p->n; q++) {
		idx_t k = patch_of(s, q);
		s->patch_mass[k] += p->mass[q];
		s->patch_mass_Je[k] += p->mass[q] * value[q];
	}
	#pragma omp parallel for schedule(static)
	for (idx_t q = 0; q < p->n; q++) {
		idx_t k = patch_of(s, q);   /* a point's own patch has its mass: the division is safe */
		avg[q] = s->patch_mass_Je[k] / s->patch_mass[k];
	}
}

/* The patch size h_patch of 000 §4.4.2: 1.5 h for quadratic and cubic B-splines, the cell for
 * linear shape functions and for the cell-wise variant (App. A's h_patch = h). The grid is tiled
 * by round(extent / h_patch) patches per direction of equal width, so no sliver patch is left at
 * the far edge (10 m at h = 0.2 m: 33 patches of 0.303 m). Patches are fixed in space for the run
 * ("defined only once"); a point belongs to the patch that contains it at the time. */
void fbar_patches_init(struct sim *s)
{
	const struct case_formulation *f = &s->spec->formulation;
	const double cells_per_patch = f->soil_stabilisation == STABILISATION_MODIFIED_FBAR &&
				       f->shape != SHAPE_LINEAR ? 1.5 : 1.0;
	for (int d = 0; d < 2; d++) {
		idx_t n = (idx_t)lround((double)s->grid.cells[d] / cells_per_patch);
		s->patches[d] = n < 1 ? 1 : n;
		s->patch_width[d] = (double)s->grid.cells[d] * s->grid.h / (double)s->patches[d];
	}
}

/* Steps 9c-9d, F-bar (000 Eqs. 79-80): each soil point's deformation-gradient increment is scaled
 * so that its volume change equals the node-wise average dJbar, dFbar = (dJbar / dJ)^(1/dof) dF,
 * dof = 2. The scaled increment serves the volume, porosity and stress updates alike, so the
 * points' volumes stay those the stress sees. Shared by the standard and the modified F-bar. */
static void apply_fbar(struct sim *s)
{
	struct particles *p = &s->soil;
	double *dJ = s->soil_scalar, *dJbar = s->soil_coef;
	#pragma omp parallel for schedule(static)
	for (idx_t q = 0; q < p->n; q++) {
		const double *dF = p->dF + 4 * q;
		dJ[q] = dF[0] * dF[3] - dF[1] * dF[2];
	}
	point_map_average_nodewise(s, dJ, dJbar);
	#pragma omp parallel for schedule(static)
	for (idx_t q = 0; q < p->n; q++) {
		if (!(dJ[q] > 0.0) || !(dJbar[q] > 0.0))
			continue;   /* an inverted point is reported by the caller */
		const double scale = sqrt(dJbar[q] / dJ[q]);
		for (int c = 0; c < 4; c++)
			p->dF[4 * q + c] *= scale;
	}
}

/* Steps 9e-9g, modified F-bar (000 Eqs. 81-83): the elastic Jacobian of the last step,
 * J^e = sqrt(det Be^t) with det over the full 3x3 tensor (Be_zz included), is replaced by its
 * patch-wise mass average: Be^t is scaled so that its J^e becomes Jbar^e. Eq. 82 writes the factor
 * (Jbar^e / J^e)^(2/3), which scales all of a 3-D Be; in plane strain we scale the in-plane block
 * by (Jbar^e / J^e)^(2/dof), dof = 2 (as Eq. 79 does for dF), and keep Be_zz: the determinant then
 * reaches Jbar^e^2 just the same and the out-of-plane stretch stays that of plane strain. Models
 * without an evolving Be (small strain) keep Be = I, J^e = 1, and are untouched. */
static void stabilise_elastic_strain(struct sim *s)
{
	struct particles *p = &s->soil;
	double *Je = s->soil_scalar, *Jebar = s->soil_coef;
	#pragma omp parallel for schedule(static)
	for (idx_t q = 0; q < p->n; q++) {
		const double *Be = p->Be + 4 * q;
		double det = (Be[0] * Be[1] - Be[2] * Be[2]) * Be[3];
		Je[q] = det > 0.0 ? sqrt(det) : 0.0;
	}
	average_patchwise(s, Je, Jebar);
	#pragma omp parallel for schedule(static)
	for (idx_t q = 0; q < p->n; q++) {
		if (!(Je[q] > 0.0) || !(Jebar[q] > 0.0))
			continue;   /* a degenerate Be is reported by the stress update */
		const double scale = Jebar[q] / Je[q];
		for (int c = 0; c < 3; c++)
			p->Be[4 * q + c] *= scale;
	}
}

/* Step 9b-9g: the soil-phase stabilisation chosen by the case (000 §4.4.2). The pore-pressure
 * smoothing (9a) is part of step 7c (see the top of this file). */
void fbar_stabilise(struct sim *s)
{
	const enum soil_stabilisation kind = s->spec->formulation.soil_stabilisation;
	if (kind == STABILISATION_NONE)
		return;
	apply_fbar(s);                                     /* (9c-d) Eqs. 79-80 */
	if (kind == STABILISATION_MODIFIED_FBAR || kind == STABILISATION_MODIFIED_FBAR_CELLWISE)
		stabilise_elastic_strain(s);               /* (9e-g) Eqs. 82-83 */
}
