/*
 * reference_kernel.c - the fixed work of reference_kernel.h. Frozen: see there before changing a
 * line.
 */
#include "reference_kernel.h"

#include <stdint.h>
#include <stdlib.h>
#include <time.h>

enum { POINTS = 1024, GRID = 64, DENSE = 48 };

struct reference_kernel {
	double x[POINTS], y[POINTS], mass[POINTS], vx[POINTS];
	double node_mass[GRID * GRID], node_px[GRID * GRID];
	double a[DENSE * DENSE], b[DENSE * DENSE], c[DENSE * DENSE];
	volatile double sink;   /* keeps the compiler from dropping the work */
};

static double cpu_seconds(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

struct reference_kernel *reference_kernel_create(void)
{
	struct reference_kernel *k = malloc(sizeof *k);
	if (!k)
		return NULL;
	uint32_t state = 7;   /* a linear congruential generator: the same points on every machine */
	for (int p = 0; p < POINTS; p++) {
		state = state * 1664525u + 1013904223u;
		k->x[p] = 2 + (double)(state >> 16) * (59.0 / 65536);
		state = state * 1664525u + 1013904223u;
		k->y[p] = 2 + (double)(state >> 16) * (59.0 / 65536);
		k->mass[p] = 1;
		k->vx[p] = 0.1;
	}
	for (int i = 0; i < DENSE * DENSE; i++) {
		k->a[i] = i % 7;
		k->b[i] = i % 5;
	}
	k->sink = 0;
	return k;
}

/* The three quadratic B-spline weights of a point at fractional offset f from its first node. */
static void weights(double f, double w[3])
{
	w[0] = 0.5 * (1.5 - f) * (1.5 - f);
	w[1] = 0.75 - (f - 1) * (f - 1);
	w[2] = 0.5 * (f - 0.5) * (f - 0.5);
}

/* The work is two halves of about equal time, because the two kinds slow differently on a shared
 * machine (measured: 1.32x and 1.64x in the slow state where the solver's step slowed 1.46x, and
 * their sum 1.47x; docs/benchmarks.md): a scatter of mass and momentum to the grid and a gather
 * back (memory-bound), and a small dense product whose inner loop is a chain of multiply-adds
 * (arithmetic-bound). */
/* Aligned to a cache line, so that its loops sit the same way in every binary: unaligned, the same
 * compiled kernel measured 42.7 us at an address 32 bytes into a line and 53-58 us at one 16 bytes
 * in (two builds of one commit, side by side), so any change elsewhere in the solver that moved it
 * would have moved relative_step_cost by a quarter. */
__attribute__((aligned(64))) double reference_kernel_run(struct reference_kernel *k)
{
	const double t0 = cpu_seconds();
	for (int i = 0; i < GRID * GRID; i++)
		k->node_mass[i] = k->node_px[i] = 0;
	for (int p = 0; p < POINTS; p++) {   /* scatter */
		int bx = (int)(k->x[p] - 0.5), by = (int)(k->y[p] - 0.5);
		double wx[3], wy[3];
		weights(k->x[p] - bx, wx);
		weights(k->y[p] - by, wy);
		for (int a = 0; a < 3; a++)
			for (int b = 0; b < 3; b++) {
				double w = wx[a] * wy[b] * k->mass[p];
				int n = (by + b) * GRID + bx + a;
				k->node_mass[n] += w;
				k->node_px[n] += w * k->vx[p];
			}
	}
	double sum = 0;
	for (int p = 0; p < POINTS; p++) {   /* gather */
		int bx = (int)(k->x[p] - 0.5), by = (int)(k->y[p] - 0.5);
		for (int a = 0; a < 3; a++)
			for (int b = 0; b < 3; b++) {
				int n = (by + b) * GRID + bx + a;
				sum += k->node_px[n] / (k->node_mass[n] + 1);
			}
	}
	for (int i = 0; i < DENSE; i++)   /* dense product */
		for (int j = 0; j < DENSE; j++) {
			double c = 0;
			for (int l = 0; l < DENSE; l++)
				c += k->a[i * DENSE + l] * k->b[l * DENSE + j];
			k->c[i * DENSE + j] = c;
		}
	k->sink = sum + k->c[5];
	return cpu_seconds() - t0;
}

void reference_kernel_destroy(struct reference_kernel *k) { free(k); }
