/*
 * landslide_options_test.c - the reduced Nor-Sand landslides of 000 §5.4 (landslide_test.c) with
 * options beyond the paper, at the reduced size (h = REDUCED_H, REDUCED_PPC^2 points per cell, to
 * the paper's 2 s). make test runs the weak free surface's regression run; make verify
 * (PORO_VERIFY_LONG=1) adds the APIC slopes and the nearly undrained pair (six more runs of half a
 * minute each, whose figures are known failures or options' comparisons):
 * - APIC point velocities (velocity_update "apic"; docs/examples.md): there the gap order holds and
 *   the dense lead is the known failure, and with it the comparison of the pairs (the dense pair
 *   alike);
 * - the dense single-point slope with the weak free-surface condition runs to the end (a
 *   regression test of its mass floor, free_surface.c);
 * - the loose pair with the water held in the soil (k = 5e-5 m/s) should agree, which it does not
 *   (a known failure, check_nearly_undrained).
 */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "landslide_run.h"

/* Regression: with the weak free-surface condition (free_surface.c) the reduced dense single-point
 * slope stopped at t = 2.50 s on an indefinite pressure matrix, when surface points beyond the
 * points' reach pushed on nodes with 1e-17 kg of mass; the push now skips nodes below
 * BOUNDARY_MASS_FLOOR of the largest mass. On one thread: the failure depended on the round-off
 * of the sums (on two threads the floorless build happened to pass); one thread reproduces it
 * (checked with the floor set to 0 and OMP_NUM_THREADS=1: stopped at t = 2.5039 s). */
static void check_weak_surface_runs(void)
{
	const int threads = omp_get_max_threads();
	omp_set_num_threads(1);
	struct landslide_run r = run_landslide(CASE_DIR "landslide_dense_single_point.json", REDUCED_H, REDUCED_PPC,
					       REDUCED_PAPER_END, WEAK_SURFACE, 0.0);
	omp_set_num_threads(threads);
	report("dense single point, weak free surface", REDUCED_H, REDUCED_PPC, &r);
	CHECK(r.ok && r.soil_mass_error < MASS_TOLERANCE, "landslide_reduced_weak_surface_dense_single_point_runs",
	      "see the INFO line");
}

/* Two run-outs within CLOSE_RUNOUT of the larger, or within `spacing` of each other (where both are
 * a few seeding spacings, a relative measure says nothing). */
static int alike(double a, double b, double spacing)
{
	return apart(a, b) <= CLOSE_RUNOUT || fabs(a - b) <= spacing;
}

/* §5.4 explains Fig. 10's similar run-outs by the phases "moving together": where the water cannot
 * move through the soil, double and single point model the same mixture and should agree. The
 * loose pair at reduced size with k = NEARLY_UNDRAINED_K (double point's largest gap stays below a
 * seeding spacing) should run out alike, by the front and by the bulk: within CLOSE_RUNOUT of the
 * larger or one seeding spacing. It does not (a known failure: docs/examples.md, "Double against
 * single point where the water cannot move"), so part of the pair's distance at the cases' k is
 * the formulations', not the relative flow's. What parts them is the layer of soil within a cell
 * of the surface, whose volume the nodes held at zero pressure leave free however impermeable the
 * soil: single point books its growth as water (n V), double point keeps each water point's
 * water (Eqs. 36-37); given the soil points' volumes and positions, the double-point run is the
 * single-point one to the millimetre. */
static void check_nearly_undrained(void)
{
	const double spacing = REDUCED_H / REDUCED_PPC;
	struct landslide_run d = run_landslide(CASE_DIR "landslide_loose_double_point.json", REDUCED_H, REDUCED_PPC,
					       REDUCED_PAPER_END, NEARLY_UNDRAINED, 0.0);
	struct landslide_run s = run_landslide(CASE_DIR "landslide_loose_single_point.json", REDUCED_H, REDUCED_PPC,
					       REDUCED_PAPER_END, NEARLY_UNDRAINED, 0.0);
	char label[96];
	snprintf(label, sizeof label, "loose double point, k = %g m/s", NEARLY_UNDRAINED_K);
	report(label, REDUCED_H, REDUCED_PPC, &d);
	snprintf(label, sizeof label, "loose single point, k = %g m/s", NEARLY_UNDRAINED_K);
	report(label, REDUCED_H, REDUCED_PPC, &s);
	CHECK(d.ok && d.gap < spacing, "landslide_reduced_nearly_undrained_phases_move_together",
	      "largest gap %.4f m, seeding spacing %.4f m", d.gap, spacing);
	const int agree = d.ok && s.ok && alike(d.runout, s.runout, spacing) && alike(d.bulk_runout, s.bulk_runout, spacing);
	CHECK_KNOWN_FAILURE(agree, "landslide_reduced_nearly_undrained_loose_double_and_single_agree",
			    "front run-out double %.4f m single %.4f m, bulk %.4f m and %.4f m", d.runout, s.runout,
			    d.bulk_runout, s.bulk_runout);
}

int main(void)
{
	const struct known_failures apic_reduced = {.dense_lead = 1, .loose_differs_less = 1};
	check_weak_surface_runs();
	const char *long_runs = getenv("PORO_VERIFY_LONG");
	if (long_runs && *long_runs && strcmp(long_runs, "0") != 0) {
		check_landslides(REDUCED_H, REDUCED_PPC, REDUCED_PAPER_END, "reduced_apic", APIC, &apic_reduced, NULL);
		check_nearly_undrained();
	}
	HARNESS_EXIT();
}
