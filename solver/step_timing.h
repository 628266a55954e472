/*
 * step_timing.h - the distribution of the steps' processor times, kept as a histogram of
 * logarithmic bins so that a run of any length costs the same few kilobytes, and its median read
 * back to within half a bin (STEP_TIMING_RATIO: 0.25%).
 *
 * Why a median: on a shared machine a step that follows a context switch finds its caches cold
 * and costs more processor time than the steps after it; the total of the steps' processor time
 * carries those costs and grew by up to 20% with the machine's load (docs/benchmarks.md, "Which
 * clock"), while the median step is the cost of a step that ran on warm caches, which the load
 * leaves alone and a slower solver does not.
 */
#ifndef PORO_STEP_TIMING_H
#define PORO_STEP_TIMING_H

#define STEP_TIMING_MIN 1e-9        /* s: shorter steps fall in the first bin */
#define STEP_TIMING_RATIO 1.005     /* width of a bin: its upper edge over its lower */
#define STEP_TIMING_BINS 5545       /* up to about 1e-9 * 1.005^5545 = 1e3 s; longer in the last */

struct step_histogram {
	unsigned *count;            /* [STEP_TIMING_BINS], NULL until step_histogram_init */
	long total;                 /* steps added */
};

/* Allocates the bins (zero); 0, or -1 without memory. */
int step_histogram_init(struct step_histogram *h);
void step_histogram_add(struct step_histogram *h, double seconds);
/* The median of the times added, s (the geometric centre of its bin); NAN when none was. */
double step_histogram_median(const struct step_histogram *h);
void step_histogram_release(struct step_histogram *h);

#endif
