/*
 * regression.h - how a benchmark figure is judged (docs/benchmarks.md, "Verdicts"):
 *
 *   band     an accuracy figure (an error against a closed form, a paper's number, a run-out)
 *            must lie in its accepted band [min, max]: every sample of the run is checked;
 *   history  a timing figure is compared with the same figure's samples from the same machine's
 *            recent runs, and counts as regressed only when
 *            - significance: a one-sided rank test says so, the Mann-Whitney U test
 *              (mann_whitney.h) or the exceedance test (regression_exceedance_p), each at
 *              alpha / 2 (Bonferroni: the two together keep the level alpha); and
 *            - size: the run's median lies beyond everything the machine showed in that history
 *              (its slowest sample) by at least min_effect.
 *            The rank tests alone would flag a 1% change given enough samples. The size is taken
 *            from the history's range, not its median, because the repeats of one run share the
 *            machine's state and a shared VM has states of its own: identical jobs were measured
 *            in two levels 1.6x apart, a run landing wholly in either (docs/benchmarks.md, "A
 *            machine with two speeds"). A run inside the machine's own range is no evidence of a
 *            change, however its ranks fall; a slowdown that moves every state lands beyond it.
 *            The exceedance test is the one a mixture leaves its power: a slowed run with two of
 *            five repeats in the fast state has an ordinary rank sum, yet its other three lie
 *            above every earlier sample.
 *            Improved is the mirror image (below the fastest sample by min_effect).
 *
 * A history too small for the test to ever reach alpha with the run's samples (the exact test's
 * smallest p-value is 1 / C(n + m, n)) gives REGRESSION_NO_HISTORY: the run is recorded as part
 * of the baseline, not judged.
 */
#ifndef PORO_REGRESSION_H
#define PORO_REGRESSION_H

/* Verdict names are the API's (schemas/openapi.yaml, BenchmarkFigure.status). */
#define REGRESSION_STATUS_MAP(X)                                                         \
	X(REGRESSION_OK, "ok")                    /* within its band, or no change */    \
	X(REGRESSION_REGRESSED, "regressed")      /* outside its band, or slower */      \
	X(REGRESSION_IMPROVED, "improved")        /* faster, by both measures */         \
	X(REGRESSION_NO_HISTORY, "no_history")    /* timing: too little history yet */   \
	X(REGRESSION_RECORDED, "recorded")        /* kept, judged by nothing */          \
	X(REGRESSION_FAILED, "failed")            /* its job ran and failed, or gave no value */ \
	X(REGRESSION_DID_NOT_RUN, "did_not_run")  /* its job was refused, cancelled or lost */

enum regression_status {
#define REGRESSION_ENUM(code, name) code,
	REGRESSION_STATUS_MAP(REGRESSION_ENUM)
#undef REGRESSION_ENUM
	REGRESSION_STATUS_COUNT
};

const char *regression_status_name(enum regression_status s);

/* The settings of the history comparison; a suite may override each (schemas/suite.schema.json). */
struct regression_rule {
	double alpha;         /* p-value at or below which the rank test counts */
	double min_effect;    /* relative change of the median that counts, e.g. 0.10 */
	int history_runs;     /* how many of the machine's latest runs form the history */
};
/* alpha 0.001 (0.0005 for each of the two tests), not 0.01: the repeats of one run are taken
 * back to back and share the machine's state, so they are not the independent samples the tests
 * assume and their p-values are optimistic; with 10 runs of 5 repeats the smallest p-value is
 * 1 / C(55, 5) = 3e-7, so the stricter level costs no power against a real slowdown
 * (docs/benchmarks.md, "Verdicts"). */
#define REGRESSION_RULE_DEFAULT { .alpha = 0.001, .min_effect = 0.10, .history_runs = 10 }

/* What a comparison found. */
struct regression_verdict {
	enum regression_status status;
	double median;            /* of the run's samples */
	double history_median;    /* of the history's samples (NAN without history) */
	double history_min, history_max; /* the machine's range in that history (NAN without) */
	double ratio;             /* median / history_median (NAN without history) */
	double p_slower, p_faster; /* one-sided p-values of the rank test (NAN when not tested) */
	double p_exceed_slower, p_exceed_faster; /* of the exceedance test (NAN when not tested) */
	int samples, history_samples;
	char detail[384]; /* one line saying why, for reports */
};

/* Judges samples[n] against band [lo, hi] (NAN for an open end). n >= 1. */
void regression_band(const double *samples, int n, double lo, double hi, struct regression_verdict *v);

/* Judges samples[n] against history[m] (m may be 0) by rule. n >= 1. 0, or -1 without memory. */
int regression_history(const double *samples, int n, const double *history, int m,
		       const struct regression_rule *rule, struct regression_verdict *v);

/* 1 when the exact rank test of n samples against m can reach p <= alpha at all (the exceedance
 * test's smallest p-value, all n above all m, is the same 1 / C(n + m, n)). */
int regression_can_detect(int n, int m, double alpha);

/* The exceedance test (Rosenbaum 1954): k of the run's samples x[n] lie strictly above
 * (slower = 1) or below (0) every history sample y[m]. When the n + m values are exchangeable
 * (no change), the k extreme ones are a uniformly random k-subset, all from x with probability
 * C(n, k) / C(n + m, k): the p-value returned (1 when k = 0). With ties the strict count can only
 * be smaller, so the p-value is conservative. m >= 1. */
double regression_exceedance_p(const double *x, int n, const double *y, int m, int slower);

#endif
