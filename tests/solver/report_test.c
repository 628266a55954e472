/*
 * report_test.c - tests of the run report (solver/output/report.h: report.c, report_frames.c,
 * report_line.c, report_csv.c).
 *
 * Oracle: synthetic result files with known answers, written by the solver's own writer
 * (output.h). A small slope (the polygon of tests/cases/mc_slope_*.json scaled down, its face
 * moved off the seeding lattice so no point lies on it) is seeded by sim_create(); its frames then
 * place the points by hand:
 *   frame 0 (t = 0)     as seeded, zero stress, water on the soil points;
 *   frame 1 (t = 0.25)  the soil seeded above the ground moved by (DX, -DZ): run-out DX, crest
 *                       settlement DZ (the soil just beyond the crest window rises by BUMP: only
 *                       the window counts); the water of column GAP_COLUMN lowered by GAP and
 *                       the water of DRY_COLUMN removed: largest gap GAP at that column's centre;
 *                       a checkerboard mean effective stress of amplitude A on a mean P, whose
 *                       index lies in [2A/(P+A), 2A/(P-A)] (oscillation.h);
 *   frame 2 (t = 0.5)   frame 1 with one foundation point lifted above ground + tolerance: the
 *                       toe jumps to it, the run-out (the slope's soil) stays DX;
 *   frame 3 (t = 0.75)  the same point lifted less, below the tolerance: the toe of frame 1.
 * The pore pressure is linear in x and y in frames 0-1 and constant in frames 2-3. A line between
 * two lattice columns, through lattice rows, sees a symmetric neighbourhood of 12 points within h,
 * so each sample is the field at the sample exactly; on another line the points used are counted
 * by brute force from the positions read back (results_read.h). Defaults (ground 0.5, crest 1.02,
 * tolerance h/8) follow from the polygon by the rules of report.h. The same frames are written in
 * single point (no gap, pressure on the soil points). Error tests check status and message, also
 * on copies of the result with one frame's soil displacements, stresses or masses cut short.
 */
#include "report.h"

#include <hdf5.h>

#include "../harness.h"
#include "case.h"
#include "oscillation.h"
#include "output.h"
#include "poro.h"
#include "results_read.h"

#define H 0.1                  /* cell_size, m */
#define PPC 2
#define SPACING (H / PPC)
#define GROUND 0.5             /* lowest vertex off the grid's bottom */
#define CREST 1.02             /* the crest edge: the highest vertex furthest right */
#define TOLERANCE (0.25 * SPACING)
#define TOE0 1.975             /* lowest row above ground, y = 0.525, meets the face x = 2.02 - (y - 0.5)
				  at 1.995; the last sub-cell centre before it */
#define DX 0.8637              /* run-out imposed on the soil seeded above the ground, m: 17.27 seeding
				  spacings, so x - displacement, not x, finds its lattice sites */
#define DZ 0.0093              /* its settlement, m; below 0.025 - TOLERANCE, so its lowest row (y0 = 0.525)
				  stays above ground + tolerance */
#define BUMP 0.2               /* soil moved just beyond the crest window (x in (1.07, 1.12)) raised, m */
#define GAP 0.0371             /* water of GAP_COLUMN lowered below its soil, m */
#define GAP_COLUMN 14          /* x in [1.4, 1.5) */
#define DRY_COLUMN 29          /* x in [2.9, 3.0): soil without water, left out of the gap */
#define LIFTED_X 2.875         /* the foundation point lifted in frames 2 and 3 (top row, y0 = 0.475) */
#define LIFTED_Y 0.475
#define LIFT_ABOVE 0.06        /* to 0.535 > GROUND + TOLERANCE */
#define LIFT_BELOW 0.03        /* to 0.505 < GROUND + TOLERANCE */
#define P_MEAN 2.5137e4        /* checkerboard mean effective stress, Pa */
#define P_AMP 1.2093e3         /* and amplitude */
#define FRAMES 4
#define FRAME_DT 0.25
#define TOL 1e-12              /* m: positions and differences of positions, round-off only */

static const char case_format[] =
	"{\"schema\": \"poro-case/1\", \"title\": \"report test slope\","
	" \"formulation\": {\"scheme\": \"semi_implicit\", \"phases\": \"%s\", \"shape\": \"quadratic_bspline\"},"
	" \"grid\": {\"origin\": [0.0, 0.0], \"extent\": [3.0, 1.6], \"cell_size\": 0.1},"
	" \"materials\": [{\"name\": \"sand\", \"model\": \"linear_elastic\", \"density\": 2650,"
	"   \"youngs_modulus\": 1e7, \"poisson_ratio\": 0.3}],"
	" \"bodies\": [{\"name\": \"slope\", \"material\": \"sand\", %s, \"particles_per_cell\": 2,"
	"   \"porosity\": 0.4, \"hydraulic_conductivity\": 1e-3}],"
	" \"fluid\": {\"density\": 1000}, \"gravity\": {\"acceleration\": [0.0, -9.81]},"
	" \"boundaries\": {\"left\": {\"soil\": \"slip\", \"water\": \"slip\"},"
	"   \"right\": {\"soil\": \"slip\", \"water\": \"slip\"}, \"bottom\": {\"soil\": \"fixed\", \"water\": \"fixed\"}},"
	" \"time\": {\"dt\": 1e-3, \"end\": 0.75}, \"output\": {\"frame_interval\": 0.25}}";
static const char slope_polygon[] =
	"\"polygon\": [[0, 0], [3.0, 0], [3.0, 0.5], [2.02, 0.5], [1.02, 1.5], [0, 1.5]]";
static const char block_rectangle[] = "\"rectangle\": {\"min\": [0, 0], \"max\": [3.0, 0.5]}";

/* The pore pressure of frame k at (x, y), Pa, positive in compression. */
static double field(int k, double x, double y)
{
	static const double constant[FRAMES] = {3.1e4, -1.7e3, 4.4321e3, 5.6789e3};
	return k < 2 ? constant[k] + 1.234e3 * x - 9.81e3 * y : constant[k];
}

static int in_column(double x, int column)
{
	return (int)floor(x / H) == column;
}

/* ---- the synthetic frames ---------------------------------------------------------------------- */

/* Soil points of frame k from the seeded positions x0[2n]. */
static void place_soil(struct particles *s, const double *x0, int k)
{
	for (idx_t q = 0; q < s->n; q++) {
		double *x = s->x + 2 * q, *sigma = s->stress + 4 * q;
		/* unequal, the toe's points heavy, so that the bulk front depends on the weighting */
		s->mass[q] = (x0[2 * q] > 1.9 ? 3.0 : 1.0) + 0.5 * (double)(q % 3);
		s->x0[2 * q] = x[0] = x0[2 * q];
		s->x0[2 * q + 1] = x[1] = x0[2 * q + 1];
		if (k >= 1 && x0[2 * q + 1] > GROUND)
			x[0] += DX, x[1] -= DZ;
		if (k >= 1 && x[0] > CREST + 0.5 * H && x[0] < CREST + H)
			x[1] += BUMP;
		if (k >= 2 && fabs(x0[2 * q] - LIFTED_X) < 1e-9 && fabs(x0[2 * q + 1] - LIFTED_Y) < 1e-9)
			x[1] += k == 2 ? LIFT_ABOVE : LIFT_BELOW;
		long u = lround(x0[2 * q] / SPACING - 0.5), v = lround(x0[2 * q + 1] / SPACING - 0.5);
		double p = k == 0 ? 0.0 : P_MEAN + ((u + v) % 2 ? P_AMP : -P_AMP);
		sigma[0] = sigma[1] = sigma[3] = -p;
		sigma[2] = k == 0 ? 0.0 : 0.137 * P_MEAN;
		s->pressure[q] = -field(k, x[0], x[1]);   /* internal sign: tension positive */
	}
}

/* Water points of frame k: on the soil points, but for the gap and dry columns from frame 1 on. */
static void place_water(struct particles *w, const struct particles *s, int k)
{
	w->n = 0;
	for (idx_t q = 0; q < s->n; q++) {
		double x = s->x[2 * q], y = s->x[2 * q + 1];
		if (k >= 1 && in_column(x, DRY_COLUMN))
			continue;
		if (k >= 1 && in_column(x, GAP_COLUMN))
			y -= GAP;
		w->x[2 * w->n] = w->x0[2 * w->n] = x;
		w->x[2 * w->n + 1] = w->x0[2 * w->n + 1] = y;
		w->pressure[w->n] = -field(k, x, y);
		w->n++;
	}
}

/* The bulk front by brute force: the largest x of a point seeded above the ground with at least
 * REPORT_BULK_FRACTION of the mass of those points at or beyond its x; NAN when there is none. */
static double brute_bulk_front(const struct particles *s)
{
	double total = 0.0, best = NAN;
	for (idx_t j = 0; j < s->n; j++)
		if (s->x0[2 * j + 1] > GROUND + TOLERANCE)
			total += s->mass[j];
	for (idx_t i = 0; i < s->n; i++) {
		if (!(s->x0[2 * i + 1] > GROUND + TOLERANCE))
			continue;
		double ahead = 0.0;
		for (idx_t j = 0; j < s->n; j++)
			if (s->x0[2 * j + 1] > GROUND + TOLERANCE && s->x[2 * j] >= s->x[2 * i])
				ahead += s->mass[j];
		if (ahead >= REPORT_BULK_FRACTION * total && (isnan(best) || s->x[2 * i] > best))
			best = s->x[2 * i];
	}
	return best;
}

/* Writes dir/result.h5 of the body `geometry` in `phases`; the oscillation index of each frame's
 * soil, straight from oscillation_index(), into direct[FRAMES] (NAN where undefined), the
 * two-cell pattern index of the pore pressure on the points that carry it, straight from
 * oscillation_index_pattern(), into pattern[FRAMES], and its bulk front by brute force into
 * bulk[FRAMES]. */
static int write_synthetic(const char *dir, const char *phases, const char *geometry, double *direct,
			   double *pattern, double *bulk)
{
	char json[4096];
	snprintf(json, sizeof json, case_format, phases, geometry);
	struct case_spec *c = NULL;
	struct sim *sim = NULL;
	struct output *o = NULL;
	struct particles soil = {0}, water = {0};
	struct poro_error err = {0};
	int double_point = !strcmp(phases, "double_point");
	int rc = case_load_string(json, &c, &err) || sim_create(&sim, c, &err) ? -1 : 0;
	idx_t n = rc ? 0 : sim_soil(sim)->n;
	if (!rc && (particles_init(&soil, n, 1, &err) || particles_init(&water, n, 0, &err) ||
		    output_create(&o, dir, json, "report_test", 0, NULL, NULL, &err)))
		rc = -1;
	for (int k = 0; !rc && k < FRAMES; k++) {
		place_soil(&soil, sim_soil(sim)->x0, k);
		place_water(&water, &soil, k);
		bulk[k] = brute_bulk_front(&soil);
		struct poro_error undefined = {0};
		if (oscillation_index(&c->grid, &soil, SPACING, &direct[k], &undefined))
			direct[k] = NAN;
		const struct particles *carrier = double_point ? &water : &soil;
		if (oscillation_index_pattern(&c->grid, carrier, SPACING, PPC, carrier->pressure, &pattern[k], &undefined))
			pattern[k] = NAN;
		struct output_frame f = {k * FRAME_DT, k, &soil, double_point ? &water : NULL};
		rc = output_frame_write(o, &f, &err) ? -1 : 0;
	}
	if (!rc && output_finish(o, "succeeded", FRAMES, n, 0.0, &err))
		rc = -1;
	if (rc)
		printf("INFO cannot write the synthetic %s result: %s\n", phases, err.message);
	water.n = n;
	particles_release(&soil);
	particles_release(&water);
	output_destroy(&o);
	sim_destroy(&sim);
	case_destroy(&c);
	return rc;
}

/* ---- the per-frame table ------------------------------------------------------------------------ */

static int near(double a, double b, double tol)
{
	return fabs(a - b) <= tol;
}

static void check_settings(const struct report *rep, const char *label)
{
	char name[128];
	const struct report_settings *s = report_settings_used(rep);
	snprintf(name, sizeof name, "%s_defaults_from_polygon", label);
	CHECK(s->ground == GROUND && s->crest == CREST && near(s->tolerance, TOLERANCE, 1e-15), name,
	      "ground %.17g (want %g), crest %.17g (want %g), tolerance %.17g (want %g)", s->ground, GROUND, s->crest,
	      CREST, s->tolerance, TOLERANCE);
}

static void check_rows(const struct report_row *r, long count, const double *direct, const double *pattern,
		       const double *bulk, int double_point, const char *label)
{
	char name[128];
	const double toe[FRAMES] = {TOE0, TOE0 + DX, LIFTED_X, TOE0 + DX};
	int toe_ok = count == FRAMES, settle_ok = toe_ok, time_ok = toe_ok, front_ok = toe_ok;
	for (long k = 0; toe_ok && k < FRAMES; k++) {
		/* the run-out follows the slope's soil: DX, also where a foundation point lifts the toe */
		toe_ok &= near(r[k].toe_x, toe[k], TOL) && near(r[k].runout, k ? DX : 0.0, TOL);
		front_ok &= near(r[k].front_x, k ? TOE0 + DX : TOE0, TOL);   /* the lifted point is foundation */
		settle_ok &= near(r[k].crest_settlement, k ? DZ : 0.0, TOL);
		time_ok &= r[k].time == k * FRAME_DT;
	}
	snprintf(name, sizeof name, "%s_frames_and_times", label);
	CHECK(time_ok, name, "%ld rows, last time %g", count, count ? r[count - 1].time : NAN);
	snprintf(name, sizeof name, "%s_toe_and_runout_follow_imposed_slide_and_tolerance", label);
	CHECK(toe_ok, name, "toe %.15g %.15g %.15g %.15g, want %.15g %.15g %.15g %.15g", r[0].toe_x, r[1].toe_x,
	      r[2].toe_x, r[3].toe_x, toe[0], toe[1], toe[2], toe[3]);
	snprintf(name, sizeof name, "%s_front_follows_slope_soil_not_lifted_foundation", label);
	CHECK(front_ok, name, "front %.15g %.15g %.15g %.15g, want %.15g then %.15g", r[0].front_x, r[1].front_x,
	      r[2].front_x, r[3].front_x, TOE0, TOE0 + DX);
	int bulk_ok = count == FRAMES && near(bulk[1], bulk[0] + DX, TOL);
	for (long k = 0; bulk_ok && k < FRAMES; k++)
		bulk_ok &= near(r[k].bulk_front_x, bulk[k], TOL);
	snprintf(name, sizeof name, "%s_bulk_front_is_brute_force_mass_percentile", label);
	CHECK(bulk_ok, name, "bulk front %.15g %.15g %.15g %.15g, brute force %.15g %.15g %.15g %.15g",
	      r[0].bulk_front_x, r[1].bulk_front_x, r[2].bulk_front_x, r[3].bulk_front_x, bulk[0], bulk[1], bulk[2],
	      bulk[3]);
	snprintf(name, sizeof name, "%s_crest_settlement_is_imposed_settlement", label);
	CHECK(settle_ok, name, "%.15g %.15g %.15g %.15g, want 0 then %g", r[0].crest_settlement,
	      r[1].crest_settlement, r[2].crest_settlement, r[3].crest_settlement, DZ);

	int gap_ok = count == FRAMES;
	for (long k = 0; gap_ok && k < FRAMES; k++)
		gap_ok &= double_point ? near(r[k].max_gap, k ? GAP : 0.0, TOL) &&
						 near(r[k].max_gap_x, k ? (GAP_COLUMN + 0.5) * H : 0.5 * H, TOL)
				       : isnan(r[k].max_gap) && isnan(r[k].max_gap_x);
	snprintf(name, sizeof name, "%s_gap_%s", label,
		 double_point ? "is_lowered_column_dry_column_left_out" : "is_nan_in_single_point");
	CHECK(gap_ok, name, "frame 0: %.15g at %.15g; frame 1: %.15g at %.15g", r[0].max_gap, r[0].max_gap_x,
	      r[1].max_gap, r[1].max_gap_x);

	int same = isnan(r[0].oscillation_index) && isnan(direct[0]), bounded = 1;
	for (long k = 1; k < FRAMES && k < count; k++) {
		same &= rel_diff(r[k].oscillation_index, direct[k], 1e-300) <= 1e-12;
		bounded &= r[k].oscillation_index >= 2 * P_AMP / (P_MEAN + P_AMP) &&
			   r[k].oscillation_index <= 2 * P_AMP / (P_MEAN - P_AMP);
	}
	snprintf(name, sizeof name, "%s_oscillation_index_is_oscillation_h_of_the_frame", label);
	CHECK(same, name, "report %.17g %.17g, oscillation_index() %.17g %.17g", r[0].oscillation_index,
	      r[1].oscillation_index, direct[0], direct[1]);
	snprintf(name, sizeof name, "%s_oscillation_index_of_checkerboard_near_2A_over_P", label);
	CHECK(bounded, name, "%.6f, want within [%.6f, %.6f]", r[1].oscillation_index, 2 * P_AMP / (P_MEAN + P_AMP),
	      2 * P_AMP / (P_MEAN - P_AMP));

	/* the pore pressure's pattern index: oscillation_index_pattern() of the carriers (the sign the
	 * file stores does not change it), 0 for the constant pressure of frames 2-3 */
	same = count == FRAMES;
	for (long k = 0; same && k < FRAMES; k++)
		same &= r[k].pressure_pattern_index == pattern[k] || (isnan(r[k].pressure_pattern_index) && isnan(pattern[k]));
	snprintf(name, sizeof name, "%s_pressure_pattern_index_is_oscillation_h_of_the_carriers", label);
	CHECK(same && r[2].pressure_pattern_index == 0.0 && r[3].pressure_pattern_index == 0.0, name,
	      "report %.17g %.17g %.17g %.17g, oscillation_index_pattern() %.17g %.17g %.17g %.17g",
	      r[0].pressure_pattern_index, r[1].pressure_pattern_index, r[2].pressure_pattern_index,
	      r[3].pressure_pattern_index, pattern[0], pattern[1], pattern[2], pattern[3]);
}

/* ---- the line ------------------------------------------------------------------------------------ */

static struct report_sample *sample(struct report *rep, const char *text, double at, double *t, int *n,
				    enum poro_status *st, struct poro_error *err)
{
	struct report_line line;
	struct report_sample *s = NULL;
	*st = report_line_parse(text, &line, err);
	if (!*st)
		*st = report_line_sample(rep, &line, at, &s, t, err);
	*n = *st ? 0 : line.samples;
	return s;
}

/* Brute force: the points of set `carrier` in frame k of path within h of (x, y); -1 on failure. */
static int points_within(const char *path, long k, const char *carrier, double x, double y)
{
	struct results *r = NULL;
	struct poro_error err = {0};
	double *p = NULL;
	long n = 0;
	int count = -1;
	if (!results_open(&r, path, &err) && !results_frame_read(r, k, carrier, "x", &p, &n, NULL, &err))
		for (long i = count = 0; i < n; i++)
			count += hypot(p[2 * i] - x, p[2 * i + 1] - y) <= H;
	free(p);
	results_close(&r);
	return count;
}

static void check_line(struct report *rep, const char *path, const char *carrier, const char *label)
{
	char name[128];
	struct poro_error err = {0};
	enum poro_status st;
	double t = NAN;
	int n = 0;
	/* along x = 0.5, between lattice columns, from row y = 0.225 to row y = 1.025 every 0.05 m */
	struct report_sample *s = sample(rep, "0.5,0.225,0.5,1.025,17", 0.1, &t, &n, &st, &err);
	int ok = !st && n == 17 && t == 0.0;
	double worst = 0.0;
	for (int k = 0; ok && k < n; k++) {
		ok &= s[k].points == 12 && near(s[k].distance, 0.05 * k, TOL) && s[k].x == 0.5 &&
		      near(s[k].y, 0.225 + 0.05 * k, TOL);
		worst = fmax(worst, fabs(s[k].pore_pressure - field(0, s[k].x, s[k].y)) / 3.1e4);
	}
	snprintf(name, sizeof name, "%s_line_samples_linear_field_exactly_from_12_points", label);
	CHECK(ok && worst < 1e-12, name, "status %d (%s), %d samples at t = %g, points[0] %d, worst %.3g", st,
	      st ? err.message : "", n, t, n ? s[0].points : -1, worst);
	free(s);

	/* the frame nearest --at: frames 2 and 3 have constant fields; 0.625 is a tie, the earlier wins */
	const double at[] = {0.55, 0.625, 0.63, NAN}, want_t[] = {0.5, 0.5, 0.75, 0.75};
	const int want_frame[] = {2, 2, 3, 3};
	ok = 1;
	int counted = 1;
	for (int i = 0; i < 4; i++) {
		s = sample(rep, "0.3,0.2,2.8,0.4,9", at[i], &t, &n, &st, &err);   /* length sqrt(6.29) */
		int used = 0;
		for (int k = 0; !st && k < n; k++) {
			counted &= s[k].points == points_within(path, want_frame[i], carrier, s[k].x, s[k].y);
			ok &= near(s[k].distance, k * sqrt(6.29) / 8, TOL) && near(s[k].x, 0.3 + k * 2.5 / 8, TOL) &&
			      near(s[k].y, 0.2 + k * 0.2 / 8, TOL);
			if (s[k].points)
				used++, ok &= rel_diff(s[k].pore_pressure, field(want_frame[i], 0, 0), 1e-300) < 1e-14;
		}
		ok &= !st && t == want_t[i] && used == n;
		free(s);
	}
	snprintf(name, sizeof name, "%s_line_counts_points_within_h_like_brute_force", label);
	CHECK(counted, name, "a sample's point count differs from the brute-force count");
	snprintf(name, sizeof name, "%s_line_at_nearest_frame_earlier_on_tie_last_by_default", label);
	CHECK(ok, name, "status %d: %s", st, st ? err.message : "");

	/* a polyline: up x = 0.5 by 0.4 m, then along y = 0.625 by 0.8 m; 13 samples every 0.1 m, the
	 * fifth on the corner */
	s = sample(rep, "0.5,0.225,0.5,0.625,1.3,0.625,13", 0.0, &t, &n, &st, &err);
	ok = !st && n == 13;
	counted = 1;
	for (int k = 0; ok && k < n; k++) {
		double want_x = k <= 4 ? 0.5 : 0.5 + 0.1 * (k - 4), want_y = k <= 4 ? 0.225 + 0.1 * k : 0.625;
		ok &= near(s[k].distance, 0.1 * k, TOL) && near(s[k].x, want_x, TOL) && near(s[k].y, want_y, TOL);
		counted &= s[k].points == points_within(path, 0, carrier, s[k].x, s[k].y);
	}
	ok &= !st && s[4].x == 0.5 && s[4].y == 0.625 && s[12].x == 1.3 && s[12].y == 0.625;
	snprintf(name, sizeof name, "%s_polyline_samples_evenly_along_its_length_through_the_corner", label);
	CHECK(ok && counted, name, "status %d (%s), %d samples, counts %s", st, st ? err.message : "", n,
	      counted ? "agree" : "differ from brute force");
	free(s);

	s = sample(rep, "2.9,1.5,2.95,1.55,2", 0.0, &t, &n, &st, &err);
	ok = !st && n == 2 && isnan(s[0].pore_pressure) && s[0].points == 0 && isnan(s[1].pore_pressure);
	snprintf(name, sizeof name, "%s_line_sample_without_points_is_nan", label);
	CHECK(ok, name, "status %d, first sample %g from %d points", st, n ? s[0].pore_pressure : 0, n ? s[0].points : -1);
	free(s);

	enum poro_status after, before;
	s = sample(rep, "1,1,2,2", 0.75 + 1e-3, &t, &n, &after, &err);
	int names_run = strstr(err.message, "outside the run") != NULL;
	free(s);
	s = sample(rep, "1,1,2,2", -0.01, &t, &n, &before, &err);
	free(s);
	snprintf(name, sizeof name, "%s_line_time_outside_run_is_einval", label);
	CHECK(after == PORO_EINVAL && before == PORO_EINVAL && names_run, name, "after %d, before %d: %s", after,
	      before, err.message);
}

/* ---- one synthetic file end to end ------------------------------------------------------------- */

/* Opens the result file `path` with the default settings and reads every frame's row. */
static enum poro_status open_and_read_frames(const char *path, struct report **rep, struct report_row **rows,
					     long *count, struct poro_error *err)
{
	struct report_settings defaults = REPORT_SETTINGS_DEFAULT;
	enum poro_status st = report_open(rep, path, &defaults, err);
	return st ? st : report_frames(*rep, rows, count, err);
}

static void check_synthetic(const char *dir, const char *phases)
{
	double direct[FRAMES], pattern[FRAMES], bulk[FRAMES];
	char path[256];
	if (write_synthetic(dir, phases, slope_polygon, direct, pattern, bulk)) {
		CHECK(0, phases, "cannot write the synthetic result");
		return;
	}
	struct report *rep = NULL;
	struct report_row *rows = NULL;
	struct poro_error err = {0};
	long count = 0;
	enum poro_status st = open_and_read_frames(harness_join(path, sizeof path, dir, "result.h5"), &rep, &rows,
						   &count, &err);
	char name[128];
	snprintf(name, sizeof name, "%s_report_opens_and_reads_every_frame", phases);
	CHECK(!st, name, "report: %s", err.message);
	if (st) {
		report_close(&rep);
		return;
	}
	check_settings(rep, phases);
	check_rows(rows, count, direct, pattern, bulk, !strcmp(phases, "double_point"), phases);
	check_line(rep, path, !strcmp(phases, "double_point") ? "water" : "soil", phases);

	/* the CSV: a header, one line per frame, NaN as "nan" (frame 0 has no stress) */
	char csv[256];
	FILE *f = fopen(harness_join(csv, sizeof csv, dir, "report.csv"), "w");
	st = f ? report_frames_write(f, csv, rows, count, &err) : PORO_EIO;
	if (f)
		fclose(f);
	char *text = harness_read_file(csv);
	int lines = 0;
	for (char *p = text; p && *p; p++)
		lines += *p == '\n';
	snprintf(name, sizeof name, "%s_csv_header_rows_and_nan", phases);
	const char *head = "time,toe_x,runout,front_x,bulk_front_x,crest_settlement,max_gap,max_gap_x,oscillation_index,"
			   "pressure_pattern_index\n0,1.975,0,1.975,";
	CHECK(!st && text && lines == FRAMES + 1 && !strncmp(text, head, strlen(head)) &&
	      strstr(text, ",nan,"), name, "status %d, %d lines:\n%s", st, lines, text ? text : "(unreadable)");
	free(text);
	free(rows);
	report_close(&rep);
	snprintf(name, sizeof name, "%s_report_close_clears_pointer", phases);
	CHECK(rep == NULL, name, "still set");
}

/* ---- invalid input ------------------------------------------------------------------------------ */

/* Copies the file `from` to `to` byte for byte; 0 on success. */
static int copy_file(const char *from, const char *to)
{
	FILE *in = fopen(from, "rb"), *out = fopen(to, "wb");
	char buf[65536];
	size_t got = 0;
	int rc = in && out ? 0 : -1;
	while (!rc && (got = fread(buf, 1, sizeof buf, in)) > 0)
		rc = fwrite(buf, 1, got, out) == got ? 0 : -1;
	if (in)
		fclose(in);
	if (out && fclose(out))
		rc = -1;
	return rc;
}

/* Replaces frame 1's soil dataset `name` (`columns` per row, 0 for one) of the result file `path`
 * with one of `rows` zero rows, as a writer cut short or a hand-edited file could leave it. */
static int shorten_soil_dataset(const char *path, const char *name, int columns, hsize_t rows)
{
	char link[128];
	snprintf(link, sizeof link, "/frames/000001/soil/%s", name);
	hid_t file = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT);
	if (file < 0)
		return -1;
	hsize_t dims[2] = {rows, (hsize_t)columns};
	double *zeros = calloc(rows * (hsize_t)(columns ? columns : 1), sizeof *zeros);
	hid_t space = H5Screate_simple(columns ? 2 : 1, dims, NULL), set = -1;
	int rc = zeros && space >= 0 && H5Ldelete(file, link, H5P_DEFAULT) >= 0 ? 0 : -1;
	if (!rc)
		set = H5Dcreate2(file, link, H5T_NATIVE_DOUBLE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
	if (!rc && (set < 0 || H5Dwrite(set, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, zeros) < 0))
		rc = -1;
	if (set >= 0)
		H5Dclose(set);
	if (space >= 0)
		H5Sclose(space);
	free(zeros);
	return H5Fclose(file) < 0 ? -1 : rc;
}

/* A frame whose soil displacements, stresses or masses do not match its positions row for row is
 * refused with PORO_EIO naming the frame and both counts, not read past its end. */
static void check_short_datasets(const char *dir, const char *source)
{
	static const struct {
		const char *dataset, *word;
		int columns;
	} cut[] = {{"displacement", "displacements", 2}, {"stress", "stresses", 4}, {"mass", "masses", 0}};
	for (size_t i = 0; i < sizeof cut / sizeof *cut; i++) {
		char path[256], name[128], want[64];
		snprintf(name, sizeof name, "short_%s.h5", cut[i].dataset);
		harness_join(path, sizeof path, dir, name);
		snprintf(name, sizeof name, "frame_with_fewer_soil_%s_is_eio", cut[i].word);
		if (copy_file(source, path) || shorten_soil_dataset(path, cut[i].dataset, cut[i].columns, 3)) {
			CHECK(0, name, "cannot write the shortened copy %s", path);
			continue;
		}
		struct report *rep = NULL;
		struct report_row *rows = NULL;
		struct poro_error err = {0};
		long count = 0;
		enum poro_status st = open_and_read_frames(path, &rep, &rows, &count, &err);
		snprintf(want, sizeof want, "but 3 %s", cut[i].word);
		CHECK(st == PORO_EIO && !rows && strstr(err.message, "frame 1 ") && strstr(err.message, want) &&
		      strstr(err.message, path), name, "status %d: %s", st, err.message);
		free(rows);
		report_close(&rep);
	}
}

static void check_errors(const char *dir, const char *polygon_dir)
{
	char path[256], name[128];
	struct report *rep = NULL;
	struct poro_error err = {0};
	struct report_settings set = REPORT_SETTINGS_DEFAULT;

	enum poro_status st = report_open(&rep, harness_join(path, sizeof path, dir, "absent.h5"), &set, &err);
	CHECK(st == PORO_EIO && !rep && strstr(err.message, path), "missing_file_is_eio_naming_it", "status %d: %s",
	      st, err.message);

	FILE *f = fopen(harness_join(path, sizeof path, dir, "plain.h5"), "w");
	if (f)
		fputs("time,toe_x\n0,1\n", f), fclose(f);
	st = report_open(&rep, path, &set, &err);
	CHECK(st == PORO_EINVAL && !rep && strstr(err.message, "not a result file") && strstr(err.message, path),
	      "text_file_is_einval_not_a_result_file", "status %d: %s", st, err.message);
	check_short_datasets(dir, harness_join(path, sizeof path, polygon_dir, "result.h5"));

	double direct[FRAMES], pattern[FRAMES], bulk[FRAMES];
	if (write_synthetic(dir, "single_point", block_rectangle, direct, pattern, bulk))
		CHECK(0, "rectangle_result_written", "cannot write");
	harness_join(path, sizeof path, dir, "result.h5");
	st = report_open(&rep, path, &set, &err);
	CHECK(st == PORO_EINVAL && strstr(err.message, "'slope'") && strstr(err.message, "--ground"),
	      "rectangle_body_needs_ground_and_crest", "status %d: %s", st, err.message);
	set.ground = 0.25;
	st = report_open(&rep, path, &set, &err);
	CHECK(st == PORO_EINVAL && strstr(err.message, "--crest"), "rectangle_body_needs_crest_too", "status %d: %s",
	      st, err.message);
	set.crest = 1.5;
	st = report_open(&rep, path, &set, &err);
	CHECK(!st && report_settings_used(rep)->tolerance == TOLERANCE, "rectangle_body_with_ground_and_crest_opens",
	      "status %d: %s", st, err.message);
	report_close(&rep);

	struct report_settings bad[] = {{NAN, NAN, -0.01}, {NAN, INFINITY, NAN}, {-INFINITY, NAN, NAN}};
	int refused = 0;
	for (int i = 0; i < 3; i++) {
		st = report_open(&rep, harness_join(path, sizeof path, polygon_dir, "result.h5"), &bad[i], &err);
		refused += st == PORO_EINVAL && !rep;
		report_close(&rep);
	}
	CHECK(refused == 3, "negative_tolerance_and_infinite_settings_refused", "%d of 3 refused", refused);

	const char *malformed[] = {"", "1,2,3", "1,2,3,4,3,4", "1,2,3,4,5,6,5,6,9", "1,2,x,4", "1;2;3;4", "1,2,3,4,1", "1,2,3,4,2.5",
				   "1,2,3,4,1e9", "1,2,1,2", "1,2,3,4,", "nan,2,3,4", "1,2,3,inf"};
	struct report_line line;
	int n_bad = (int)(sizeof malformed / sizeof *malformed);
	for (int i = 0; i < n_bad; i++) {
		st = report_line_parse(malformed[i], &line, &err);
		char quoted[64];
		snprintf(quoted, sizeof quoted, "'%s'", malformed[i]);
		snprintf(name, sizeof name, "line_parse_refuses_[%s]", malformed[i]);
		CHECK(st == PORO_EINVAL && strstr(err.message, quoted), name, "status %d: %s", st, err.message);
	}
	st = report_line_parse(" 1.5,-2e-1,3,4.25", &line, &err);
	CHECK(!st && line.vertices == 2 && line.vertex[0][0] == 1.5 && line.vertex[0][1] == -0.2 &&
	      line.vertex[1][0] == 3 && line.vertex[1][1] == 4.25 &&
	      line.samples == REPORT_LINE_SAMPLES, "line_parse_four_numbers_default_samples", "status %d: %s", st,
	      err.message);
	char corners[2048] = "";
	for (int c = 0; c <= REPORT_LINE_VERTICES_MAX; c++)   /* one corner too many */
		snprintf(corners + strlen(corners), sizeof corners - strlen(corners), "%s%d,%d", c ? "," : "", c, c);
	st = report_line_parse(corners, &line, &err);
	CHECK(st == PORO_EINVAL && strstr(err.message, "more than 64 corners"), "line_parse_refuses_too_many_corners",
	      "status %d: %s", st, err.message);
	corners[strlen(corners) - strlen(",64,64")] = 0;
	st = report_line_parse(corners, &line, &err);
	CHECK(!st && line.vertices == REPORT_LINE_VERTICES_MAX && line.vertex[63][1] == 63 &&
	      line.samples == REPORT_LINE_SAMPLES, "line_parse_takes_64_corners", "status %d: %s", st, err.message);
	st = report_line_parse("0,0,1,0,1,2", &line, &err);
	CHECK(!st && line.vertices == 3 && line.vertex[2][1] == 2 && line.samples == REPORT_LINE_SAMPLES,
	      "line_parse_even_count_is_corners_only", "status %d, %d corners, %d samples", st, line.vertices,
	      line.samples);
	st = report_line_parse("0,0,1,0,7", &line, &err);
	CHECK(!st && line.samples == 7, "line_parse_samples", "status %d, %d samples", st, line.samples);
}

int main(void)
{
	char *dp = harness_temp_dir("report_test"), *sp = harness_temp_dir("report_test"),
	     *scratch = harness_temp_dir("report_test");
	if (!dp || !sp || !scratch) {
		CHECK(0, "temporary_directories", "mkdtemp failed");
		HARNESS_EXIT();
	}
	check_synthetic(dp, "double_point");
	check_synthetic(sp, "single_point");
	check_errors(scratch, dp);
	if (!harness_failed_count) {
		harness_remove_dir(dp);
		harness_remove_dir(sp);
		harness_remove_dir(scratch);
	}
	HARNESS_EXIT();
}
