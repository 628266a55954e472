/*
 * step_timing.c - a histogram of step times in logarithmic bins, see step_timing.h. Bin k holds
 * times in [MIN r^k, MIN r^(k+1)), r = STEP_TIMING_RATIO.
 */
#include "step_timing.h"

#include <math.h>
#include <stdlib.h>

int step_histogram_init(struct step_histogram *h)
{
	h->total = 0;
	h->count = calloc(STEP_TIMING_BINS, sizeof *h->count);
	return h->count ? 0 : -1;
}

void step_histogram_add(struct step_histogram *h, double seconds)
{
	if (!h->count)
		return;
	double k = seconds > STEP_TIMING_MIN ? floor(log(seconds / STEP_TIMING_MIN) / log(STEP_TIMING_RATIO)) : 0;
	h->count[k < STEP_TIMING_BINS - 1 ? (long)k : STEP_TIMING_BINS - 1]++;
	h->total++;
}

double step_histogram_median(const struct step_histogram *h)
{
	if (!h->count || h->total == 0)
		return NAN;
	long half = (h->total + 1) / 2, seen = 0;
	for (long k = 0; k < STEP_TIMING_BINS; k++)
		if ((seen += h->count[k]) >= half)
			return STEP_TIMING_MIN * pow(STEP_TIMING_RATIO, (double)k + 0.5);
	return NAN;
}

void step_histogram_release(struct step_histogram *h)
{
	free(h->count);
	h->count = NULL;
	h->total = 0;
}
