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
	*v = (struct regression_verdict){ .status = REGRESSION_OK, .history_median = NAN, .ratio = NAN,
					  .p_slower = NAN, .p_faster = NAN, .samples = n };
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

int regression_history(const double *samples, int n, const double *history, int m,
		       const struct regression_rule *rule, struct regression_verdict *v)
{
	verdict_init(v, samples, n);
	v->history_samples = m;
	if (!regression_can_detect(n, m, rule->alpha)) {
		v->status = REGRESSION_NO_HISTORY;
		snprintf(v->detail, sizeof v->detail, "%d history samples on this machine: too few for %d samples "
			 "to reach p <= %g; recorded as baseline", m, n, rule->alpha);
		return 0;
	}
	struct mw_result slower, faster;
	if (mann_whitney(samples, n, history, m, MW_GREATER, MW_AUTO, &slower) ||
	    mann_whitney(samples, n, history, m, MW_LESS, MW_AUTO, &faster))
		return -1;
	v->history_median = mw_median(history, m);
	v->ratio = v->history_median > 0 ? v->median / v->history_median : NAN;
	v->p_slower = slower.p;
	v->p_faster = faster.p;
	double change = v->ratio - 1;
	if (slower.p <= rule->alpha && change >= rule->min_effect)
		v->status = REGRESSION_REGRESSED;
	else if (faster.p <= rule->alpha && 1 / v->ratio - 1 >= rule->min_effect)
		v->status = REGRESSION_IMPROVED;
	snprintf(v->detail, sizeof v->detail, "median %.6g vs %.6g (%+.1f%%) over %d history samples; "
		 "rank test p = %.3g slower, %.3g faster (alpha %g, minimum effect %.0f%%)", v->median,
		 v->history_median, 100 * change, m, slower.p, faster.p, rule->alpha, 100 * rule->min_effect);
	return 0;
}
