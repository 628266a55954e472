/*
 * regression.c - verdicts of benchmark figures, see regression.h.
 */
#include "regression.h"

#include <math.h>
#include <stdio.h>

#include "mann_whitney.h"

static const char *const NAMES[] = {
#define REGRESSION_NAME(code, name) name,
	REGRESSION_STATUS_MAP(REGRESSION_NAME)
#undef REGRESSION_NAME
};

const char *regression_status_name(enum regression_status s)
{
	return s < REGRESSION_STATUS_COUNT ? NAMES[s] : "unknown";
}

static void verdict_init(struct regression_verdict *v, const double *samples, int n)
{
	*v = (struct regression_verdict){ .status = REGRESSION_OK,
					  .history_median = NAN,
					  .history_min = NAN,
					  .history_max = NAN,
					  .ratio = NAN,
					  .p_slower = NAN,
					  .p_faster = NAN,
					  .p_exceed_slower = NAN,
					  .p_exceed_faster = NAN,
					  .samples = n };
	v->median = mw_median(samples, n);
}

void regression_band(const double *samples, int n, double lo, double hi, struct regression_verdict *v)
{
	verdict_init(v, samples, n);
	for (int i = 0; i < n; i++) {
		double s = samples[i];
		if (!isfinite(s) || (!isnan(lo) && s < lo) || (!isnan(hi) && s > hi)) {
			v->status = REGRESSION_REGRESSED;
			snprintf(v->detail, sizeof v->detail, "%.6g is outside its band [%.6g, %.6g]", s, lo, hi);
			return;
		}
	}
	snprintf(v->detail, sizeof v->detail, "%.6g within its band [%.6g, %.6g]", v->median, lo, hi);
}

int regression_can_detect(int n, int m, double alpha)
{
	/* the exact test's smallest one-sided p-value is 1 / C(n + m, n) */
	double c = 1;
	for (int k = 1; k <= n; k++)
		c = c * (m + k) / k;
	return m > 0 && 1.0 / c <= alpha;
}

double regression_exceedance_p(const double *x, int n, const double *y, int m, int slower)
{
	double edge = y[0];
	for (int j = 1; j < m; j++)
		edge = slower ? fmax(edge, y[j]) : fmin(edge, y[j]);
	int k = 0;
	for (int i = 0; i < n; i++)
		k += slower ? x[i] > edge : x[i] < edge;
	double p = 1; /* C(n, k) / C(n + m, k) as a product of k ratios */
	for (int i = 0; i < k; i++)
		p *= (double)(n - i) / (double)(n + m - i);
	return p;
}

int regression_history(const double *samples, int n, const double *history, int m,
		       const struct regression_rule *rule, struct regression_verdict *v)
{
	verdict_init(v, samples, n);
	v->history_samples = m;
	const double alpha = rule->alpha / 2; /* each of the two rank tests (Bonferroni) */
	if (!regression_can_detect(n, m, alpha)) {
		v->status = REGRESSION_NO_HISTORY;
		snprintf(v->detail, sizeof v->detail,
			 "%d history samples on this machine: too few for %d samples "
			 "to reach p <= %g; recorded as baseline",
			 m, n, alpha);
		return 0;
	}
	struct mw_result slower, faster;
	if (mann_whitney(samples, n, history, m, MW_GREATER, MW_AUTO, &slower) ||
	    mann_whitney(samples, n, history, m, MW_LESS, MW_AUTO, &faster))
		return -1;
	v->history_median = mw_median(history, m);
	v->history_min = v->history_max = history[0];
	for (int j = 1; j < m; j++) {
		v->history_min = fmin(v->history_min, history[j]);
		v->history_max = fmax(v->history_max, history[j]);
	}
	v->ratio = v->history_median > 0 ? v->median / v->history_median : NAN;
	v->p_slower = slower.p;
	v->p_faster = faster.p;
	v->p_exceed_slower = regression_exceedance_p(samples, n, history, m, 1);
	v->p_exceed_faster = regression_exceedance_p(samples, n, history, m, 0);
	const double grow = 1 + rule->min_effect;
	int slower_significant = slower.p <= alpha || v->p_exceed_slower <= alpha;
	int faster_significant = faster.p <= alpha || v->p_exceed_faster <= alpha;
	if (slower_significant && v->median >= grow * v->history_max)
		v->status = REGRESSION_REGRESSED;
	else if (faster_significant && v->median * grow <= v->history_min)
		v->status = REGRESSION_IMPROVED;
	snprintf(v->detail, sizeof v->detail,
		 "median %.6g vs %.6g (%+.1f%%), range [%.6g, %.6g] over %d history "
		 "samples; rank test p = %.3g slower, %.3g faster; exceedance p = %.3g slower, %.3g faster (each at "
		 "alpha %g; minimum effect %.0f%% beyond the range)",
		 v->median, v->history_median, 100 * (v->ratio - 1), v->history_min, v->history_max, m, slower.p,
		 faster.p, v->p_exceed_slower, v->p_exceed_faster, alpha, 100 * rule->min_effect);
	return 0;
}
