/*
 * strip_footing_001_test.c - paper 001's strip footing (§4.1, Fig. 3, Table 2) by the implicit
 * u-p-U scheme (solver/schemes/implicit/): the undrained bearing capacity of a rough strip footing
 * on weightless Tresca soil, a total-stress problem run on the coupled model with k = 0.1 m/s.
 *
 * Small deformation (§4.1.1, tests/cases/strip_footing_001.json; Figs. 4-6): q rises at 0.01 kPa/s
 * on the soil under the half footing, E/c = 1e4. The limit load is read as spec-001 §9.1 proposes,
 * at half its settlement: q_lim / c := the applied q / c at which the settlement under the
 * footing's centre first reaches d/B = 0.01, ten times the elastic settlement at collapse
 * (interpolated between steps); a run whose settlement stays below it has no limit load. Under
 * load control the footing runs away past the limit and the modified Newton-Raphson iteration
 * then stops the run (at h = 0.5 m at q/c = 6.31, d/B = 0.144: docs/numerics.md, "001's
 * examples"); between d/B = 0.01 and spec-001's 0.02 the curve moves by 1% of q.
 *  - make test: h = 0.5 m with B-bar and without, to q/c = 7.5. With B-bar a limit is reached,
 *    not below Prandtl's 2 + pi, and at most H05_LIMIT_BAND above it (one cell under the half
 *    footing overestimates, as every low-order method does; measured +15.7%, XFAIL); without B-bar (001 Eq. 12's plain GIMP gradients) the soil
 *    locks (Fig. 4): no limit load, or one LOCKING_MARGIN above B-bar's; and its mean-stress
 *    oscillation index (oscillation.h) at the end is OSCILLATION_RATIO times B-bar's (Fig. 5).
 *  - make verify (PORO_VERIFY_LONG=1): 001's Fig. 3 gives no domain size: with the soil 7.5 m x
 *    7.5 m instead of 5 m x 5 m the limit moves by at most DOMAIN_TOLERANCE (spec-001 §9.1); and
 *    h = 0.25, 0.1 and 0.05 m with B-bar (Fig. 6) and h = 0.25 m without, by full Newton (the
 *    consistent tangent: modified Newton stalls before the limit at h = 0.25 m): the limit falls
 *    as h falls (MESH_NOISE allowed), h = 0.1 m within 3% of 2 + pi (spec-001 §9.1 allows +5%),
 *    h = 0.05 m within 3%, and at h = 0.25 m no B-bar locks.
 *
 * Large deformation (§4.1.2, tests/cases/strip_footing_large_001.json; Fig. 7): E/c = 100, the
 * footing an elastic block (E_f = 10 MPa) loaded at 0.1 kPa/s on its top. 001 loads a dry footing
 * by its own weight; the implicit scheme takes saturated bodies only (the loader refuses
 * "saturated": false there), so the block is a stiff saturated body loaded by a traction on its
 * top, which the loads module spreads through its points (a body force, as 001's unit weight).
 * q is the applied pressure (001 reads the contact force, which differs from it by the block's
 * inertia under a load rising over a minute). Asserted (spec-001 §9.2): q/c at d/B = 0.1 within
 * [5.1, 6.0], rising after d/B = 0.05, and at d/B = 1 within [5.7, 7.5]. The run stops at
 * q/c = 5.33, d/B = 0.066 (Newton, its energy at round-off, before a step could converge on its
 * residual; earlier a point beside the footing's corner over-compressed to J = 0.59;
 * docs/numerics.md, "001's examples"): XFAIL while that lasts. make test runs it to
 * t = LD_SHORT_END (elastic), make verify to d/B = 1.
 */
#include <string.h>

#include "../case_file.h"
#include "../harness.h"
#include "oscillation.h"
#include "poro.h"

#define CASES "tests/cases/"
#define FOOTING_B 1.0         /* m: the footing's breadth, twice the half model's loaded span */
#define LIMIT_SETTLEMENT 0.01 /* d/B read as collapse (file comment) */
#define PRANDTL 5.141592653589793 /* 2 + pi, Prandtl's q/c */
#define H05_LIMIT_BAND 0.15   /* h = 0.5 m: at most +15% of 2 + pi (spec-001 §9.1, one cell under the
				 half footing); measured +15.7%, a known failure */
#define LIMIT_BELOW 0.03      /* no mesh may fall more than 3% below 2 + pi */
#define FINE_TOLERANCE 0.03   /* h = 0.1 and 0.05 m */
#define MESH_NOISE 0.01       /* the limit may rise by 1% as h falls (spec-001 §9.1) */
#define LOCKING_MARGIN 0.10   /* no B-bar: at least 10% above B-bar's limit, or none */
#define OSCILLATION_RATIO 3.0 /* no B-bar's mean-stress oscillation index over B-bar's, at least
				 (spec-001 §9.1; measured 20) */
#define SD_SHORT_END 75.0     /* s: q/c = 7.5 */
#define LARGE_DOMAIN 7.5      /* m: the soil's width and depth of the domain check (5 m in the case) */
#define DOMAIN_TOLERANCE 0.01 /* of q_lim */
#define LD_SHORT_END 20.0     /* s: q/c = 2, elastic */

struct footing_run {
	int ok, reached;          /* ran to its end; the settlement reached LIMIT_SETTLEMENT B */
	double q_limit;           /* q/c there */
	double q_at_01, q_at_1;   /* LD: q/c at d/B = 0.1 and 1 (0: not reached) */
	int monotone;             /* LD: q/c rose with d beyond d/B = 0.05 (10-step averages) */
	double d_end, q_end;      /* the last state's d/B and q/c */
	double index;             /* oscillation index of the mean effective stress at the end */
	double seconds;
	char failure[256];
};

/* The applied q / c at time t: the first load's traction, ramped. */
static double q_over_c(const struct case_spec *c, double t)
{
	const struct case_load *l = &c->loads[0];
	const double ramp = l->time_function.kind == TIME_RAMP ? fmin(t / l->time_function.ramp_time, 1.0) : 1.0;
	return -l->traction[1] * ramp / c->materials[0].peak_cohesion;
}

/* q/c where d/B first reaches `target` between the samples (d0, q0) and (d1, q1). */
static double crossing(double target, double d0, double q0, double d1, double q1)
{
	return q0 + (q1 - q0) * (target - d0) / (d1 - d0);
}

/* The soil body 0 made size x size metres, the grid a metre taller, the probes moved with its top. */
static void resize_soil(struct case_spec *c, double size)
{
	const double rise = size - c->bodies[0].max[1];
	c->bodies[0].max[0] = c->bodies[0].max[1] = size;
	c->grid.extent[0] = size, c->grid.extent[1] = size + 1.0;
	for (int k = 0; k < c->probe_count; k++)
		c->probes[k].point[1] += rise;
}

/* Runs `file` at cell size h with B-bar or without, by the Newton tangent given, to `end` (0: the
 * case's), its soil `size` metres wide and deep (0: the case's); probe 0 is the footing's
 * settlement. */
static struct footing_run run_footing(const char *file, double h, enum soil_stabilisation st,
				      enum newton_tangent tangent, double end, double size)
{
	struct footing_run r = {0};
	struct case_spec *c = test_case_load(file);
	struct sim *s = NULL;
	struct poro_error err = {0};
	if (!c)
		return r;
	c->grid.cell_size = h;
	c->formulation.soil_stabilisation = st;
	c->formulation.tangent = tangent;
	if (end > 0)
		c->time.end = end;
	if (size > 0)
		resize_soil(c, size);
	if (sim_create(&s, c, &err)) {
		printf("INFO cannot build %s: %s\n", file, err.message);
		case_destroy(&c);
		return r;
	}
	const double t0 = harness_wall_seconds();
	double d_prev = 0.0, q_prev = 0.0, window_d = 0.0, window_q = 0.0, last_mean_q = -1.0;
	int ok = 1, count = 0;
	r.monotone = 1;
	while (ok && !sim_done(s)) {
		ok = !sim_step(s);
		const double d = -sim_probe_value(s, 0) / FOOTING_B, q = q_over_c(c, sim_time(s));
		if (!r.reached && d >= LIMIT_SETTLEMENT)
			r.reached = 1, r.q_limit = crossing(LIMIT_SETTLEMENT, d_prev, q_prev, d, q);
		if (!r.q_at_01 && d >= 0.1)
			r.q_at_01 = crossing(0.1, d_prev, q_prev, d, q);
		if (!r.q_at_1 && d >= 1.0)
			r.q_at_1 = crossing(1.0, d_prev, q_prev, d, q);
		/* the load-settlement curve's slope beyond d/B = 0.05 over windows of 10 steps */
		if (d > 0.05) {
			window_d += d, window_q += q;
			if (++count == 10) {
				if (last_mean_q >= 0 && window_q / 10 < last_mean_q)
					r.monotone = 0;
				last_mean_q = window_q / 10, window_d = window_q = 0.0, count = 0;
			}
		}
		d_prev = d, q_prev = q;
	}
	r.seconds = harness_wall_seconds() - t0;
	r.ok = ok;
	r.d_end = d_prev, r.q_end = q_prev;
	if (!ok)
		snprintf(r.failure, sizeof r.failure, "%.240s", sim_error(s)->message);
	const int ppc = c->bodies[0].particles_per_cell;
	if (oscillation_index(&c->grid, sim_soil(s), h / ppc, &r.index, &err))
		r.index = -1.0;
	sim_destroy(&s);
	case_destroy(&c);
	return r;
}

static void print_sd(const char *label, double h, const struct footing_run *r)
{
	printf("INFO strip footing 001 SD %s h=%.3g m: %s, q_lim/c = %.4f (%+.2f%% of 2 + pi), last q/c %.3f at "
	       "d/B %.5f, mean-stress oscillation index %.4f, %.1f s of wall time%s%s\n", label, h,
	       r->ok ? "ran" : "FAILED", r->reached ? r->q_limit : NAN,
	       r->reached ? 100 * (r->q_limit / PRANDTL - 1) : NAN, r->q_end, r->d_end, r->index, r->seconds,
	       r->ok ? "" : ": ", r->failure);
}

/* Without B-bar: a limit load LOCKING_MARGIN above B-bar's, or none up to a run's end that lies
 * that far above it. */
static void check_locking(const char *name, const struct footing_run *bbar, const struct footing_run *none,
			  int known)
{
	const double above = (1 + LOCKING_MARGIN) * bbar->q_limit;
	const int locked = bbar->reached && (none->reached ? none->q_limit >= above : none->q_end >= above);
	CHECK_UNLESS_KNOWN(known, locked, name, "no B-bar q_lim/c %.4f (reached %d) against B-bar %.4f (reached %d)",
			   none->q_limit, none->reached, bbar->q_limit, bbar->reached);
}

static void small_deformation(int long_run)
{
	const char *file = CASES "strip_footing_001.json";
	struct footing_run bbar = run_footing(file, 0.5, STABILISATION_BBAR, NEWTON_TANGENT_ELASTIC, SD_SHORT_END, 0);
	struct footing_run none = run_footing(file, 0.5, STABILISATION_NONE, NEWTON_TANGENT_ELASTIC, SD_SHORT_END, 0);
	print_sd("B-bar", 0.5, &bbar);
	print_sd("no B-bar", 0.5, &none);
	CHECK(bbar.reached && bbar.q_limit >= (1 - LIMIT_BELOW) * PRANDTL, "strip_footing_001_h0.5_limit_load_reached",
	      "q_lim/c %.4f (reached %d)", bbar.q_limit, bbar.reached);
	CHECK_KNOWN_FAILURE(bbar.reached && bbar.q_limit <= (1 + H05_LIMIT_BAND) * PRANDTL,
			    "strip_footing_001_h0.5_limit_load_within_15pct_of_prandtl", "q_lim/c %.4f, %+.2f%%",
			    bbar.q_limit, 100 * (bbar.q_limit / PRANDTL - 1));
	check_locking("strip_footing_001_h0.5_locks_without_bbar", &bbar, &none, 0);
	/* Fig. 5: without B-bar the mean stress oscillates, with it a smooth bulb */
	CHECK(bbar.index >= 0 && none.index >= OSCILLATION_RATIO * bbar.index,
	      "strip_footing_001_h0.5_bbar_removes_stress_oscillation", "index %.4f with B-bar, %.4f without",
	      bbar.index, none.index);
	if (!long_run)
		return;
	/* 001's Fig. 3 gives no size: the 5 m domain is large enough if 7.5 m moves q_lim by < 1%
	 * (spec-001 §9.1); the larger domain costs 2.25 times the case's run, so make verify only */
	struct footing_run large =
		run_footing(file, 0.5, STABILISATION_BBAR, NEWTON_TANGENT_ELASTIC, SD_SHORT_END, LARGE_DOMAIN);
	print_sd("B-bar, soil 7.5 m x 7.5 m,", 0.5, &large);
	CHECK(bbar.reached && large.reached && fabs(large.q_limit / bbar.q_limit - 1) <= DOMAIN_TOLERANCE,
	      "strip_footing_001_domain_large_enough", "q_lim/c %.4f on 7.5 m against %.4f on 5 m", large.q_limit,
	      bbar.q_limit);
	/* Fig. 6: the mesh series to the case's end, q/c = 5.8, by full Newton: the elastic tangent's
	 * linear rate falls towards 1 as the mechanism forms, and 100 modified Newton iterations stop
	 * the h = 0.25 m run at q/c = 5.515, d/B = 0.0044, before the limit, where the consistent
	 * tangent converges in 3-7 iterations a step to the end (docs/numerics.md, "001's examples") */
	static const double hs[3] = {0.25, 0.1, 0.05};
	struct footing_run fine[3];
	double previous = bbar.q_limit;
	int falls = bbar.reached;
	for (int k = 0; k < 3; k++) {
		fine[k] = run_footing(file, hs[k], STABILISATION_BBAR, NEWTON_TANGENT_CONSISTENT, 0, 0);
		print_sd("B-bar, consistent tangent,", hs[k], &fine[k]);
		falls = falls && fine[k].reached && fine[k].q_limit <= (1 + MESH_NOISE) * previous;
		previous = fine[k].q_limit;
	}
	CHECK(falls, "strip_footing_001_limit_load_falls_with_h", "q_lim/c %.4f, %.4f, %.4f, %.4f at h = 0.5, 0.25, 0.1, "
	      "0.05 m (0: not reached)", bbar.q_limit, fine[0].q_limit, fine[1].q_limit, fine[2].q_limit);
	/* h = 0.1 m: 5.447, +5.9% (known: the limits fall as 5.949, 5.587, 5.447 with h = 0.5, 0.25,
	 * 0.1 m, beyond 3% and spec-001's +5% at h = 0.1 m; docs/numerics.md); h = 0.05 m, about 7 h
	 * on one thread, not yet run (docs/numerics.md) */
	static const int known[3] = {0, 1, 0};
	for (int k = 1; k < 3; k++) {
		char name[96];
		snprintf(name, sizeof name, "strip_footing_001_h%g_limit_load_within_3pct_of_prandtl", hs[k]);
		CHECK_UNLESS_KNOWN(known[k], fine[k].reached && fabs(fine[k].q_limit / PRANDTL - 1) <= FINE_TOLERANCE, name,
				   "q_lim/c %.4f, %+.2f%% (0: not reached; %s)", fine[k].q_limit,
				   100 * (fine[k].q_limit / PRANDTL - 1), fine[k].ok ? "ran" : fine[k].failure);
	}
	struct footing_run none025 = run_footing(file, 0.25, STABILISATION_NONE, NEWTON_TANGENT_CONSISTENT, 0, 0);
	print_sd("no B-bar, consistent tangent,", 0.25, &none025);
	check_locking("strip_footing_001_h0.25_locks_without_bbar", &fine[0], &none025, 0);
}

static void large_deformation(int long_run)
{
	const double end = long_run ? 0 : LD_SHORT_END;
	struct footing_run r =
		run_footing(CASES "strip_footing_large_001.json", 0.25, STABILISATION_BBAR, NEWTON_TANGENT_ELASTIC, end, 0);
	printf("INFO strip footing 001 LD h=0.25 m: %s at q/c %.3f, d/B %.4f; q/c at d/B = 0.1: %.3f, at d/B = 1: "
	       "%.3f; rising beyond d/B = 0.05: %d; %.1f s of wall time%s%s\n", r.ok ? "ran" : "FAILED", r.q_end,
	       r.d_end, r.q_at_01, r.q_at_1, r.monotone, r.seconds, r.ok ? "" : ": ", r.failure);
	if (!long_run) {
		/* elastic at q/c = 2: within a factor of three of the order of a strip's settlement on
		 * an elastic layer, q B (1 - nu^2) / E = 0.015 B */
		CHECK(r.ok && r.d_end > 0.005 && r.d_end < 0.05, "strip_footing_large_001_elastic_start",
		      "d/B %.4f at q/c %.3f", r.d_end, r.q_end);
		return;
	}
	/* the run stops at q/c = 5.33 (file comment) */
	const int known = 1;
	CHECK_UNLESS_KNOWN(known, r.ok && r.q_at_01 >= 5.1 && r.q_at_01 <= 6.0,
			   "strip_footing_large_001_q_at_0.1B_in_5.1_6.0", "q/c %.3f at d/B = 0.1 (%s)", r.q_at_01,
			   r.ok ? "ran" : r.failure);
	CHECK_UNLESS_KNOWN(known, r.ok && r.q_at_1 >= 5.7 && r.q_at_1 <= 7.5 && r.monotone,
			   "strip_footing_large_001_q_at_1B_in_5.7_7.5_rising", "q/c %.3f at d/B = 1, rising %d (%s)",
			   r.q_at_1, r.monotone, r.ok ? "ran" : r.failure);
}

int main(void)
{
	const char *env = getenv("PORO_VERIFY_LONG");
	const int long_run = env && *env && strcmp(env, "0") != 0;
	small_deformation(long_run);
	large_deformation(long_run);
	HARNESS_EXIT();
}
