/*
 * landslide_test.c - the Nor-Sand landslides of 000 §5.4 (Table 5, Figs. 9-10): dense (v0 = 1.55)
 * and loose (v0 = 1.70) sand, double point against single point.
 *
 * Cases: tests/cases/landslide_{dense,loose}_{double,single}_point.json (geometry, initial state
 * and the reading of psi's logarithm in docs/examples.md). Case time = paper time + 1 s (the
 * elastic gravity ramp comes first).
 *
 * make test (reduced size): h = REDUCED_H with REDUCED_PPC^2 points per cell, dt scaled with h
 * (the paper's CFL number), to the paper's 2 s.
 * make verify (PORO_VERIFY_LONG=1): the paper's size, h = 0.025 m, 3x3 points per cell,
 * dt = 1.2e-4 s, to the paper's 6 s (where the loose slide has come to rest, §5.4). §5.4 says its
 * 3x3 agrees with 4x4; ours does not for the loose slope: its fronts are 24% apart at 3x3 (a
 * known failure here), 3% at 4x4 and 10% at 5x5, each variant scattering by about 0.09 m with the
 * seeding, while the dense lead holds at all three (docs/examples.md, from poro-solve runs; the
 * refined seedings are not repeated here, as the gap order at 4x4 is a 1 mm tie that a known
 * failure check would turn into a coin toss).
 *
 * Each run goes through sim_run() into a temporary result.h5 and is measured by the run report
 * (solver/output/report.h), as a user measures it: the slide front (front_x: the farthest soil that
 * started above the toe plain; the toe itself also counts foundation soil heaved in front of it),
 * the front of the debris' bulk (bulk_front_x: beyond it lies 1% of that soil's mass) and the
 * largest gap between the soil and water surfaces (double point), at the last frame.
 * Asserted: every run reaches its end without the return mapping failing, soil mass (and water
 * mass, double point) is conserved, the loose slope slides and its double- and single-point
 * run-outs are close (Fig. 10), a gap opens in the dense double-point run (Fig. 9), and the
 * dense double-point slide runs out farther than the single-point one, by more than a cell
 * (Fig. 9). Whether the loose pair is close depends on the measure: at reduced size by the
 * fronts (10% apart) and not by the bulk (25%), at paper size by the bulk (11%) and not by the
 * fronts (24%, the double-point front standing at the far wall); the failing one is a known
 * failure at each size (docs/examples.md). What §5.4 says of the two figures together is also
 * checked: the loose pair differs less than the dense pair, by both measures.
 * The gap being wider for dense than for loose sand (Figs. 9-10) is a known failure
 * (docs/examples.md). The same slopes with options beyond the paper (APIC, the weak free
 * surface, a nearly undrained soil) are landslide_options_test.c.
 * Figs. 9-10 are also checked over three seedings of the slope, the face moved by a row of points
 * out and in (check_seedings): one seeding moves the loose run-outs by more than double and single
 * point differ, so Fig. 10's "similar" is asked of the pair's mean run-outs. These are eight more
 * runs at each size, each as long as one of the cases' own, so make verify runs them (at the
 * reduced size too).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "landslide_run.h"

/* The seedings beside the cases', as moves of the slope's face in seeding spacings (h / ppc). The
 * cases' 45-degree face runs through points of the seeding lattice, which the seeding leaves out;
 * half a spacing out takes that diagonal row of points in, one and a half in leaves the next row
 * out. The face thus lies one row of points farther out or in (a spacing over sqrt 2 along its
 * normal): the same slope to within the seeding's resolution. */
static const double FACE_SHIFTS[2] = {-1.5, 0.5};

/* 000 Figs. 9-10 over three seedings of the same slope (the cases' and FACE_SHIFTS). One seeding
 * moves the loose run-outs by more than the two formulations differ (docs/examples.md,
 * "One slope, three seedings"): at paper size the loose fronts are 24% apart in the cases' seeding and 1% apart
 * with the face half a spacing out. So Fig. 10's "similar" is asked of the pair's mean run-outs
 * over the three seedings; Fig. 9's lead of every seeding, and by more than a cell on the mean
 * (the single seeding's check, check_landslides, asks a cell of the cases' seeding). `as_given`:
 * check_landslides' runs of the cases, in its order. */
static void check_seedings(double h, int ppc, double paper_end, const char *size,
			   const struct landslide_run as_given[4], const struct known_failures *known)
{
	enum { seedings = 1 + sizeof FACE_SHIFTS / sizeof *FACE_SHIFTS };
	struct landslide_run r[seedings][4];
	memcpy(r[0], as_given, sizeof r[0]);
	int all_ok = 1;
	double mass = 0.0;
	for (int k = 0; k < 4; k++)
		all_ok &= as_given[k].ok;
	for (int i = 1; i < seedings; i++) {
		char suffix[64];
		snprintf(suffix, sizeof suffix, ", face moved %+.1f seeding spacings", FACE_SHIFTS[i - 1]);
		all_ok &= run_cases(h, ppc, paper_end, AS_GIVEN, FACE_SHIFTS[i - 1] * h / ppc, suffix, r[i], &mass);
	}
	char name[128];
	snprintf(name, sizeof name, "landslide_%s_other_seedings_run_and_conserve_mass", size);
	CHECK(all_ok && mass < MASS_TOLERANCE, name, "largest relative mass error %.1e", mass);
	int lead = all_ok;
	double mean[4][2] = {{0}};   /* [case][front, bulk] */
	for (int i = 0; i < seedings; i++) {
		const struct landslide_run *dd = &r[i][0], *ds = &r[i][1], *ld = &r[i][2], *ls = &r[i][3];
		lead &= dd->runout > ds->runout;
		printf("INFO landslide %s seeding %d (face %+.1f spacings): double and single point apart by the front "
		       "dense %.1f%% loose %.1f%%, by the bulk dense %.1f%% loose %.1f%%\n", size, i,
		       i ? FACE_SHIFTS[i - 1] : 0.0, 100 * apart(dd->runout, ds->runout), 100 * apart(ld->runout, ls->runout),
		       100 * apart(dd->bulk_runout, ds->bulk_runout), 100 * apart(ld->bulk_runout, ls->bulk_runout));
		for (int k = 0; k < 4; k++) {
			mean[k][0] += r[i][k].runout / seedings;
			mean[k][1] += r[i][k].bulk_runout / seedings;
		}
	}
	snprintf(name, sizeof name, "landslide_%s_dense_double_point_runs_out_farther_at_every_seeding", size);
	CHECK(lead && mean[0][0] > mean[1][0] + h, name, "ahead at every seeding: %s; mean front run-out double %.4f m "
	      "single %.4f m, more than a cell (%.3f m) apart (000 Fig. 9; INFO lines)", lead ? "yes" : "no", mean[0][0],
	      mean[1][0], h);
	snprintf(name, sizeof name, "landslide_%s_loose_double_and_single_close_over_seedings", size);
	CHECK_UNLESS_KNOWN(known->seedings_loose_close, all_ok && apart(mean[2][0], mean[3][0]) <= CLOSE_RUNOUT, name,
			   "mean front run-out over %d seedings double %.4f m single %.4f m, %.1f%% apart (000 Fig. 10)",
			   seedings, mean[2][0], mean[3][0], 100 * apart(mean[2][0], mean[3][0]));
	snprintf(name, sizeof name, "landslide_%s_loose_double_and_single_bulk_close_over_seedings", size);
	CHECK_UNLESS_KNOWN(known->seedings_loose_bulk_close, all_ok && apart(mean[2][1], mean[3][1]) <= CLOSE_RUNOUT,
			   name, "mean bulk front run-out over %d seedings double %.4f m single %.4f m, %.1f%% apart "
			   "(000 Fig. 10)", seedings, mean[2][1], mean[3][1], 100 * apart(mean[2][1], mean[3][1]));
	snprintf(name, sizeof name, "landslide_%s_loose_pair_differs_less_than_dense_over_seedings", size);
	const double front_d = apart(mean[0][0], mean[1][0]), front_l = apart(mean[2][0], mean[3][0]),
		     bulk_d = apart(mean[0][1], mean[1][1]), bulk_l = apart(mean[2][1], mean[3][1]);
	CHECK(all_ok && front_l < front_d && bulk_l < bulk_d, name,
	      "mean run-outs of double and single point apart by the front: loose %.1f%%, dense %.1f%%; by the bulk: "
	      "loose %.1f%%, dense %.1f%% (000 §5.4)", 100 * front_l, 100 * front_d, 100 * bulk_l, 100 * bulk_d);
}

int main(void)
{
	const struct known_failures flip_reduced = {.gap_order = 1, .loose_bulk_close = 1, .seedings_loose_bulk_close = 1},
				    flip_paper = {.gap_order = 1, .loose_close = 1};
	struct landslide_run runs[4];
	check_landslides(REDUCED_H, REDUCED_PPC, REDUCED_PAPER_END, "reduced", AS_GIVEN, &flip_reduced, runs);
	const char *long_runs = getenv("PORO_VERIFY_LONG");
	if (long_runs && *long_runs && strcmp(long_runs, "0") != 0) {
		check_seedings(REDUCED_H, REDUCED_PPC, REDUCED_PAPER_END, "reduced", runs, &flip_reduced);
		check_landslides(PAPER_H, PAPER_PPC, FULL_PAPER_END, "paper_size", AS_GIVEN, &flip_paper, runs);
		check_seedings(PAPER_H, PAPER_PPC, FULL_PAPER_END, "paper_size", runs, &flip_paper);
	}
	HARNESS_EXIT();
}
