/*
 * regression.h - how a benchmark figure is judged (docs/benchmarks.md, "Verdicts"):
 *
 *   band     an accuracy figure (an error against a closed form, a paper's number, a run-out)
 *            must lie in its accepted band [min, max]: every sample of the run is checked;
 *   history  a timing figure is compared with the same figure's samples from the same machine's
 *            recent runs by a one-sided Mann-Whitney U test (mann_whitney.h), and counts as
 *            regressed only when the test is significant (p <= alpha) AND the median moved by at
 *            least min_effect of the history's median. The rank test alone would flag a 1%
 *            change given enough samples; the effect size alone would flag one unlucky sample.
 *            Both together keep a noisy shared machine from crying wolf while a 1.5x slowdown
 *            stands out by both measures.
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
/* alpha 0.001, not 0.01: the repeats of one run are taken back to back and share the machine's
 * state, so they are not the independent samples the test assumes and its p-values are
 * optimistic; with 10 runs of 5 repeats the smallest p-value is 1 / C(55, 5) = 3e-7, so the
 * stricter level costs no power against a real slowdown (docs/benchmarks.md, "Verdicts"). */
#define REGRESSION_RULE_DEFAULT { .alpha = 0.001, .min_effect = 0.10, .history_runs = 10 }

/* What a comparison found. */
struct regression_verdict {
	enum regression_status status;
	double median;            /* of the run's samples */
	double history_median;    /* of the history's samples (NAN without history) */
	double ratio;             /* median / history_median (NAN without history) */
	double p_slower, p_faster; /* one-sided p-values of the rank test (NAN when not tested) */
	int samples, history_samples;
	char detail[256];         /* one line saying why, for reports */
};

/* Judges samples[n] against band [lo, hi] (NAN for an open end). n >= 1. */
void regression_band(const double *samples, int n, double lo, double hi, struct regression_verdict *v);

/* Judges samples[n] against history[m] (m may be 0) by rule. n >= 1. 0, or -1 without memory. */
int regression_history(const double *samples, int n, const double *history, int m,
		       const struct regression_rule *rule, struct regression_verdict *v);

/* 1 when the exact rank test of n samples against m can reach p <= alpha at all. */
int regression_can_detect(int n, int m, double alpha);

#endif
