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
 * (solver/report.h), as a user measures it: the slide front (front_x: the farthest soil that
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
 * (docs/examples.md). The reduced runs are repeated with APIC point velocities (velocity_update
 * "apic", an option beyond the paper; docs/examples.md): there the gap order holds and the dense
 * lead is the known failure, and with it the comparison of the pairs (the dense pair alike).
 * Figs. 9-10 are also checked over three seedings of the slope, the face moved by a row of points
 * out and in (check_seedings): one seeding moves the loose run-outs by more than double and single
 * point differ, so Fig. 10's "similar" is asked of the pair's mean run-outs. At paper size these
 * are eight more runs, each as long as one of the cases' own.
 * Also (make test): the dense single-point slope with the weak free-surface condition runs to the
 * end (a regression test of its mass floor, free_surface.c); and the loose pair with the water held
 * in the soil (k = 5e-5 m/s) should agree, which it does not (a known failure, check_nearly_undrained).
 */
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "../harness.h"
#include "case.h"
#include "poro.h"
#include "report.h"
#include "slope_case.h"

#define CASE_DIR "tests/cases/"
#define PAPER_H 0.025               /* m */
#define PAPER_PPC 3
#define REDUCED_H 0.05              /* m */
#define REDUCED_PPC 2
#define INITIALISATION 1.0          /* s: the gravity ramp before the paper's t = 0 */
#define REDUCED_PAPER_END 2.0       /* s of the paper's time */
#define FULL_PAPER_END 6.0
#define MASS_TOLERANCE 1e-12        /* relative: points carry constant masses, outflow is booked */
#define CLOSE_RUNOUT 0.2            /* Fig. 10's "similar": run-outs within 20% of the larger */
#define NEARLY_UNDRAINED_K 5e-5     /* m/s, 100 times below Table 5: the phases move together */

struct landslide_run {
	int ok;
	double dt, runout, bulk_runout, gap, settlement, seconds;
	double report_tolerance;   /* m, the report's default: a quarter of the stored case's seeding spacing */
	double soil_mass_error, water_mass_error;
};

/* The run report of out_dir/result.h5 at its last frame: run-out of the slide front and of the
 * debris' bulk, largest gap (NaN in single point) and crest settlement. */
static int measure(const char *out_dir, struct landslide_run *r)
{
	char path[256];
	struct report *rep = NULL;
	struct report_settings set = REPORT_SETTINGS_DEFAULT;
	struct report_row *rows = NULL;
	struct poro_error err = {0};
	long n = 0;
	int ok = !report_open(&rep, harness_join(path, sizeof path, out_dir, "result.h5"), &set, &err) &&
		 !report_frames(rep, &rows, &n, &err) && n > 1;
	if (ok) {
		r->runout = rows[n - 1].front_x - rows[0].front_x;
		r->bulk_runout = rows[n - 1].bulk_front_x - rows[0].bulk_front_x;
		r->gap = rows[n - 1].max_gap;
		r->settlement = rows[n - 1].crest_settlement;
		r->report_tolerance = report_settings_used(rep)->tolerance;
	} else {
		printf("INFO cannot report %s: %s\n", path, err.message);
	}
	free(rows);
	report_close(&rep);
	return ok;
}

/* What a run changes in its case besides the size. */
enum change { AS_GIVEN, WEAK_SURFACE, APIC, NEARLY_UNDRAINED };

struct adjustment {
	double paper_end;   /* s, the paper's time (after the initialisation) to run to */
	enum change change; /* formulation.free_surface "weak", velocity_update "apic", conductivity */
	double face_shift;  /* m, the slope's face moved in x (check_seedings) */
};

/* Moves the slope's face by `shift` in x: every vertex of the body's polygon that does not lie on
 * the left or right wall (the toe corner, the crest corner), so the slope keeps its height and
 * angle and only the face moves against the points' lattice. */
static void shift_face(json_t *doc, double shift)
{
	const json_t *grid = json_object_get(doc, "grid");
	const double left = json_number_value(json_array_get(json_object_get(grid, "origin"), 0));
	const double right = left + json_number_value(json_array_get(json_object_get(grid, "extent"), 0));
	json_t *polygon = json_object_get(json_array_get(json_object_get(doc, "bodies"), 0), "polygon");
	size_t i;
	json_t *vertex;
	json_array_foreach(polygon, i, vertex) {
		const double x = json_number_value(json_array_get(vertex, 0));
		if (x > left && x < right)
			json_array_set_new(vertex, 0, json_real(x + shift));
	}
}

static void adjust(json_t *doc, void *user)
{
	const struct adjustment *a = user;
	slope_case_set(doc, "time", "end", json_real(INITIALISATION + a->paper_end));
	json_object_del(doc, "checkpoint");
	if (a->face_shift != 0.0)
		shift_face(doc, a->face_shift);
	if (a->change == WEAK_SURFACE)
		slope_case_set(doc, "formulation", "free_surface", json_string("weak"));
	if (a->change == APIC)
		slope_case_set(doc, "formulation", "velocity_update", json_string("apic"));
	if (a->change == NEARLY_UNDRAINED) {
		size_t i;
		json_t *body;
		json_array_foreach(json_object_get(doc, "bodies"), i, body)
			json_object_set_new(body, "hydraulic_conductivity", json_real(NEARLY_UNDRAINED_K));
	}
}

static struct landslide_run run_landslide(const char *file, double h, int ppc, double paper_end, enum change change,
					  double face_shift)
{
	struct landslide_run r = {0};
	struct case_spec *c = NULL;
	struct sim *s = NULL;
	struct adjustment a = {paper_end, change, face_shift};
	char *dir = harness_temp_dir("poro-landslide");
	if (!dir)
		printf("INFO cannot make a temporary directory for %s\n", file);
	r.ok = dir && !slope_case_create(file, h, ppc, adjust, &a, &c, &s);
	if (!r.ok)
		return r;
	r.dt = c->time.dt;
	const double soil0 = sim_soil_mass(s), water0 = sim_water_mass(s), t0 = harness_wall_seconds();
	r.ok = !sim_run(s, dir, "test", NULL, NULL, NULL);
	r.seconds = harness_wall_seconds() - t0;
	if (!r.ok)
		printf("INFO %s failed at t = %.4f s: %s\n", file, sim_time(s), sim_error(s)->message);
	r.soil_mass_error = fabs(sim_soil_mass(s) - soil0) / soil0;
	/* single point: the pores' water follows the soil's porosity and is exchanged through the
	 * drained surface, so only the soil's mass is a point quantity (as in consolidation_test) */
	r.water_mass_error = sim_is_double_point(s) ? fabs(sim_water_mass(s) + sim_water_outflow_mass(s) - water0) /
				water0 : 0.0;
	r.ok = r.ok && measure(dir, &r);
	sim_destroy(&s);
	case_destroy(&c);
	harness_remove_dir(dir);
	return r;
}

static void report(const char *label, double h, int ppc, const struct landslide_run *r)
{
	printf("INFO landslide %s h=%.3f m %dx%d dt=%.2e s: %s, front run-out %.4f m, bulk front run-out %.4f m, "
	       "crest settlement %.4f m, largest soil-water gap %.4f m, mass error soil %.1e water %.1e, run time "
	       "%.1f s\n", label, h, ppc, ppc, r->dt, r->ok ? "ran to the end" : "FAILED", r->runout, r->bulk_runout,
	       r->settlement, r->gap,
	       r->soil_mass_error, r->water_mass_error, r->seconds);
}

/* How far apart two run-outs are: the difference over the larger (0 when both are zero). */
static double apart(double a, double b)
{
	const double larger = fmax(fabs(a), fabs(b));
	return larger > 0.0 ? fabs(a - b) / larger : 0.0;
}

/* The four cases, in the order the checks index them (dense pair, then loose pair). */
static const char *const CASE_FILES[4] = {
	CASE_DIR "landslide_dense_double_point.json", CASE_DIR "landslide_dense_single_point.json",
	CASE_DIR "landslide_loose_double_point.json", CASE_DIR "landslide_loose_single_point.json",
};
static const char *const CASE_LABELS[4] = {"dense double point", "dense single point", "loose double point",
					   "loose single point"};

/* Which of 000 §5.4's statements a variant does not reproduce (docs/examples.md). */
struct known_failures {
	int gap_order;              /* the dense gap wider than the loose one */
	int loose_close;            /* the loose run-outs within CLOSE_RUNOUT */
	int loose_bulk_close;       /* the loose bulk run-outs within CLOSE_RUNOUT */
	int dense_lead;             /* the dense double-point run-out ahead by more than a cell */
	int loose_differs_less;     /* the loose pair less far apart than the dense pair, by both measures */
	int seedings_loose_close;   /* check_seedings: the loose pair's mean front run-outs within CLOSE_RUNOUT */
	int seedings_loose_bulk_close;   /* and their mean bulk run-outs */
};

/* Runs the four cases (CASE_FILES' order) into r, each reported with `suffix` after its label.
 * Returns whether all ran to their end; *mass becomes the largest relative mass error (it starts
 * at the caller's value). */
static int run_cases(double h, int ppc, double paper_end, enum change change, double face_shift, const char *suffix,
		     struct landslide_run r[4], double *mass)
{
	int all_ok = 1;
	for (int k = 0; k < 4; k++) {
		char label[96];
		snprintf(label, sizeof label, "%s%s", CASE_LABELS[k], suffix);
		r[k] = run_landslide(CASE_FILES[k], h, ppc, paper_end, change, face_shift);
		report(label, h, ppc, &r[k]);
		all_ok &= r[k].ok;
		*mass = fmax(*mass, fmax(r[k].soil_mass_error, r[k].water_mass_error));
	}
	return all_ok;
}

static void check_landslides(double h, int ppc, double paper_end, const char *size, enum change change,
			     const struct known_failures *known, struct landslide_run runs[4])
{
	struct landslide_run r[4];
	double mass = 0;
	const int all_ok = run_cases(h, ppc, paper_end, change, 0.0, change == APIC ? ", APIC" : "", r, &mass);
	if (runs)
		memcpy(runs, r, sizeof r);
	const struct landslide_run *dd = &r[0], *ds = &r[1], *ld = &r[2], *ls = &r[3];
	char name[128];
	snprintf(name, sizeof name, "landslide_%s_all_four_run_without_return_mapping_failure", size);
	CHECK(all_ok, name, "dense %d/%d loose %d/%d (double/single)", dd->ok, ds->ok, ld->ok, ls->ok);
	snprintf(name, sizeof name, "landslide_%s_mass_conserved", size);
	CHECK(all_ok && mass < MASS_TOLERANCE, name, "largest relative mass error %.1e", mass);
	/* Regression: the reduced runs' result.h5 once stored the paper's case (h = 0.025 m, 3x3), the
	 * spec having been changed after loading, and the report measured the gap and the crest on the
	 * paper's grid (slope_case.h). Its default tolerance shows which grid it read. */
	snprintf(name, sizeof name, "landslide_%s_report_reads_the_run_grid", size);
	const double tolerance = REPORT_TOLERANCE_SPACINGS * h / ppc;
	CHECK(all_ok && fabs(dd->report_tolerance - tolerance) < 1e-12 * tolerance, name,
	      "report tolerance %.6f m, run's seeding gives %.6f m", dd->report_tolerance, tolerance);
	snprintf(name, sizeof name, "landslide_%s_loose_slides", size);
	CHECK(ld->ok && ls->ok && ld->runout > h && ls->runout > h, name,
	      "front run-out double %.4f m single %.4f m, cell %.3f m", ld->runout, ls->runout, h);
	snprintf(name, sizeof name, "landslide_%s_loose_double_and_single_close", size);
	const int close = ld->ok && ls->ok && apart(ld->runout, ls->runout) <= CLOSE_RUNOUT;
	/* known at paper size with FLIP (docs/examples.md): 24-28% apart by this measure */
	CHECK_UNLESS_KNOWN(known->loose_close, close, name, "front run-out double %.4f m single %.4f m (000 Fig. 10)",
			   ld->runout, ls->runout);
	/* the same for the debris' bulk (report.h, bulk_front_x), which a few points running ahead or
	 * stopped at the far wall do not set */
	snprintf(name, sizeof name, "landslide_%s_loose_double_and_single_bulk_close", size);
	const int bulk_close = ld->ok && ls->ok && apart(ld->bulk_runout, ls->bulk_runout) <= CLOSE_RUNOUT;
	CHECK_UNLESS_KNOWN(known->loose_bulk_close, bulk_close, name,
			   "bulk front run-out double %.4f m single %.4f m (000 Fig. 10)", ld->bulk_runout,
			   ls->bulk_runout);
	/* §5.4 on Fig. 10: loose sand is the case "for which the differences between the single-point
	 * and double-point approaches are smaller" than for dense sand (Fig. 9) */
	snprintf(name, sizeof name, "landslide_%s_loose_pair_differs_less_than_dense", size);
	const double front_d = apart(dd->runout, ds->runout), front_l = apart(ld->runout, ls->runout),
		     bulk_d = apart(dd->bulk_runout, ds->bulk_runout), bulk_l = apart(ld->bulk_runout, ls->bulk_runout);
	CHECK_UNLESS_KNOWN(known->loose_differs_less, all_ok && front_l < front_d && bulk_l < bulk_d, name,
			   "double and single point apart by the front: loose %.1f%%, dense %.1f%%; by the bulk: loose "
			   "%.1f%%, dense %.1f%% (000 §5.4)", 100 * front_l, 100 * front_d, 100 * bulk_l, 100 * bulk_d);
	snprintf(name, sizeof name, "landslide_%s_dense_double_point_gap_opens", size);
	CHECK(dd->ok && dd->gap > h / ppc, name, "gap %.4f m, seeding spacing %.4f m (000 Fig. 9)", dd->gap, h / ppc);
	snprintf(name, sizeof name, "landslide_%s_dense_gap_wider_than_loose", size);
	/* Not reproduced (docs/examples.md): the loose slope's water drains farther below its soil */
	const int gap_order = dd->ok && ld->ok && dd->gap > ld->gap;
	CHECK_UNLESS_KNOWN(known->gap_order, gap_order, name,
			   "gap dense %.4f m loose %.4f m (000 Figs. 9-10: a very narrow gap for loose sand)", dd->gap,
			   ld->gap);
	snprintf(name, sizeof name, "landslide_%s_dense_double_point_runs_out_farther", size);
	const int lead = dd->ok && ds->ok && dd->runout > ds->runout + h;
	/* known with APIC (docs/examples.md): the dense pair alike at the paper's 2 s */
	CHECK_UNLESS_KNOWN(known->dense_lead, lead, name,
			   "front run-out double %.4f m single %.4f m, cell %.3f m (000 Fig. 9)", dd->runout, ds->runout,
			   h);
}

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
	const struct known_failures flip_reduced = {.gap_order = 1, .loose_bulk_close = 1, .seedings_loose_bulk_close = 1},
				    flip_paper = {.gap_order = 1, .loose_close = 1},
				    apic_reduced = {.dense_lead = 1, .loose_differs_less = 1};
	struct landslide_run runs[4];
	check_landslides(REDUCED_H, REDUCED_PPC, REDUCED_PAPER_END, "reduced", AS_GIVEN, &flip_reduced, runs);
	check_seedings(REDUCED_H, REDUCED_PPC, REDUCED_PAPER_END, "reduced", runs, &flip_reduced);
	check_landslides(REDUCED_H, REDUCED_PPC, REDUCED_PAPER_END, "reduced_apic", APIC, &apic_reduced, NULL);
	check_weak_surface_runs();
	check_nearly_undrained();
	const char *long_runs = getenv("PORO_VERIFY_LONG");
	if (long_runs && *long_runs && strcmp(long_runs, "0") != 0) {
		check_landslides(PAPER_H, PAPER_PPC, FULL_PAPER_END, "paper_size", AS_GIVEN, &flip_paper, runs);
		check_seedings(PAPER_H, PAPER_PPC, FULL_PAPER_END, "paper_size", runs, &flip_paper);
	}
	HARNESS_EXIT();
}
