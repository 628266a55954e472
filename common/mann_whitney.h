/*
 * mann_whitney.h - the Mann-Whitney U test (Wilcoxon rank-sum test) of two independent samples,
 * the rank test the benchmark nightlies judge timing figures with (docs/benchmarks.md).
 *
 * U of x is the number of pairs (x_i, y_j) with x_i > y_j, ties counting one half; from the
 * ranks of the pooled sample (mid-ranks for ties), U_x = R_x - n_x (n_x + 1) / 2. Under the null
 * hypothesis (both samples from one distribution) U_x has mean n_x n_y / 2.
 *
 * The p-value (method "auto"):
 *   exact      without ties, as scipy.stats.mannwhitneyu computes it, when n_x n_y <=
 *              MW_EXACT_MAX_PRODUCT: from the exact null distribution of U, counted by the
 *              recurrence f(m, n, u) = f(m - 1, n, u - n) + f(m, n - 1, u) (sums of non-negative
 *              counts, so no cancellation);
 *              with ties, where scipy turns asymptotic, when the count's work is at most
 *              MW_EXACT_TIES_MAX_WORK: the permutation distribution of the rank sum given the ties
 *              (every choice of which n_x of the pooled values are x equally likely, mid-ranks
 *              kept; R's coin::wilcox_test(distribution = "exact") computes the same). Timings
 *              read off a histogram of 0.5% bins tie often, and the normal approximation's tail is
 *              far heavier than the exact one's: 5 samples above all of 50 tied ones get p = 8e-5
 *              from it, 3e-7 exactly, so a few samples of the history overlapping a slowed run
 *              pushed p past alpha 0.001 (seen once in a few runs of the service test);
 *   asymptotic otherwise: the normal approximation with the tie correction of the variance,
 *              sigma^2 = n_x n_y / 12 ((N + 1) - sum(t^3 - t) / (N (N - 1))), and a continuity
 *              correction of 1/2 towards the mean (scipy's).
 * "greater" tests whether x tends to be larger than y (a slower run: P(U >= U_obs)); "less" the
 * opposite; "two_sided" doubles the smaller tail (at most 1).
 *
 * No allocation survives a call; a call allocates O(n_x + n_y) for the ranks and, for an exact
 * p-value, O(n_x (n_x n_y)) for the counts (with ties O(n_x (2 N n_x))).
 */
#ifndef PORO_MANN_WHITNEY_H
#define PORO_MANN_WHITNEY_H

/* Largest n_x n_y for which the exact distribution is counted (scipy's "auto" uses it below 8
 * per sample; counting is cheap far beyond: 10,000 pairs cost about 10^6 additions). */
#define MW_EXACT_MAX_PRODUCT 10000
/* Largest work N * n_x * 2 N n_x of the exact count with ties (additions; 10^8 take about 0.1 s):
 * 5 samples against 50 cost 1.5 * 10^5, 20 against 200 about 3 * 10^7. */
#define MW_EXACT_TIES_MAX_WORK 1e8

enum mw_alternative { MW_GREATER, MW_LESS, MW_TWO_SIDED };
/* MW_AUTO: exact when it can be (see above), else asymptotic; the others force one. */
enum mw_method { MW_AUTO, MW_EXACT, MW_ASYMPTOTIC };

struct mw_result {
	double u;         /* U of x: pairs with x_i > y_j, ties one half */
	double p;         /* the p-value of the alternative asked for */
	int exact;        /* 1: from the exact distribution; 0: the normal approximation */
};

/* Tests x[nx] against y[ny] (both >= 1, finite values). 0, or -1 for a bad argument, no memory,
 * or MW_EXACT asked for samples beyond its limits. */
int mann_whitney(const double *x, int nx, const double *y, int ny, enum mw_alternative alt, enum mw_method method,
		 struct mw_result *out);

/* The median of v[n] (n >= 1; the mean of the two middle values for even n). v is not changed. */
double mw_median(const double *v, int n);

#endif
