/*
 * reference_kernel.h - a fixed piece of work whose processor time measures how fast the machine is
 * running the solver's kind of work at that moment, so that a step's time can be read in units of
 * it (the figure relative_step_cost, docs/benchmarks.md "A machine with two speeds").
 *
 * Why: on a shared VM the same job's median step has been measured at two levels 1.5-1.6x apart,
 * the level a property of the virtual processor the process ran on at the time (taskset -c 0 slow
 * while -c 1 was not, for tens of seconds to minutes), and no statistic over processor times alone
 * can tell such a level from a slower solver. Timed in the same process between the steps, this
 * kernel slows with the machine and not with the solver.
 *
 * The work is what an MPM step spends its time on, at a size that stays in the caches: quadratic
 * B-spline weights of 1024 points scattered with their mass and momentum to a 64 x 64 grid and
 * gathered back, and a 48 x 48 dense product (reference_kernel.c says why both). It shares no code
 * with the solver, on purpose: a change to the solver must not change it. It must never change
 * either, since every stored history of relative_step_cost is in its units: a new kernel is a new
 * figure name.
 */
#ifndef PORO_REFERENCE_KERNEL_H
#define PORO_REFERENCE_KERNEL_H

struct reference_kernel;

/* The kernel's points and grid, always filled the same way; NULL without memory. */
struct reference_kernel *reference_kernel_create(void);
/* Runs it once (about 45 microseconds on the 2-core EPYC VM of docs/benchmarks.md); its
 * processor time (CLOCK_PROCESS_CPUTIME_ID), s. It reads the clock itself, inside its own
 * translation unit, rather than the caller timing it with run.c's clock: moving the two clock reads
 * out made the same work measure 57 us instead of 43 on the same machine (the compiled kernel
 * changed), which would have changed the figure's units. */
double reference_kernel_run(struct reference_kernel *k);
void reference_kernel_destroy(struct reference_kernel *k);

#endif
