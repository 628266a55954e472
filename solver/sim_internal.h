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
#include "poro.h"
#include "spd_solve.h"
#include "stable_dt.h"

/* Returns from the calling function with a phase's status unless it is PORO_OK. */
#define TRY(call)                                       \
	do {                                            \
		enum poro_status st_ = (call);          \
		if (st_ != PORO_OK)                     \
			return st_;                     \
	} while (0)

/* Standard gravity in the drag term n^2 rho_w g / k (000 Eq. 15): hydraulic conductivity is
 * defined with it, so it stays 9.81 m/s^2 even when a case switches the body force off. */
#define CONDUCTIVITY_GRAVITY 9.81

/* The pressure Poisson system (000 Eqs. 60-61) on a fixed (2S-1)^2 node stencil. */
struct pressure_system {
	int exact;                /* 1: projection matrix G^T M^-1 G; 0: Laplacian of Eq. 61 */
	int radius;               /* coupling reach of the matrix in nodes: S - 1 (Eq. 61) or 2 (S - 1) */
	int width;                /* 2 radius + 1 */
	int g_radius, g_width;    /* reach of the gradient operators G: S - 1, and 2 g_radius + 1 */
	double *stencil;          /* [node_count * width^2] matrix entries by offset of J from I */
	double *grad_s, *grad_w;  /* [node_count * g_width^2 * 2] G_s, G_w (Eqs. 67-68) by offset;
				     this and the coupling, diagonal and interior: consistent projection
				     only (NULL with the Laplacian) */
	double *coupling;         /* [node_count * 2 * 3] K^-1 (ss, sw, ww) of each node and component,
				     the correction's phase coupling */
	idx_t *unknown;           /* [node_count] unknown number of a node, -1 if not an unknown */
	idx_t *colptr, *rowidx;   /* CSC upper triangle of the reduced system */
	double *values, *b, *x;
	double *diagonal;         /* [node_count] A's diagonal before the pressure stabilisation */
	double *samples;          /* [2 sample_max] x, y of the interpolated or weak free-surface
				     condition's surface points (free_surface.c), m; NULL with the nodal
				     condition */
	double *sample_normal;    /* [2 sample_max] outward normal of each surface point's face times
				     the point's share of the face's length, m (weak condition) */
	idx_t sample_count, sample_max;
	signed char *interior;    /* [node_count] 1: the stabilisation may act on the node */
	struct spd_solver *solver;
};

struct sim {
	const struct case_spec *spec;
	struct grid grid;
	struct grid_fields f;
	struct particles soil, water;
	int double_point;
	struct material *materials;   /* [case material_count] */
	struct pressure_system ps;
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
	double *cell_fill;            /* [cell_count] volume of pressure-carrying points per cell, m^3/m */
	double *cell_fill_soil;       /* [cell_count] volume of soil points per cell (double point), m^3/m */
	struct load_band *load_bands; /* [load_count] how each traction is integrated (loads.c) */

	/* Patches of the modified F-bar (000 Eq. 83): a fixed tiling of the grid into
	 * patches[0] x patches[1] rectangles of patch_width (about h_patch; see semi_implicit.c) */
	idx_t patches[2];
	double patch_width[2];        /* m */
	double *patch_mass;           /* [cell_count >= patch count] sum of m_sp over the patch, kg/m */
	double *patch_mass_Je;        /* [cell_count] sum of m_sp J^e over the patch */

	double mapped_mass_s, mapped_mass_w; /* point mass sums mapped in the last P2G, kg/m */
	double water_outflow_mass;    /* kg/m of water points that left through drained faces */
	double plate_velocity[FACE_COUNT]; /* normal velocity of each face's rigid plate this step, m/s,
					      along the grid axis (plate.c; 0 on faces without one) */
	double *plate_work;           /* [(FACE_COUNT + 2) node_count] the plates' pressure responses and
					 reduced right-hand side and solution (plate.c); NULL without plates */
	double phase_seconds[PHASE_COUNT]; /* wall time per phase, accumulated over steps */
	int *probe_point;             /* [probe_count] tracked point of point probes, -1 otherwise */
	int resumed;                  /* 1: the state was loaded from a checkpoint (checkpoint.c) */
	double checkpoint_wall;       /* s of wall time between checkpoints in sim_run; 0 = none */
	struct poro_error err;
};

/* Monotonic wall clock, s; phases time themselves with it. */
double sim_clock(void);

/* semi_implicit.c: one step of 000 §4.5. */
enum poro_status semi_implicit_step(struct sim *s);

/* pressure.c: the Poisson solve (000 §4.5 step 5). */
/* surface_points: room for the interpolated free-surface condition's points (free_surface.c). */
enum poro_status pressure_system_init(struct pressure_system *ps, const struct grid *g, int support,
				      enum pressure_projection projection, int surface_points, struct poro_error *err);
void pressure_system_release(struct pressure_system *ps);
enum poro_status pressure_solve(struct sim *s);
/* Adds the case's pressure stabilisation, and the weak free-surface condition's penalty on its
 * ghost nodes, to the assembled consistent projection (stencil and right-hand side); a ghost node
 * that no penalty line reaches is held at zero (f->dirichlet). pressure_stabilisation.c. */
void pressure_stabilise(struct sim *s);
/* Adds the storage of the water points at or beyond fluid.cavitation_pressure to the assembled
 * pressure matrix's diagonal (either projection); nothing without cavitation. cavitation.c. */
void cavitation_add_storage(struct sim *s);
/* G_s and G_w of the consistent projection into ps->grad_s, ps->grad_w (Eqs. 67-68 with the nodal
 * porosity factors; with the weak free-surface condition, its surface term from the surface points
 * free_surface_mark placed). */
void pressure_gradient_operators(struct sim *s);
void pressure_apply_gradient(const struct sim *s, const double *G, const double *pressure, double *out);

/* f->surface: SURFACE_ON, a node on the surface (interpolated condition: it takes the condition
 * instead of p = 0; weak: next to full and dry cells); SURFACE_GHOST, weak condition, a node beyond
 * the surface that points of full cells reach; SURFACE_GHOST_TIED, such a node that a penalty
 * line ties to the field inside (pressure_stabilisation.c). */
enum surface_node { SURFACE_NONE, SURFACE_ON, SURFACE_GHOST, SURFACE_GHOST_TIED };

/* free_surface.c: where p^{t+1} = 0 (000 §4.5 step 5b). free_surface_mark sets f->cell_wet,
 * f->dirichlet (prescribed nodes), f->surface and the surface points of the interpolated and weak
 * conditions; free_surface_add_penalty adds the interpolated condition's penalty, weighted by
 * free_surface_penalty_factor * scale, to the stencil and f->rhs among the numbered unknowns
 * (nothing with the other conditions); free_surface_add_boundary_term subtracts the weak
 * condition's surface integral sum_x a_x n_x S_I(x) S_J(x) from a gradient operator G laid out
 * as pressure.c's, on the nodes where `mass` (the phase's nodal mass) is not negligible. */
void free_surface_mark(struct sim *s);
void free_surface_add_penalty(struct sim *s, double scale);
void free_surface_add_boundary_term(const struct sim *s, const double *mass, double *G);

/* boundary.c: velocity constraints of the grid faces (000 §4.5 steps 3e, 4d, 6d). */
void boundary_mark(struct sim *s);
void boundary_apply(const struct grid *g, const unsigned char *fix, double *v);

/* plate.c: rigid smooth plates on grid faces (boundaries.<face>.soil "plate"). plate_predict sets
 * the plates' normal velocity V* from the tied nodes' momentum and forces after the predictors
 * (f->force must hold Eq. 52's mixture force) and writes it into v_s*, v_w*; plate_couple_pressure,
 * after the pressure solve (reduced system of n unknowns in s->ps, its solution in f->dp), makes
 * the plates' velocities part of it; plate_correct adds the pressure increment's push to V and
 * writes V into v_s, v_w (step 6); plate_displace writes dt V into the MUSL displacement of step
 * 8a. f->correction_w and f->du_s serve as scratch where they are free and are left zero. */
void plate_predict(struct sim *s);
enum poro_status plate_couple_pressure(struct sim *s, idx_t n);
void plate_correct(struct sim *s);
void plate_displace(struct sim *s, double *du_s);
/* pressure.c: out_I = ((1 - n_I) (D_s v_s)_I + n_I (D_w v_w)_I) / dt, the right-hand side of Eq. 60
 * for nodal velocities v_s, v_w (Eqs. 62-63 through the point divergences); uses f->correction_s
 * and f->correction_w as scratch and leaves them zero. */
void pressure_divergence_rhs(struct sim *s, const double *v_s, const double *v_w, double *out);

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
