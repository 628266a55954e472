/*
 * sim_internal.h - the simulation object shared by the solver's internal files (not public).
 *
 * struct sim owns the grid, the point sets, the materials and every scratch array a step uses;
 * all are allocated in sim_create() (STYLE rule 3). Phase functions of the schemes take a
 * struct sim * and loop over points or nodes.
 */
#ifndef PORO_SIM_INTERNAL_H
#define PORO_SIM_INTERNAL_H

#include "grid.h"
#include "material.h"
#include "permeability.h"
#include "poro.h"
#include "stable_dt.h"
#include "step_timing.h"

/* Returns from the calling function with a phase's status unless it is PORO_OK. */
#define TRY(call)                                       \
	do {                                            \
		enum poro_status st_ = (call);          \
		if (st_ != PORO_OK)                     \
			return st_;                     \
	} while (0)

struct sim {
	const struct case_spec *spec;
	struct grid grid;
	struct grid_fields f;
	struct particles soil, water;
	int double_point;
	idx_t saturated_soil;         /* the first this many soil points belong to saturated bodies, the
					 rest to dry ones ("saturated": false; sim.c seeds them so) */
	struct material *materials;   /* [case material_count] */
	const struct scheme *scheme;  /* formulation.scheme's step (scheme.h) */
	void *scheme_state;           /* the scheme's own state, which its create allocates */
	double dt, time;
	long step, steps_total;
	double rho_w;                 /* fluid density, kg/m^3 */
	double gravity[2];            /* body force b^{t+1} of the current step, m/s^2 */
	struct stable_dt stable;      /* the scheme's CFL step for this case (stable_dt.h) */
	char warning[512];            /* the run's first warning (step_health.c), "" if none */

	/* per-point scratch, sized at create */
	double *soil_grad;            /* [4 n_soil] velocity or displacement gradient */
	double *soil_scalar;          /* [n_soil] */
	double *soil_coef;            /* [n_soil] */
	double *water_scalar;         /* [n_water] */
	double *water_coef;           /* [n_water] */
	struct load_band *load_bands; /* [load_count] how each traction is integrated (loads.c) */

	/* Patches of the modified F-bar (000 Eq. 83): a fixed tiling of the grid into
	 * patches[0] x patches[1] rectangles of patch_width (about h_patch; see semi_implicit.c) */
	idx_t patches[2];
	double patch_width[2];        /* m */
	double *patch_mass;           /* [cell_count >= patch count] sum of m_sp over the patch, kg/m */
	double *patch_mass_Je;        /* [cell_count] sum of m_sp J^e over the patch */

	double mapped_mass_s, mapped_mass_w; /* point mass sums mapped in the last P2G, kg/m */
	double water_outflow_mass;    /* kg/m of water points that left through drained faces */
	double phase_seconds[PHASE_COUNT]; /* wall time per phase, accumulated over steps */
	int *probe_point;             /* [probe_count] tracked point of point probes, -1 otherwise */
	int resumed;                  /* 1: the state was loaded from a checkpoint (checkpoint.c) */
	double checkpoint_wall;       /* s of wall time between checkpoints in sim_run; 0 = none */
	struct sim_timing timing;     /* the steps sim_run took in this process (run.c) */
	struct step_histogram step_cpu; /* their processor times (step_timing.h), allocated by sim_run */
	double slowdown;              /* test knob of sim_set_slowdown (run.c); 1 = off */
	struct reference_kernel *reference;  /* timed after each step when asked (run.c), else NULL */
	struct step_histogram reference_cpu; /* its processor times */
	struct poro_error err;
};

/* Monotonic wall clock, s; phases time themselves with it. */
double sim_clock(void);

/* boundary.c: velocity constraints of the grid faces (000 §4.5 steps 3e, 4d, 6d). */
void boundary_mark(struct sim *s);
void boundary_apply(const struct grid *g, const unsigned char *fix, double *v);

/* loads.c: tractions on body faces (000 Eq. 54) and gravity with its ramp. */
struct load_band {
	int through_points;           /* 1: integrated through the body's points; 0: at the point faces */
	int axis;                     /* the face's normal: 0 = x (left, right), 1 = y (bottom, top) */
	double sign;                  /* +1 for an upper face (right, top), -1 for a lower one */
	double face, depth;           /* reference coordinate of the face along axis, and the body's
				         bounding-box thickness along it, m */
	double along[2];              /* reference extent along the face of the loaded points' strips, m */
};
void loads_init(struct sim *s);
void loads_add_tractions(struct sim *s, double time, double *force);
void loads_gravity(const struct case_spec *c, double time, double b[2]);
/* 1 while the step being taken ends within the gravity ramp: the initialisation of 000 App. B.4
 * and §5.4, during which gravity.elastic_loading, loading_conductivity and water_attached act. */
int loads_in_gravity_ramp(const struct sim *s);
/* 000 App. B.4 with gravity.elastic_loading: 1 for a step that ends within the gravity ramp (it is
 * elastic); 2 for the first step after it, which first makes each point's present state, the one
 * at the end of the ramp, its reference (material_reset_reference: p0, eps_v0^e, the image
 * pressure from OCR); 0 otherwise and without elastic loading. */
int loads_gravity_loading_stage(const struct sim *s);

/* probes.c */
void probes_init(struct sim *s);

#endif
