/*
 * step_health.h - what a step's outcome says about its cause (private to sim.c).
 *
 * A failed step reports its symptom (an inverted point, a non-finite stress, a return that found
 * no solution); step_health_explain adds the likely cause: the step's dt against the scheme's CFL
 * step (stable_dt.h), the strain the loads alone give the skeleton when it is large, and the
 * run's warning if it raised one. step_health_watch keeps the run's warning: a small-strain model at a volume change beyond
 * STEP_HEALTH_SMALL_STRAIN_LIMIT, where its stress no longer describes the soil.
 */
#ifndef PORO_STEP_HEALTH_H
#define PORO_STEP_HEALTH_H

#include "sim_internal.h"

/* |J - 1| above which a small-strain model is warned about: 10% volumetric strain. The Xie-Leo
 * column (000 §5.2) reaches 18% and its small-strain run settles 17% more than the finite-strain
 * one; at the Terzaghi column's 0.1% the two agree to 0.05%. */
#define STEP_HEALTH_SMALL_STRAIN_LIMIT 0.1

/* dt / (h / c_p) above which a failed step names the time step as its likely cause: the lowest
 * limit measured on the Terzaghi column is 0.87 h / c_p (drag in the correction, k = 1e-9 m/s). */
#define STEP_HEALTH_DT_SUSPECT 0.8
/* The explicit scheme's: dt over its critical step (stable_dt.h) above which the time step is named. */
#define STEP_HEALTH_EXPLICIT_DT_SUSPECT 0.8

/* The largest elastic strain the case's loads and gravity alone give a body: (the peak traction on
 * it + its effective weight, buoyant or dry, over its height) / its constrained modulus; *body its
 * index (-1: none). An estimate from the parameters alone, for naming a material too soft for its load. */
double step_health_load_strain(const struct case_spec *c, int *body);

/* Appends the likely cause to s->err after a failed step. */
void step_health_explain(struct sim *s);

/* After a step: records the run's first small-strain warning in s->warning. */
void step_health_watch(struct sim *s);

#endif
