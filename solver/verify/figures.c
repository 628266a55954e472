/*
 * figures.c - the figures of a run and the accuracy figures' computations, see figures.h.
 *
 * The column figures read the case as 000 §5.1-5.2 and tools/terzaghi_error.c do (symbols of
 * 000 Eqs. 84-90): q the magnitude of the first load's traction, H the first body's height, m_v =
 * (1 + nu)(1 - 2 nu) / ((1 - nu) E) of its material (Eq. 86), c_v = k / (rho_w g m_v), drainage
 * length Hd = H, or H/2 when the bottom face drains too, Tv = c_v t / Hd^2, z the depth below the
 * nearer drained face.
 */
#include "figures.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "analytic.h"
#include "case.h"
#include "element.h"
#include "particles.h"

#define G 9.81   /* gravitational acceleration in c_v, m/s^2 (000 Eq. 85) */
#define DEG (M_PI / 180.0)

static const struct {
	const char *name, *unit;
	enum figure_class cls;
	unsigned where;
} FIGURES[] = {
#define FIGURE_ROW(kind, name, unit, cls, where) { name, unit, cls, where },
	FIGURE_MAP(FIGURE_ROW)
#undef FIGURE_ROW
};

static const char *const MEANINGS[FIGURE_COUNT] = {
	[FIGURE_WALL_SECONDS] = "wall time of the steps this process took",
	[FIGURE_CPU_SECONDS] = "processor time of the steps this process took, all threads",
	[FIGURE_US_PER_POINT_STEP] = "wall microseconds per material-point step",
	[FIGURE_CPU_US_PER_POINT_STEP] = "processor microseconds per material-point step",
	[FIGURE_MEDIAN_STEP_CPU_US] = "the median step's processor microseconds per material point",
	[FIGURE_REFERENCE_KERNEL_US] = "the reference kernel's median processor microseconds, timed after each step",
	[FIGURE_RELATIVE_STEP_COST] = "the median material-point step in thousandths of the reference kernel",
	[FIGURE_STEPS] = "steps taken",
	[FIGURE_MAX_DISPLACEMENT] = "largest displacement of a soil point at the end",
	[FIGURE_TERZAGHI_RMS] = "RMS pore-pressure error against Terzaghi's closed form, over q, at the end",
	[FIGURE_XIE_LEO_SETTLEMENT] = "relative error of the top settlement against Xie and Leo's closed form",
	[FIGURE_RUNOUT] = "run-out of the slope's soil at the last frame",
	[FIGURE_PEAK_Q] = "largest deviator stress q of the element test",
	[FIGURE_NEWTON_ITERATIONS] = "Newton iterations of all steps (element test, or a scheme that iterates)",
	[FIGURE_MOHR_COULOMB_PEAK] = "relative error of q at failure against the Mohr-Coulomb closed form",
};

const char *figure_name(enum figure_kind k) { return k < FIGURE_COUNT ? FIGURES[k].name : "unknown"; }
const char *figure_unit(enum figure_kind k) { return k < FIGURE_COUNT ? FIGURES[k].unit : ""; }
enum figure_class figure_class(enum figure_kind k) { return FIGURES[k].cls; }
unsigned figure_where(enum figure_kind k) { return k < FIGURE_COUNT ? FIGURES[k].where : 0; }
const char *figure_meaning(enum figure_kind k) { return k < FIGURE_COUNT ? MEANINGS[k] : ""; }

const char *figure_class_name(enum figure_class c)
{
	return c == FIGURE_ACCURACY ? "accuracy" : c == FIGURE_TIMING ? "timing" : "count";
}

int figure_parse(const char *name)
{
	for (int k = 0; k < FIGURE_COUNT; k++)
		if (!strcmp(name, FIGURES[k].name))
			return k;
	return -1;
}

/* ---- the loaded column (000 §5.1-5.2) ---- */

struct column {
	double q, H, top, bottom, Hd, mv, cv, nu;
	int drained_both;
};

/* 0 with the column of c, or -1 with why. */
static int column_of(const struct case_spec *c, struct column *col, char *why, size_t why_size)
{
	if (c->body_count < 1 || c->load_count < 1 || c->loads[0].body != 0 || c->loads[0].face != FACE_TOP) {
		snprintf(why, why_size, "needs a loaded column: the first load on the top face of the first body");
		return -1;
	}
	const struct case_body *b = &c->bodies[0];
	const struct case_material *m = &c->materials[b->material];
	*col = (struct column){ .q = hypot(c->loads[0].traction[0], c->loads[0].traction[1]), .top = b->max[1],
				.bottom = b->min[1], .nu = m->poisson_ratio };
	col->H = col->top - col->bottom;
	col->drained_both = c->boundaries[FACE_BOTTOM].drainage == DRAINAGE_DRAINED;
	col->Hd = col->drained_both ? col->H / 2 : col->H;
	col->mv = (1 + col->nu) * (1 - 2 * col->nu) / ((1 - col->nu) * m->youngs_modulus);   /* 000 Eq. 86 */
	col->cv = b->hydraulic_conductivity / (c->fluid.density * G * col->mv);
	if (!(col->q > 0) || !(col->H > 0)) {
		snprintf(why, why_size, "needs a loaded column: the first load's traction and the first body's height "
			 "must not be zero");
		return -1;
	}
	return 0;
}

int figure_check(const struct case_spec *c, enum figure_kind k, char *why, size_t why_size)
{
	struct column col;
	if (!(figure_where(k) & FIGURE_SIM)) {
		snprintf(why, why_size, "'%s' is a figure of element tests (\"schema\": \"poro-element/1\")", figure_name(k));
		return -1;
	}
	switch (k) {
	case FIGURE_TERZAGHI_RMS:
		return column_of(c, &col, why, why_size);
	case FIGURE_XIE_LEO_SETTLEMENT:
		if (column_of(c, &col, why, why_size))
			return -1;
		if (col.drained_both || col.nu != 0) {
			snprintf(why, why_size, "needs a column drained at the top only with Poisson ratio 0 (000 §5.2)");
			return -1;
		}
		/* the closed form is of a linear elastic soil; a Hencky column settles about 17% less
		 * (000 §5.2), so the figure would measure the model, not the solver */
		if (c->materials[c->bodies[0].material].model != MODEL_LINEAR_ELASTIC) {
			snprintf(why, why_size, "needs a linear_elastic soil: Xie and Leo's closed form is of one (000 §5.2)");
			return -1;
		}
		return 0;
	case FIGURE_NEWTON_ITERATIONS:
		if (c->formulation.scheme != SCHEME_IMPLICIT_UPU) {
			snprintf(why, why_size, "needs a scheme that iterates within a step (\"scheme\": \"implicit_upU\")");
			return -1;
		}
		return 0;
	case FIGURE_RUNOUT:
		for (int i = 0; i < c->body_count; i++)
			if (!c->bodies[i].is_polygon) {
				snprintf(why, why_size, "needs every body to be a polygon (a slope: docs/report.md)");
				return -1;
			}
		return 0;
	default:
		return 0;
	}
}

int figure_check_element(const struct element_case *c, enum figure_kind k, char *why, size_t why_size)
{
	if (!(figure_where(k) & FIGURE_ELEMENT)) {
		snprintf(why, why_size, "'%s' is a figure of simulation runs, not of element tests", figure_name(k));
		return -1;
	}
	if (k == FIGURE_MOHR_COULOMB_PEAK && (c->material.model != MODEL_MOHR_COULOMB || c->test != ELEMENT_DRAINED ||
					      !(c->axial_strain < 0))) {
		snprintf(why, why_size, "needs a drained compression test of a mohr_coulomb material");
		return -1;
	}
	return 0;
}

double figure_reference_height(const struct particles *p, double y, double top0)
{
	const double x_ref = p->x0[0];
	double below_y = -1e300, below_y0 = 0, above_y = 1e300, above_y0 = top0;
	for (idx_t q = 0; q < p->n; q++) {
		if (fabs(p->x0[2 * q] - x_ref) > 1e-9)
			continue;
		double yq = p->x[2 * q + 1], y0 = p->x0[2 * q + 1];
		if (yq <= y && yq > below_y)
			below_y = yq, below_y0 = y0;
		if (yq > y && yq < above_y)
			above_y = yq, above_y0 = y0;
	}
	if (below_y < -1e299)
		return above_y > 0 ? above_y0 * y / above_y : top0;
	if (above_y > 1e299)
		return top0;    /* above the top row: inside the drained skin */
	return below_y0 + (above_y0 - below_y0) * (y - below_y) / (above_y - below_y);
}

double figure_terzaghi_rms(const struct case_spec *c, const struct particles *soil, double t, const double *p,
			   const double *xy, long n)
{
	struct column col;
	char why[160];
	if (column_of(c, &col, why, sizeof why) || n < 1)
		return NAN;
	double Tv = col.cv * t / (col.Hd * col.Hd), sum = 0;
	for (long i = 0; i < n; i++) {
		double y = figure_reference_height(soil, xy[2 * i + 1], col.top) - col.bottom;
		double z = col.drained_both ? fmin(col.H - y, y) : col.H - y;
		double e = (p[i] - terzaghi_pressure(z, col.Hd, Tv, col.q)) / col.q;
		sum += e * e;
	}
	return sqrt(sum / (double)n);
}

double figure_xie_leo_settlement(const struct case_spec *c, const struct particles *soil, double t)
{
	struct column col;
	char why[160];
	if (column_of(c, &col, why, sizeof why))
		return NAN;
	const struct case_body *b = &c->bodies[0];
	double spacing = c->grid.cell_size / b->particles_per_cell, sum = 0;
	long count = 0;
	for (idx_t q = 0; q < soil->n; q++) {
		if (soil->body[q] != 0 || soil->x0[2 * q + 1] < col.top - spacing)
			continue;
		/* the row's current top edge: half a spacing above the point, stretched by F_yy */
		double top = soil->x[2 * q + 1] + 0.5 * spacing * soil->F[4 * q + 3];
		sum += col.top - top;
		count++;
	}
	double Tv = col.cv * t / (col.H * col.H);
	double want = xie_leo_settlement(col.H, col.mv, col.q, Tv);
	return count && want > 0 ? fabs(sum / (double)count - want) / want : NAN;
}

double figure_max_displacement(const struct particles *soil)
{
	double worst = 0;
	for (idx_t q = 0; q < soil->n; q++)
		worst = fmax(worst, hypot(soil->x[2 * q] - soil->x0[2 * q], soil->x[2 * q + 1] - soil->x0[2 * q + 1]));
	return worst;
}

double figure_mohr_coulomb_peak_error(const struct element_case *c, double q_last, double J_last)
{
	const struct case_material *m = &c->material;
	double srf = m->strength_reduction_factor > 0 ? m->strength_reduction_factor : 1;
	double phi = atan(tan(m->friction_angle * DEG) / srf), coh = m->cohesion / srf;   /* 000 Eq. 91 */
	double J = m->strain == STRAIN_FINITE ? J_last : 1.0;
	double want = mohr_coulomb_drained_peak_q(c->confining_pressure, coh, phi, J);
	return fabs(q_last - want) / want;
}
