/*
 * strip_load_test.c - the strip load on a saturated layer of 002 §4.2 (Table 2), run with the
 * semi-implicit double-point scheme (tests/cases/strip_load_002.json) and with 002's own explicit
 * stabilised single-point scheme (tests/cases/strip_load_002_explicit.json).
 *
 * 002 states a 10 m x 10 m half domain, 0.05 m cells, 2x2 points per cell, 1,600 points and a
 * 0.3 m strip. These do not fit together: 10 m x 10 m at 2x2 per cell has 1,600 points per set
 * only with 0.5 m cells, and a 0.3 m strip would then be under one cell. The case reads the cell
 * and the strip as a factor-10 slip (0.5 m cells, 3 m half-strip); the earlier reading, a
 * 1 m x 1 m domain with 0.05 m cells and the 0.3 m strip, displaced 0.561 mm, twelve times less
 * than 002 reports. Asserted: the maximum displacement at t = 0.1 s within
 * DISPLACEMENT_TOLERANCE of 002's 6.737 mm (measured 6.618 mm, 1.8% below), and the pore
 * pressure has no checkerboard. The measure is the RMS over interior points of p_i minus the
 * mean of its four lattice neighbours (reference positions), divided by max |p|: a checkerboard
 * scores O(1), a smooth field O(h^2). With the node-wise smoothing (000 Eq. 77) it must stay
 * below 1%, and switching the smoothing off must raise it at least five-fold (002 Fig. 10).
 * Soil and water mass are conserved to 1e-12.
 *
 * The explicit scheme (002 §4.2's own): the maximum displacement at t = 0.1 s within
 * EXPLICIT_DISPLACEMENT_TOLERANCE (5%) of 6.737 mm; the same roughness at most 2% with its
 * stabilisations (the cell average of the volumetric strain rates, Eqs. 26-27, and the multi-field
 * pressure rate, Eqs. 33-34) and at least five times higher with both off (002 Fig. 10b's
 * checkerboard); and its oscillation index of the pore pressure (oscillation.h, at the scale of
 * the points) printed beside it.
 */
#include "../harness.h"
#include "case.h"
#include "oscillation.h"
#include "pressure_roughness.h"
#include "poro.h"

#define CASE_FILE "tests/cases/strip_load_002.json"
#define EXPLICIT_CASE_FILE "tests/cases/strip_load_002_explicit.json"
#define EXPLICIT_DISPLACEMENT_TOLERANCE 0.05
#define EXPLICIT_ROUGHNESS_MAX 0.02
#define PAPER_MAX_DISPLACEMENT 6.737e-3   /* m, 002 §4.2 at t = 0.1 s */
#define DISPLACEMENT_TOLERANCE 0.03        /* relative */

struct outcome {
	double umax, roughness, oscillation, drift;
	int ok;
};

/* Runs a case file to its end, its stabilisation on or off: the semi-implicit scheme's node-wise
 * pressure smoothing (000 Eq. 77), the explicit scheme's two (002 §3.2). */
static struct outcome run(const char *file, int stabilised)
{
	struct outcome o = {0};
	struct case_spec *c = NULL;
	struct sim *s = NULL;
	struct poro_error err = {0};
	o.ok = !case_load_file(file, &c, &err);
	if (o.ok) {
		c->formulation.pore_pressure_smoothing = stabilised;
		if (!stabilised) {
			c->formulation.strain_rate_smoothing = STRAIN_RATE_SMOOTHING_NONE;
			c->formulation.pressure_rate_projection = PRESSURE_RATE_NONE;
		}
		o.ok = !sim_create(&s, c, &err);
	}
	if (!o.ok) {
		printf("INFO cannot run %s: %s\n", file, err.message);
		return o;
	}
	double ms0 = sim_soil_mass(s), mw0 = sim_water_mass(s);
	while (o.ok && !sim_done(s)) {
		o.ok = !sim_step(s);
		double ds = fabs(sim_soil_mass(s) - ms0) / ms0;
		double dw = fabs(sim_water_mass(s) + sim_water_outflow_mass(s) - mw0) / mw0;
		o.drift = fmax(o.drift, fmax(ds, dw));
	}
	if (!o.ok)
		printf("INFO strip load failed: %s\n", sim_error(s)->message);
	const struct particles *p = sim_soil(s);
	for (idx_t q = 0; q < p->n; q++)
		o.umax = fmax(o.umax, hypot(p->x[2 * q] - p->x0[2 * q], p->x[2 * q + 1] - p->x0[2 * q + 1]));
	const double spacing = c->grid.cell_size / c->bodies[0].particles_per_cell;
	o.roughness = pressure_roughness(sim_water(s), spacing);
	if (oscillation_index_of(&c->grid, sim_soil(s), spacing, 1, sim_is_double_point(s) ? NULL : sim_water(s)->pressure,
				 &o.oscillation, &err))
		o.oscillation = NAN;   /* double point: the pressure lives on the water points */
	sim_destroy(&s);
	case_destroy(&c);
	return o;
}

static void check_explicit(void)
{
	struct outcome smooth = run(EXPLICIT_CASE_FILE, 1), rough = run(EXPLICIT_CASE_FILE, 0);
	printf("INFO strip load, explicit scheme, t=0.1 s: maximum displacement %.3f mm (002: %.3f mm; %.3f mm "
	       "without stabilisation); pore-pressure roughness %.4f with the stabilisations, %.4f without; "
	       "oscillation index of p %.4f and %.4f\n", 1e3 * smooth.umax, 1e3 * PAPER_MAX_DISPLACEMENT,
	       1e3 * rough.umax, smooth.roughness, rough.roughness, smooth.oscillation, rough.oscillation);
	CHECK(smooth.ok && rough.ok, "strip_load_explicit_runs", "a run failed");
	const double rel = fabs(smooth.umax - PAPER_MAX_DISPLACEMENT) / PAPER_MAX_DISPLACEMENT;
	CHECK(smooth.ok && rel <= EXPLICIT_DISPLACEMENT_TOLERANCE, "strip_load_explicit_max_displacement_matches_002",
	      "%.3f mm against 002's %.3f mm (%.1f%%)", 1e3 * smooth.umax, 1e3 * PAPER_MAX_DISPLACEMENT, 100 * rel);
	CHECK(smooth.ok && smooth.roughness <= EXPLICIT_ROUGHNESS_MAX, "strip_load_explicit_pore_pressure_smooth",
	      "roughness %.4f", smooth.roughness);
	CHECK(rough.roughness >= 5 * smooth.roughness, "strip_load_explicit_stabilisation_removes_checkerboard",
	      "roughness %.4f without vs %.4f with", rough.roughness, smooth.roughness);
}

int main(void)
{
	check_explicit();
	struct outcome smooth = run(CASE_FILE, 1), rough = run(CASE_FILE, 0);
	printf("INFO strip load t=0.1 s: maximum displacement %.3f mm (002: %.3f mm); pore-pressure "
	       "roughness %.4f with smoothing, %.4f without\n", 1e3 * smooth.umax, 1e3 * PAPER_MAX_DISPLACEMENT,
	       smooth.roughness, rough.roughness);
	CHECK(smooth.ok && rough.ok, "strip_load_runs", "a run failed");
	const double rel = fabs(smooth.umax - PAPER_MAX_DISPLACEMENT) / PAPER_MAX_DISPLACEMENT;
	CHECK(smooth.ok && rel <= DISPLACEMENT_TOLERANCE, "strip_load_max_displacement_matches_002",
	      "%.3f mm against 002's %.3f mm (%.1f%%)", 1e3 * smooth.umax, 1e3 * PAPER_MAX_DISPLACEMENT, 100 * rel);
	CHECK(smooth.ok && smooth.roughness < 0.01, "strip_load_pore_pressure_has_no_checkerboard",
	      "roughness %.4f", smooth.roughness);
	CHECK(rough.roughness > 5 * smooth.roughness, "strip_load_smoothing_removes_checkerboard",
	      "roughness %.4f without vs %.4f with", rough.roughness, smooth.roughness);
	CHECK(smooth.drift <= 1e-12, "strip_load_mass_conserved", "drift %.3e", smooth.drift);
	HARNESS_EXIT();
}
