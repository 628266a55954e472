/*
 * mann_whitney_test.c - common/mann_whitney.c and common/regression.c against known values:
 *
 *  a. scipy.stats.mannwhitneyu's documented example (its docstring: the ages of 5 male and 4
 *     female subjects): U = 17, exact two-sided p = 1/9 = 0.1111111111111111, asymptotic
 *     two-sided p = 0.11134688653314041; the exact one-sided p is 7/126 (the 7 orderings of the
 *     126 with U >= 17, counted by hand: U <= 3 by symmetry, 1 + 1 + 2 + 3);
 *  b. the exact p-value against a brute-force oracle: every split of the pooled sample into
 *     n_x and n_y values, counted, for high-entropy samples of sizes 1..6;
 *  c. the asymptotic p-value with ties against the formula written out (pair counts for U, the
 *     tie-corrected variance); the exact p-value with ties (what auto takes) against the
 *     brute-force oracle, on samples of 1..6 and 1..7 drawn from four levels, both tails, and on
 *     the service test's case (5 slowed samples above 50 tied ones: 1 / C(55, 5));
 *  d. the exceedance test's p-value C(n, k) / C(n + m, k) against the enumeration of every
 *     split: equal without ties, never below it with ties (conservative), both tails;
 *  e. the verdicts: a band, a 1.5x slower run against a noisy history (regressed), the same
 *     distribution (ok), a small but significant change below the effect size (ok), too little
 *     history (no_history), a faster run (improved); and on a machine with two speeds (the
 *     figures a CI machine printed: identical jobs at 0.286 and 0.456 us), the 1.5x slowed run
 *     with two of its five repeats in the fast state flagged by the exceedance test where the
 *     Mann-Whitney test alone misses it, and unchanged runs wholly in either state, or in a
 *     slower state the history saw once, not flagged.
 */
#include <math.h>
#include <stdio.h>

#include "../harness.h"
#include "mann_whitney.h"
#include "regression.h"

static void scipy_example(void)
{
	const double male[] = { 19, 22, 16, 29, 24 }, female[] = { 20, 11, 17, 12 };
	struct mw_result r;
	int rc = mann_whitney(male, 5, female, 4, MW_TWO_SIDED, MW_AUTO, &r);
	CHECK(rc == 0 && r.u == 17 && r.exact && fabs(r.p - 1.0 / 9) < 1e-14, "mann_whitney_scipy_exact",
	      "U %g p %.17g exact %d", r.u, r.p, r.exact);
	rc = mann_whitney(male, 5, female, 4, MW_TWO_SIDED, MW_ASYMPTOTIC, &r);
	CHECK(rc == 0 && !r.exact && fabs(r.p - 0.11134688653314041) < 1e-12, "mann_whitney_scipy_asymptotic",
	      "p %.17g", r.p);
	rc = mann_whitney(male, 5, female, 4, MW_GREATER, MW_EXACT, &r);
	CHECK(rc == 0 && fabs(r.p - 7.0 / 126) < 1e-14, "mann_whitney_scipy_one_sided", "p %.17g", r.p);
	rc = mann_whitney(female, 4, male, 5, MW_LESS, MW_EXACT, &r);
	CHECK(rc == 0 && r.u == 3 && fabs(r.p - 7.0 / 126) < 1e-14, "mann_whitney_swapped_samples", "U %g p %.17g",
	      r.u, r.p);
}

/* P(U >= u_obs) by enumerating every way to choose which nx of the pooled values are "x". */
static double brute_upper(const double *pool, int nx, int N, double u_obs)
{
	long hits = 0, total = 0;
	for (unsigned mask = 0; mask < (1u << N); mask++) {
		if (__builtin_popcount(mask) != nx)
			continue;
		double u = 0;
		for (int i = 0; i < N; i++)
			for (int j = 0; j < N; j++)
				if ((mask >> i & 1) && !(mask >> j & 1))
					u += pool[i] > pool[j] ? 1 : pool[i] == pool[j] ? 0.5 : 0;
		total++;
		hits += u >= u_obs - 1e-9;
	}
	return (double)hits / (double)total;
}

static void asymptotic_with_ties(void)
{
	const double x[] = { 2.385, 3.1, 3.1, 4.75, 5.2, 3.1 }, y[] = { 1.9, 2.385, 3.1, 2.2, 2.6, 1.4, 3.3 };
	const int nx = 6, ny = 7, N = 13;
	double u = 0;
	for (int i = 0; i < nx; i++)
		for (int j = 0; j < ny; j++)
			u += x[i] > y[j] ? 1 : x[i] == y[j] ? 0.5 : 0;
	/* tie groups: 2.385 twice, 3.1 four times */
	double tie = (8 - 2) + (64 - 4);
	double sd = sqrt(nx * ny / 12.0 * ((N + 1) - tie / (N * (N - 1.0))));
	double want = 0.5 * erfc((u - nx * ny / 2.0 - 0.5) / sd / sqrt(2.0));
	struct mw_result r;
	int rc = mann_whitney(x, nx, y, ny, MW_GREATER, MW_ASYMPTOTIC, &r);
	CHECK(rc == 0 && !r.exact && r.u == u && fabs(r.p - want) < 1e-14, "mann_whitney_ties_asymptotic",
	      "U %g (want %g) p %.17g (want %.17g) exact %d", r.u, u, r.p, want, r.exact);
	/* auto takes the exact count with ties: every split of the 13 values enumerated */
	double pool[13];
	for (int i = 0; i < nx; i++)
		pool[i] = x[i];
	for (int j = 0; j < ny; j++)
		pool[nx + j] = y[j];
	const double brute = brute_upper(pool, nx, N, u);
	rc = mann_whitney(x, nx, y, ny, MW_GREATER, MW_AUTO, &r);
	printf("INFO mann_whitney with ties: exact p %.6g (enumerated %.6g), asymptotic %.6g\n", r.p, brute, want);
	CHECK(rc == 0 && r.exact && fabs(r.p - brute) < 1e-12, "mann_whitney_ties_exact_matches_enumeration",
	      "p %.17g, enumerated %.17g, exact %d", r.p, brute, r.exact);
}

/* b: both tails of the exact p-value against the enumeration, for samples of 1..6 against 1..ny_max:
 * high-entropy values (no ties), or, tied, values on four levels 0.5% apart (ties within and
 * between the samples, as the median step's histogram bins give) */
static void exact_against_brute_force(int tied, int ny_max, const char *name)
{
	double worst = 0;
	int cases = 0;
	for (int nx = 1; nx <= 6; nx++)
		for (int ny = 1; ny <= ny_max; ny++) {
			double pool[13], pool_y_first[13];
			for (int i = 0; i < nx + ny; i++)   /* x a little larger */
				pool[i] = tied ? 2.385 * (1 + 0.005 * floor(rnd(0, 4) + (i < nx ? rnd(0, 1.5) : 0)))
					       : rnd(0.37, 9.81) + (i < nx ? rnd(0, 1.3) : 0);
			struct mw_result up, low;
			if (mann_whitney(pool, nx, pool + nx, ny, MW_GREATER, MW_EXACT, &up) ||
			    mann_whitney(pool, nx, pool + nx, ny, MW_LESS, MW_EXACT, &low))
				continue;
			/* P(U <= u) of x is P(U >= nx ny - u) of y */
			for (int i = 0; i < ny; i++)
				pool_y_first[i] = pool[nx + i];
			for (int i = 0; i < nx; i++)
				pool_y_first[ny + i] = pool[i];
			const double lower = brute_upper(pool_y_first, ny, nx + ny, nx * ny - low.u);
			worst = fmax(worst, fmax(fabs(up.p - brute_upper(pool, nx, nx + ny, up.u)), fabs(low.p - lower)));
			cases++;
		}
	printf("INFO mann_whitney exact%s vs brute force: %d sample pairs, largest p difference %.3g\n",
	       tied ? " with ties" : "", cases, worst);
	CHECK(cases == 6 * ny_max && worst < 1e-12, name, "%d cases, worst %.3g", cases, worst);
}

/* The service test's case: 50 history samples read off 0.5% bins (tied), 5 slowed samples above
 * them all. Exactly, 1 / C(55, 5); the normal approximation's tail gave 8e-5, close enough to
 * alpha 0.001 that a few overlapping samples crossed it. */
static void tied_history_slowdown(void)
{
	double history[50], run[5];
	for (int i = 0; i < 50; i++)
		history[i] = 0.2426 * pow(1.005, (double)(i % 3));
	for (int i = 0; i < 5; i++)
		run[i] = 0.3743 * pow(1.005, (double)(i % 2));
	struct mw_result exact, asym;
	int rc = mann_whitney(run, 5, history, 50, MW_GREATER, MW_AUTO, &exact);
	rc |= mann_whitney(run, 5, history, 50, MW_GREATER, MW_ASYMPTOTIC, &asym);
	const double want = 1.0 / 3478761;   /* C(55, 5) */
	printf("INFO 5 slowed samples above 50 tied ones: exact p %.3g, asymptotic %.3g\n", exact.p, asym.p);
	CHECK(rc == 0 && exact.exact && fabs(exact.p / want - 1) < 1e-9, "mann_whitney_tied_history_exact",
	      "p %.6g, want %.6g", exact.p, want);
}

/* d: P(at least k of the x split's values above every y value) over every split of the pool,
 * against regression_exceedance_p, for sizes 1..6 against 1..7, both tails. */
static void exceedance_against_brute_force(int tied, const char *name)
{
	double worst_untied = 0, below = 0;
	int cases = 0;
	for (int nx = 1; nx <= 6; nx++)
		for (int ny = 1; ny <= 7; ny++)
			for (int slower = 0; slower <= 1; slower++) {
				const int N = nx + ny;
				double pool[13], split_x[13], split_y[13];
				for (int i = 0; i < N; i++) /* x shifted toward the tail tested */
					pool[i] = tied ? 2.385 * (1 + 0.005 * floor(rnd(0, 3)))
						       : rnd(0.37, 9.81) + (i < nx ? (slower ? 1 : -1) * rnd(0, 4) : 0);
				const double p = regression_exceedance_p(pool, nx, pool + nx, ny, slower);
				int k_obs = 0; /* the observed count, from p's definition */
				for (int i = 0; i < nx; i++) {
					int beyond = 1;
					for (int j = 0; j < ny; j++)
						beyond &= slower ? pool[i] > pool[nx + j] : pool[i] < pool[nx + j];
					k_obs += beyond;
				}
				long hits = 0, total = 0;
				for (unsigned mask = 0; mask < (1u << N); mask++) {
					if (__builtin_popcount(mask) != nx)
						continue;
					int a = 0, b = 0;
					for (int i = 0; i < N; i++)
						if (mask >> i & 1)
							split_x[a++] = pool[i];
						else
							split_y[b++] = pool[i];
					int k = 0;
					for (int i = 0; i < nx; i++) {
						int beyond = 1;
						for (int j = 0; j < ny; j++)
							beyond &= slower ? split_x[i] > split_y[j]
									 : split_x[i] < split_y[j];
						k += beyond;
					}
					total++;
					hits += k >= k_obs;
				}
				const double exact = (double)hits / (double)total;
				if (tied)
					below = fmax(below, exact - p); /* p must not be below the exact one */
				else
					worst_untied = fmax(worst_untied, fabs(exact - p));
				cases++;
			}
	printf("INFO exceedance p%s vs enumeration: %d cases, largest %s %.3g\n", tied ? " with ties" : "", cases,
	       tied ? "shortfall below the exact p" : "difference", tied ? below : worst_untied);
	CHECK(cases == 84 && worst_untied < 1e-12 && below <= 1e-12, name, "%d cases, worst %.3g, shortfall %.3g",
	      cases, worst_untied, below);
}

/* n values around center with relative noise spread (uniform). */
static void noisy(double *v, int n, double center, double spread)
{
	for (int i = 0; i < n; i++)
		v[i] = center * (1 + rnd(-spread, spread));
}

static void verdicts(void)
{
	struct regression_rule rule = REGRESSION_RULE_DEFAULT;
	struct regression_verdict v;
	const double err[] = { 0.0123 };
	regression_band(err, 1, 0, 0.02, &v);
	CHECK(v.status == REGRESSION_OK, "regression_band_inside", "%s", v.detail);
	const double worse[] = { 0.0123, 0.0251 };
	regression_band(worse, 2, 0, 0.02, &v);
	CHECK(v.status == REGRESSION_REGRESSED, "regression_band_outside", "%s", v.detail);

	double history[30], run[5];
	noisy(history, 30, 2.385, 0.08);
	noisy(run, 5, 1.5 * 2.385, 0.08);
	regression_history(run, 5, history, 30, &rule, &v);
	printf("INFO regression 1.5x slower: %s\n", v.detail);
	CHECK(v.status == REGRESSION_REGRESSED, "regression_history_slowdown_flagged", "%s", v.detail);

	int alarms = 0;
	for (int k = 0; k < 200; k++) {   /* the same distribution: no alarm */
		noisy(run, 5, 2.385, 0.08);
		regression_history(run, 5, history, 30, &rule, &v);
		alarms += v.status == REGRESSION_REGRESSED;
	}
	printf("INFO regression same distribution: %d alarms in 200 runs\n", alarms);
	CHECK(alarms == 0, "regression_history_no_false_alarms", "%d alarms", alarms);

	noisy(run, 5, 1.05 * 2.385, 0.001);   /* significant, yet below the 10% effect */
	double tight[30];
	noisy(tight, 30, 2.385, 0.001);
	regression_history(run, 5, tight, 30, &rule, &v);
	CHECK(v.status == REGRESSION_OK && v.p_slower < 1e-4, "regression_history_small_effect_ok", "%s", v.detail);

	regression_history(run, 5, history, 3, &rule, &v);   /* 1 / C(8, 5) = 0.018; 1 / C(9, 5) = 0.0079 */
	CHECK(v.status == REGRESSION_NO_HISTORY && !regression_can_detect(5, 3, 0.01) && regression_can_detect(5, 4, 0.01),
	      "regression_history_too_short", "%s", v.detail);

	noisy(run, 5, 0.6 * 2.385, 0.08);
	regression_history(run, 5, history, 30, &rule, &v);
	CHECK(v.status == REGRESSION_IMPROVED, "regression_history_improved", "%s", v.detail);
}

/* e: a machine with two speeds. A CI machine printed, for one unchanged job run again and again,
 * the median step at 0.286 or near 0.456 us (run medians 0.437-0.476 and one 0.287, each run's
 * samples from 0.286 up), and for the run slowed 1.5x the samples below; the history here is 50
 * samples, 38 near 0.456 and 12 at 0.286, each on the 0.5% bins the figure is read off. */
static void two_speed_machine(void)
{
	struct regression_rule rule = REGRESSION_RULE_DEFAULT;
	struct regression_verdict v;
	double history[50];
	for (int i = 0; i < 50; i++)
		history[i] = (i % 4 == 3 && i < 48 ? 0.286 : 0.4502) * pow(1.005, (double)(i % 5));
	const double slowed[] = { 0.7159, 0.7124, 0.7195, 0.4756, 0.4480 };
	regression_history(slowed, 5, history, 50, &rule, &v);
	printf("INFO two speeds, 1.5x slowed: %s\n", v.detail);
	CHECK(v.status == REGRESSION_REGRESSED && v.p_slower > rule.alpha / 2 && v.p_exceed_slower <= rule.alpha / 2,
	      "regression_two_speeds_slowdown_flagged_by_exceedance", "%s", v.detail);

	const double fast[] = { 0.286, 0.2874, 0.286, 0.2888, 0.286 };
	const double slow[] = { 0.4662, 0.4709, 0.4616, 0.4733, 0.4686 };
	regression_history(fast, 5, history, 50, &rule, &v);
	CHECK(v.status == REGRESSION_OK && v.p_faster < rule.alpha / 2, "regression_two_speeds_fast_state_not_improved",
	      "%s", v.detail);
	regression_history(slow, 5, history, 50, &rule, &v);
	CHECK(v.status == REGRESSION_OK, "regression_two_speeds_slow_state_ok", "%s", v.detail);

	/* a third, slower state seen once in the history (one sample 0.664), then a whole run in it */
	history[49] = 0.664;
	const double third[] = { 0.688, 0.6845, 0.6914, 0.688, 0.6811 };
	regression_history(third, 5, history, 50, &rule, &v);
	CHECK(v.status == REGRESSION_OK && v.p_slower < rule.alpha / 2, "regression_two_speeds_seen_state_ok", "%s",
	      v.detail);
}

int main(void)
{
	scipy_example();
	exact_against_brute_force(0, 6, "mann_whitney_exact_matches_enumeration");
	asymptotic_with_ties();
	exact_against_brute_force(1, 7, "mann_whitney_exact_ties_matches_enumeration");
	tied_history_slowdown();
	exceedance_against_brute_force(0, "exceedance_matches_enumeration");
	exceedance_against_brute_force(1, "exceedance_ties_conservative");
	verdicts();
	two_speed_machine();
	return harness_failed_count ? 1 : 0;
}
