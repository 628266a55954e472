/*
 * landslide_run.h - what the landslide tests share (landslide_test.c, the paper's cases;
 * landslide_options_test.c, the same slopes with options beyond the paper): one run of a case at a
 * size, with a change, through sim_run() into a temporary result.h5 measured by the run report,
 * and the checks of 000 §5.4's statements on the four cases.
 */
#ifndef PORO_TEST_LANDSLIDE_RUN_H
#define PORO_TEST_LANDSLIDE_RUN_H

#include <math.h>
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
static inline int measure(const char *out_dir, struct landslide_run *r)
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
static inline void shift_face(json_t *doc, double shift)
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

static inline void adjust(json_t *doc, void *user)
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

static inline struct landslide_run run_landslide(const char *file, double h, int ppc, double paper_end, enum change change,
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

static inline void report(const char *label, double h, int ppc, const struct landslide_run *r)
{
	printf("INFO landslide %s h=%.3f m %dx%d dt=%.2e s: %s, front run-out %.4f m, bulk front run-out %.4f m, "
	       "crest settlement %.4f m, largest soil-water gap %.4f m, mass error soil %.1e water %.1e, run time "
	       "%.1f s\n", label, h, ppc, ppc, r->dt, r->ok ? "ran to the end" : "FAILED", r->runout, r->bulk_runout,
	       r->settlement, r->gap,
	       r->soil_mass_error, r->water_mass_error, r->seconds);
}

/* How far apart two run-outs are: the difference over the larger (0 when both are zero). */
static inline double apart(double a, double b)
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
static inline int run_cases(double h, int ppc, double paper_end, enum change change, double face_shift, const char *suffix,
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

static inline void check_landslides(double h, int ppc, double paper_end, const char *size, enum change change,
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

#endif
