/*
 * mann_whitney.c - the Mann-Whitney U test, see mann_whitney.h.
 *
 * Exact null distribution: with m values of x and n of y and no ties, the number of orderings
 * giving U = u obeys f(m, n, u) = f(m - 1, n, u - n) + f(m, n - 1, u) (the largest value is an
 * x, beating all n y's, or a y, beating none), f(0, n, 0) = f(m, 0, 0) = 1. The table f(., n, .)
 * is built for n = 0, 1, ..., n_y in place, one row per m <= n_x; the counts are doubles, which
 * hold C(m + n, m) with 15 significant digits (p-values relative to 1e-15).
 *
 * With ties the exact distribution is the rank sum's over every choice of which n_x of the pooled
 * values are x, each value keeping its mid-rank (exact_tied_tails; doubled, the ranks are
 * integers).
 */
#include "mann_whitney.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

struct ranked {
	double v;
	int from_x;
};

static int by_value(const void *a, const void *b)
{
	double x = ((const struct ranked *)a)->v, y = ((const struct ranked *)b)->v;
	return (x > y) - (x < y);
}

double mw_median(const double *v, int n)
{
	double *s = malloc(sizeof *s * (size_t)n);
	if (!s)
		return NAN;
	memcpy(s, v, sizeof *s * (size_t)n);
	for (int i = 1; i < n; i++)   /* insertion sort: samples are small */
		for (int j = i; j > 0 && s[j - 1] > s[j]; j--) {
			double t = s[j];
			s[j] = s[j - 1];
			s[j - 1] = t;
		}
	double m = n % 2 ? s[n / 2] : 0.5 * (s[n / 2 - 1] + s[n / 2]);
	free(s);
	return m;
}

/* The two tails P(X >= obs), P(X <= obs) of counts dist[0..max] of the values 0..max. */
static void tails(const double *dist, long max, long obs, double *upper, double *lower)
{
	double total = 0, up = 0, low = 0;
	for (long v = 0; v <= max; v++) {
		total += dist[v];
		if (v >= obs)
			up += dist[v];
		if (v <= obs)
			low += dist[v];
	}
	*upper = up / total;
	*lower = low / total;
}

/* P(U >= u) and P(U <= u) from the exact distribution for sizes m, n (no ties). u is a whole
 * number here. -1 without memory. */
static int exact_tails(int m, int n, double u, double *upper, double *lower)
{
	int umax = m * n;
	/* row k holds f(k, j, .) for the current j; rows are updated for j = 1..n */
	double *f = calloc((size_t)(m + 1) * (size_t)(umax + 1), sizeof *f);
	if (!f)
		return -1;
	for (int k = 0; k <= m; k++)
		f[(size_t)k * (size_t)(umax + 1)] = 1;   /* j = 0: U = 0 only */
	for (int j = 1; j <= n; j++)
		for (int k = 1; k <= m; k++) {
			/* f(k, j, u) = f(k - 1, j, u - j) + f(k, j - 1, u): row k still holds j - 1, row
			 * k - 1 already holds j (row 0 is the same for every j) */
			double *row = f + (size_t)k * (size_t)(umax + 1), *prev = row - (umax + 1);
			for (int v = umax; v >= j; v--)
				row[v] += prev[v - j];
		}
	tails(f + (size_t)m * (size_t)(umax + 1), umax, lround(u), upper, lower);
	free(f);
	return 0;
}

/* P(W >= w) and P(W <= w) for W the sum of nx of the N doubled mid-ranks w2[] chosen at random:
 * the permutation distribution of the rank sum given the ties (each of the C(N, nx) choices
 * equally likely). g[k][s] counts the choices of k of the items seen so far with sum s, items
 * added one at a time with k descending (each item is chosen at most once). Sums of counts only,
 * as above. -1 without memory. */
static int exact_tied_tails(const int *w2, int N, int nx, long w_obs, double *upper, double *lower)
{
	long smax = 0;
	for (int i = N - nx; i < N; i++)   /* w2 ascends: the largest nx */
		smax += w2[i];
	size_t width = (size_t)smax + 1;
	double *g = calloc((size_t)(nx + 1) * width, sizeof *g);
	if (!g)
		return -1;
	g[0] = 1;
	for (int i = 0; i < N; i++)
		for (int k = nx < i + 1 ? nx : i + 1; k >= 1; k--) {
			double *row = g + (size_t)k * width, *prev = row - width;
			for (long v = smax; v >= w2[i]; v--)
				row[v] += prev[v - w2[i]];
		}
	tails(g + (size_t)nx * width, smax, w_obs, upper, lower);
	free(g);
	return 0;
}

/* The standard normal's upper tail P(Z >= z). */
static double normal_upper(double z)
{
	return 0.5 * erfc(z / sqrt(2.0));
}

int mann_whitney(const double *x, int nx, const double *y, int ny, enum mw_alternative alt, enum mw_method method,
		 struct mw_result *out)
{
	if (!x || !y || nx < 1 || ny < 1 || !out)
		return -1;
	int N = nx + ny;
	struct ranked *r = malloc(sizeof *r * (size_t)N);
	if (!r)
		return -1;
	for (int i = 0; i < nx; i++)
		r[i] = (struct ranked){ x[i], 1 };
	for (int j = 0; j < ny; j++)
		r[nx + j] = (struct ranked){ y[j], 0 };
	qsort(r, (size_t)N, sizeof *r, by_value);
	int *w2 = malloc(sizeof *w2 * (size_t)N);   /* doubled mid-ranks, ascending */
	if (!w2) {
		free(r);
		return -1;
	}
	double rank_x = 0, tie_sum = 0;
	long w2_x = 0;
	int ties = 0;
	for (int i = 0; i < N;) {
		int j = i;
		while (j + 1 < N && r[j + 1].v == r[i].v)
			j++;
		double mid = 0.5 * ((i + 1) + (j + 1));   /* ranks from 1 */
		double t = j - i + 1;
		if (t > 1) {
			ties = 1;
			tie_sum += t * t * t - t;
		}
		for (int k = i; k <= j; k++) {
			w2[k] = (i + 1) + (j + 1);
			if (r[k].from_x)
				rank_x += mid, w2_x += w2[k];
		}
		i = j + 1;
	}
	free(r);
	double u = rank_x - 0.5 * nx * (nx + 1.0);
	double upper, lower;
	out->u = u;
	/* the tied count's work: N items times nx rows times the sums (at most 2 N nx) */
	int exact_possible = ties ? (double)N * nx * 2.0 * N * nx <= MW_EXACT_TIES_MAX_WORK
				  : (long)nx * ny <= MW_EXACT_MAX_PRODUCT;
	if (method == MW_EXACT && !exact_possible) {
		free(w2);
		return -1;
	}
	out->exact = method == MW_EXACT || (method == MW_AUTO && exact_possible);
	int rc = 0;
	if (out->exact)
		rc = ties ? exact_tied_tails(w2, N, nx, w2_x, &upper, &lower) : exact_tails(nx, ny, u, &upper, &lower);
	free(w2);
	if (rc)
		return -1;
	if (!out->exact) {
		double mu = 0.5 * nx * ny;
		double var = nx * (double)ny / 12.0 * ((N + 1.0) - tie_sum / ((double)N * (N - 1.0)));
		double sd = var > 0 ? sqrt(var) : 0;
		if (sd == 0) {                    /* every value equal: no evidence either way */
			upper = lower = 1;
		} else {
			upper = normal_upper((u - mu - 0.5) / sd);
			lower = normal_upper((mu - u - 0.5) / sd);
		}
	}
	if (alt == MW_GREATER)
		out->p = upper;
	else if (alt == MW_LESS)
		out->p = lower;
	else
		out->p = fmin(1.0, 2 * fmin(upper, lower));
	return 0;
}
