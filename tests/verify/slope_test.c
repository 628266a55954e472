/*
 * slope_test.c - the Mohr-Coulomb slope of 000 §5.3 (Table 3, SRF = 2, Figs. 5-7): the same time
 * step for k = 1e-3 and 1e-7 m/s, the low-permeability slope failing deeper and settling more,
 * soil and water mass conserved, and the modified F-bar against the standard F-bar (Fig. 7).
 *
 * Cases: tests/cases/mc_slope_k{1e-3,1e-7}_{double,single}_point.json (geometry and initial state
 * in docs/examples.md: gravity loading at the slope's own conductivity, water cavitating at
 * -100 kPa, without which Fig. 6's order is reversed). Case time = paper time + 1 s (the elastic
 * gravity ramp comes first).
 *
 * make test (reduced size): h = REDUCED_H with REDUCED_PPC^2 points per cell, dt scaled with h
 * (the CFL number of the paper's 0.002 s at 0.5 m), to the paper's 6 s.
 * make verify (PORO_VERIFY_LONG=1): the paper's size, h = 0.5 m, 4x4 points per cell,
 * dt = 0.002 s, to 6 s.
 *
 * Measured per run: crest settlement (probe 0 of the cases: the soil point nearest the crest
 * edge), the points mobilised (displacement above one cell) and the lowest initial height among
 * them (the depth of the failure), the oscillation index of the mean effective stress
 * (solver/output/oscillation.h) at the paper's 2, 4 and 6 s, the pore pressure along the lower shear
 * band at the paper's 3 s (Fig. 5b, sampled as `poro-solve report --line` does), the largest
 * relative displacement of a water point from the soil point it started on (§5.3: 0.0014 m at
 * k = 1e-7 and 0.0065 m at k = 1e-3 m/s), and the mass balance of both phases.
 *
 * And the water pressure's pattern of period two cells (docs/numerics.md, "A pressure pattern of
 * period two cells"): the two-cell pattern index (oscillation.h) of the water points seeded in
 * the foundation below y = FOUNDATION_TOP, at case time PATTERN_TIME, where the report read it
 * (142, 212, 209, 137 ... kPa along y = 2 m). The slope's soil above is left out: where the slide
 * has sheared the seeding lattice, neighbours on it are no longer neighbours and the index reads
 * that as a pattern too. On the cases as they stand the pattern is there (a known failure: the
 * consistent projection cannot see it and the pressure stabilisation that holds it down changes
 * the failure, docs/numerics.md); with formulation.pressure_stabilisation "second_difference" it
 * is not.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../harness.h"
#include "case.h"
#include "oscillation.h"
#include "particles.h"
#include "poro.h"
#include "report.h"
#include "slope_case.h"

#define CASE_DIR "tests/cases/"
#define PAPER_H 0.5                 /* m */
#define REDUCED_H 1.0               /* m: Table 4's cell (Table 4 itself runs 6x6 and more per cell) */
#define REDUCED_PPC 2
#define INITIALISATION 1.0          /* s: the gravity ramp before the paper's t = 0 */
#define MASS_TOLERANCE 1e-12        /* relative: points carry constant masses, outflow is booked */
#define SNAPSHOTS 3
static const double snapshot_paper_time[SNAPSHOTS] = {2.0, 4.0, 6.0};   /* 000 Fig. 7 */

/* 000 Fig. 5b: the lower shear band, which Yuan et al. define and 000 only sketches in Fig. 5a.
 * Here the ridge of accumulated plastic strain of the full-size k = 1e-3 double-point run at the
 * paper's 3 s, traced row by row and column by column (docs/examples.md): from behind the crest
 * down into the foundation's top and out at the toe, 17.3 m long, 41 samples. */
#define BAND "8.9,14.25,9.6,11.5,10.4,9.75,11.4,7.5,12.4,6.25,13.6,5.1,14.75,4.4,16.5,4.0,18.25,4.5,20,5.0,41"
#define BAND_SAMPLES 41
#define BAND_PAPER_TIME 3.0         /* s */
#define BAND_PRINT_EVERY 5          /* samples between two printed on the INFO line */
#define PATTERN_TIME 3.0            /* s, case time (the report's t = 3 s; the paper's 2 s) */
#define FOUNDATION_TOP 4.0          /* m: the water points seeded below it (the toe plain is at 5 m) */
#define PATTERN_FLAG 0.1            /* pattern index that flags a pattern: about 7% of the pressure
				       alternating along one direction (2 A / P / sqrt(2)); measured at
				       PATTERN_TIME 0.54 (reduced) and 0.31 (paper size) on the cases, 0.034
				       and 0.002 with the pressure stabilisation */

struct slope_run {
	int ok;
	long steps;
	double dt, settlement, lowest_mobilised, seconds;
	long mobilised;
	double oscillation[SNAPSHOTS];
	double soil_mass_error, water_mass_error;
	struct report_sample band[BAND_SAMPLES];   /* pore pressure, Pa, compression positive */
	int band_sampled;
	double relative_displacement;              /* m, largest over the point pairs; NAN if unpaired */
	double pattern;                            /* pressure pattern index at PATTERN_TIME; NAN if not taken */
};

/* The two-cell pattern index of the water pressure over the water points seeded below
 * FOUNDATION_TOP (their reference positions on the seeding lattice); NAN when undefined. */
static double foundation_pattern(const struct case_spec *c, const struct sim *s, double h, int ppc)
{
	const struct particles *w = sim_water(s);
	struct particles view = {0};
	double *x0 = malloc(sizeof *x0 * 2 * ((size_t)w->n + 1)), *p = malloc(sizeof *p * ((size_t)w->n + 1));
	double index = NAN;
	struct poro_error err = {0};
	for (idx_t q = 0; x0 && p && q < w->n; q++)
		if (w->x0[2 * q + 1] < FOUNDATION_TOP) {
			x0[2 * view.n] = w->x0[2 * q], x0[2 * view.n + 1] = w->x0[2 * q + 1];
			p[view.n++] = w->pressure[q];
		}
	view.x0 = x0;
	if (x0 && p && oscillation_index_pattern(&c->grid, &view, h / ppc, ppc, p, &index, &err))
		printf("INFO pressure pattern index: %s\n", err.message), index = NAN;
	free(x0);
	free(p);
	return index;
}

/* Mobilised soil: points displaced by more than one cell; the lowest initial height among them
 * marks how deep the failure reaches. */
static void measure_failure(const struct particles *p, double h, struct slope_run *r)
{
	r->mobilised = 0;
	r->lowest_mobilised = INFINITY;
	for (idx_t q = 0; q < p->n; q++) {
		double ux = p->x[2 * q] - p->x0[2 * q], uy = p->x[2 * q + 1] - p->x0[2 * q + 1];
		if (hypot(ux, uy) > h) {
			r->mobilised++;
			r->lowest_mobilised = fmin(r->lowest_mobilised, p->x0[2 * q + 1]);
		}
	}
}

/* The band's pore pressure from the points that carry it (sim_pore_pressure: water in double
 * point, compression positive as in result.h5), averaged within one cell of each sample
 * (REPORT_LINE_RADIUS). */
static int sample_band(const struct sim *s, double h, struct slope_run *r)
{
	const idx_t n = sim_pressure_point_count(s);
	struct report_line band;
	struct poro_error err = {0};
	double *p = malloc(sizeof *p * ((size_t)n + 1)), *x = malloc(sizeof *x * 2 * ((size_t)n + 1));
	int ok = p && x && !report_line_parse(BAND, &band, &err) && band.samples == BAND_SAMPLES;
	if (ok) {
		sim_pore_pressure(s, p, x);
		report_line_sample_points(&band, x, p, n, REPORT_LINE_RADIUS * h, r->band);
	}
	free(p);
	free(x);
	return ok;
}

/* Water points start on soil points, in the same order, and stay attached through the gravity
 * ramp (docs/examples.md): offset[] holds each pair's separation at the ramp's end, and the
 * relative displacement is how far a pair has moved apart since. NAN when the sets do not pair
 * (single point, or water points have left). */
static double relative_displacement(const struct sim *s, const double *offset)
{
	const struct particles *p = sim_soil(s), *w = sim_water(s);
	if (!offset || w->n != p->n || w->x == p->x)
		return NAN;
	double largest = 0.0;
	for (idx_t q = 0; q < p->n; q++)
		largest = fmax(largest, hypot(p->x[2 * q] - w->x[2 * q] - offset[2 * q],
					      p->x[2 * q + 1] - w->x[2 * q + 1] - offset[2 * q + 1]));
	return largest;
}

static double *pair_offsets(const struct sim *s)
{
	const struct particles *p = sim_soil(s), *w = sim_water(s);
	double *offset = w->n == p->n ? malloc(sizeof *offset * 2 * ((size_t)p->n + 1)) : NULL;
	for (idx_t k = 0; offset && k < 2 * p->n; k++)
		offset[k] = p->x[k] - w->x[k];
	return offset;
}

static void set_stabilisation(json_t *doc, void *stabilisation)
{
	slope_case_set(doc, "formulation", "soil_stabilisation", json_string(stabilisation));
}

static void set_pressure_stabilisation(json_t *doc, void *unused)
{
	slope_case_set(doc, "formulation", "pressure_stabilisation", json_string("second_difference"));
	slope_case_set(doc, "time", "end", json_real(PATTERN_TIME));
}

/* The water pressure's pattern index at PATTERN_TIME on `file` with the pressure stabilisation. */
static double stabilised_pattern(const char *file, double h, int ppc)
{
	struct case_spec *c = NULL;
	struct sim *s = NULL;
	if (slope_case_create(file, h, ppc, set_pressure_stabilisation, NULL, &c, &s))
		return NAN;
	int ok = 1;
	while (ok && !sim_done(s))
		ok = !sim_step(s);
	const double index = ok ? foundation_pattern(c, s, h, ppc) : NAN;
	if (!ok)
		printf("INFO %s with the pressure stabilisation failed at t = %.4f s: %s\n", file, sim_time(s),
		       sim_error(s)->message);
	sim_destroy(&s);
	case_destroy(&c);
	return index;
}

static struct slope_run run_slope(const char *file, double h, int ppc, const char *stabilisation)
{
	struct slope_run r = {0};
	r.pattern = NAN;
	struct case_spec *c = NULL;
	struct sim *s = NULL;
	struct poro_error err = {0};
	r.ok = !slope_case_create(file, h, ppc, set_stabilisation, (void *)stabilisation, &c, &s);
	if (!r.ok)
		return r;
	r.dt = c->time.dt;
	const double soil0 = sim_soil_mass(s), water0 = sim_water_mass(s), t0 = harness_wall_seconds();
	double *offset = NULL;
	int next = 0;
	while (r.ok && !sim_done(s)) {
		r.ok = !sim_step(s);
		r.steps++;
		if (r.ok && !offset && sim_time(s) >= INITIALISATION - 0.5 * r.dt)
			offset = pair_offsets(s);
		if (r.ok && !r.band_sampled && sim_time(s) >= INITIALISATION + BAND_PAPER_TIME - 0.5 * r.dt)
			r.band_sampled = sample_band(s, h, &r);
		if (r.ok && isnan(r.pattern) && sim_time(s) >= PATTERN_TIME - 0.5 * r.dt)
			r.pattern = foundation_pattern(c, s, h, ppc);
		if (r.ok && next < SNAPSHOTS && sim_time(s) >= INITIALISATION + snapshot_paper_time[next] - 0.5 * r.dt) {
			if (oscillation_index(&c->grid, sim_soil(s), h / ppc, &r.oscillation[next], &err))
				r.ok = 0, printf("INFO oscillation index: %s\n", err.message);
			next++;
		}
	}
	r.seconds = harness_wall_seconds() - t0;
	if (!r.ok && s && sim_error(s)->code)
		printf("INFO %s failed at t = %.4f s: %s\n", file, sim_time(s), sim_error(s)->message);
	r.settlement = -sim_probe_value(s, 0);
	r.relative_displacement = relative_displacement(s, offset);
	free(offset);
	measure_failure(sim_soil(s), h, &r);
	r.soil_mass_error = fabs(sim_soil_mass(s) - soil0) / soil0;
	r.water_mass_error = fabs(sim_water_mass(s) + sim_water_outflow_mass(s) - water0) / water0;
	sim_destroy(&s);
	case_destroy(&c);
	return r;
}

static void report(const char *label, double h, int ppc, const struct slope_run *r)
{
	printf("INFO mc slope %s h=%.2f m %dx%d dt=%.4f s: %s after %ld steps, crest settlement %.3f m, %ld points "
	       "mobilised (|u| > h) down to initial y = %.2f m, oscillation index at paper t = 2/4/6 s "
	       "%.4f/%.4f/%.4f, mass error soil %.1e water %.1e, run time %.1f s\n", label, h, ppc, ppc, r->dt,
	       r->ok ? "ran to the end" : "FAILED", r->steps, r->settlement, r->mobilised, r->lowest_mobilised,
	       r->oscillation[0], r->oscillation[1], r->oscillation[2], r->soil_mass_error, r->water_mass_error,
	       r->seconds);
	if (r->band_sampled) {
		printf("INFO mc slope %s h=%.2f m: pore pressure along the lower shear band at paper t = %.0f s (000 "
		       "Fig. 5b), kPa at distance m:", label, h, BAND_PAPER_TIME);
		for (int k = 0; k < BAND_SAMPLES; k += BAND_PRINT_EVERY)
			printf(" %.1f:%.1f", r->band[k].distance, r->band[k].pore_pressure / 1e3);
		printf("; largest water-soil relative displacement %.4f m (000 §5.3: 0.0014 m at k=1e-7, 0.0065 m "
		       "at k=1e-3)\n", r->relative_displacement);
	}
}

/* Every sample of the band has points within a cell: the band lies in the saturated slope. */
static int band_in_water(const struct slope_run *r)
{
	int ok = r->band_sampled;
	for (int k = 0; ok && k < BAND_SAMPLES; k++)
		ok = r->band[k].points > 0 && isfinite(r->band[k].pore_pressure);
	return ok;
}

static void check_slope(double h, int ppc, const char *size)
{
	char name[128];
	struct slope_run high = run_slope(CASE_DIR "mc_slope_k1e-3_double_point.json", h, ppc,
					  "modified_fbar");
	struct slope_run low = run_slope(CASE_DIR "mc_slope_k1e-7_double_point.json", h, ppc,
					 "modified_fbar");
	struct slope_run fbar = run_slope(CASE_DIR "mc_slope_k1e-3_double_point.json", h, ppc, "fbar");
	report("k=1e-3 double point modified F-bar", h, ppc, &high);
	report("k=1e-7 double point modified F-bar", h, ppc, &low);
	report("k=1e-3 double point standard F-bar", h, ppc, &fbar);

	/* the reported pattern of period two cells in the water pressure (docs/numerics.md) */
	const double stabilised = stabilised_pattern(CASE_DIR "mc_slope_k1e-3_double_point.json", h, ppc);
	printf("INFO mc slope h=%.2f m %dx%d: pressure pattern index of the water seeded below y = %.0f m at t = %.0f s, "
	       "k=1e-3 %.3f, k=1e-7 %.3f; k=1e-3 with the pressure stabilisation %.3f\n", h, ppc, ppc, FOUNDATION_TOP,
	       PATTERN_TIME, high.pattern, low.pattern, stabilised);
	snprintf(name, sizeof name, "mc_slope_%s_water_pressure_without_two_cell_pattern", size);
	CHECK_KNOWN_FAILURE(high.pattern < PATTERN_FLAG, name, "pattern index %.3f (flagged above %.2f): the consistent "
			    "projection cannot see the node-to-node alternation; docs/numerics.md", high.pattern,
			    PATTERN_FLAG);
	snprintf(name, sizeof name, "mc_slope_%s_pressure_stabilisation_removes_two_cell_pattern", size);
	CHECK(stabilised < PATTERN_FLAG, name, "pattern index %.3f with the stabilisation against %.3f without "
	      "(flagged above %.2f)", stabilised, high.pattern, PATTERN_FLAG);

	snprintf(name, sizeof name, "mc_slope_%s_both_permeabilities_run_at_one_dt", size);
	CHECK(high.ok && low.ok && high.dt == low.dt, name, "k=1e-3 %s, k=1e-7 %s", high.ok ? "ok" : "failed",
	      low.ok ? "ok" : "failed");
	snprintf(name, sizeof name, "mc_slope_%s_mass_conserved", size);
	CHECK(high.ok && low.ok && fmax(high.soil_mass_error, high.water_mass_error) < MASS_TOLERANCE &&
	      fmax(low.soil_mass_error, low.water_mass_error) < MASS_TOLERANCE, name,
	      "soil %.1e/%.1e water %.1e/%.1e", high.soil_mass_error, low.soil_mass_error, high.water_mass_error,
	      low.water_mass_error);
	snprintf(name, sizeof name, "mc_slope_%s_lower_shear_band_sampled_in_the_water", size);
	CHECK(band_in_water(&high) && band_in_water(&low), name, "k=1e-3 %s, k=1e-7 %s",
	      band_in_water(&high) ? "every sample" : "a sample without water points",
	      band_in_water(&low) ? "every sample" : "a sample without water points");
	/* 000 §5.3: 0.0065 m at k = 1e-3 against 0.0014 m at k = 1e-7 m/s */
	snprintf(name, sizeof name, "mc_slope_%s_water_moves_off_the_soil_more_at_high_permeability", size);
	CHECK(high.relative_displacement > low.relative_displacement, name, "largest relative displacement "
	      "k=1e-3 %.4f m vs k=1e-7 %.4f m", high.relative_displacement, low.relative_displacement);
	/* Fig. 6 and §5.3: at k = 1e-7 m/s the failure reaches deeper, mobilises more points and
	 * settles more. The cases load at the slope's own conductivity and let the water cavitate at
	 * -100 kPa (docs/examples.md): with water that takes any tension the suction behind the crest
	 * ties the low-permeability slope back and the order is reversed. */
	snprintf(name, sizeof name, "mc_slope_%s_low_permeability_settles_more", size);
	CHECK(high.ok && low.ok && low.settlement > high.settlement, name, "crest settlement k=1e-7 %.3f m vs "
	      "k=1e-3 %.3f m (000 Fig. 6)", low.settlement, high.settlement);
	snprintf(name, sizeof name, "mc_slope_%s_low_permeability_fails_deeper", size);
	CHECK(high.ok && low.ok && low.lowest_mobilised < high.lowest_mobilised, name, "lowest initial height "
	      "mobilised k=1e-7 %.2f m vs k=1e-3 %.2f m (000 Fig. 6: a deeper shear band)", low.lowest_mobilised,
	      high.lowest_mobilised);
	snprintf(name, sizeof name, "mc_slope_%s_low_permeability_mobilises_more", size);
	CHECK(high.ok && low.ok && low.mobilised > high.mobilised, name, "mobilised points k=1e-7 %ld vs k=1e-3 %ld "
	      "(000 §5.3: more points mobilised)", low.mobilised, high.mobilised);
	for (int i = 0; i < SNAPSHOTS; i++) {
		snprintf(name, sizeof name, "mc_slope_%s_modified_fbar_smoother_than_fbar_t%.0f", size,
			 snapshot_paper_time[i]);
		CHECK(high.ok && fbar.ok && high.oscillation[i] < fbar.oscillation[i], name,
		      "oscillation index modified %.4f vs F-bar %.4f (000 Fig. 7)", high.oscillation[i],
		      fbar.oscillation[i]);
	}
}

int main(void)
{
	check_slope(REDUCED_H, REDUCED_PPC, "reduced");
	const char *long_runs = getenv("PORO_VERIFY_LONG");
	if (long_runs && *long_runs && strcmp(long_runs, "0") != 0)
		check_slope(PAPER_H, 4, "paper_size");
	HARNESS_EXIT();
}
