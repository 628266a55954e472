/*
 * scheme.h - the time-integration schemes behind one interface, chosen by formulation.scheme.
 *
 * A scheme is a folder of its own under schemes/ with one step that reads as its paper's
 * algorithm over the shared phases of mpm/phases.h (maps, point motion, deformation, stress,
 * loads, boundaries); what it adds (its equations, its nodal fields and workspaces) lives in its
 * own struct, which create allocates into s->scheme_state and destroy frees.
 *
 * Between steps a scheme's state lives on the points (struct particles), which checkpoint.c saves
 * whole; what a scheme allocates is rebuilt from the points every step, so a resumed run needs no
 * more than the points. A scheme that carries nodal state between steps would add it to the
 * checkpoint here.
 *
 * The stable time step of a case is the scheme's too: stable_dt_estimate (stable_dt.h) dispatches
 * on the same formulation.scheme, since the loader checks it before any simulation is built.
 */
#ifndef PORO_SCHEME_H
#define PORO_SCHEME_H

#include "sim_internal.h"

/* Runs one phase of a step and adds its wall time to the phase's account (poro.h, enum sim_phase). */
#define PHASE(which, call)                                              \
	do {                                                            \
		double t0_ = sim_clock();                               \
		call;                                                   \
		s->phase_seconds[which] += sim_clock() - t0_;           \
	} while (0)

struct scheme {
	const char *name;                              /* formulation.scheme */
	/* What each of the step's phase slots (poro.h, enum sim_phase) times in this scheme; NULL
	 * for a slot the scheme does not use. */
	const char *phase_names[PHASE_COUNT];
	/* Builds the scheme's state once the grid, points, materials, boundaries and loads exist. */
	enum poro_status (*create)(struct sim *s);
	void (*destroy)(struct sim *s);                /* frees s->scheme_state; NULL state is fine */
	/* One step from s->time to s->time + dt; advances s->time and s->step, or fails with s->err
	 * naming what and where. */
	enum poro_status (*step)(struct sim *s);
	/* A scheme that iterates within a step reports its iterations (poro.h, sim_iterations);
	 * NULL for one that does not. */
	int (*iterations)(const struct sim *s, int *last, long *total, const double **energies, int *count);
	/* A scheme with a sparse direct solver reports its work (poro.h, sim_linear_solver_counts). */
	int (*solver_counts)(const struct sim *s, long *analyses, long *factorisations, long *solves,
			     long *factor_nonzeros);
};

/* The scheme a case asks for. */
const struct scheme *scheme_of(enum case_scheme kind);

extern const struct scheme semi_implicit_scheme, explicit_scheme, implicit_upU_scheme;

#endif
