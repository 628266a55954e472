/*
 * semi_implicit.h - paper 000's semi-implicit scheme: its own state and the files that serve it
 * (schemes/semi_implicit/). Not public; the rest of the solver sees the scheme through scheme.h.
 *
 *   semi_implicit.c           the step (000 §4.5), the predictors and the correction
 *   pressure.c                the pressure Poisson system and its solve (step 5, Eqs. 60-68)
 *   pressure_stabilisation.c  the consistent projection's stabilisation
 *   free_surface.c            where p^{t+1} = 0 (step 5b)
 *   cavitation.c              storage of water at the cavitation pressure
 *   plate.c                   rigid plates on grid faces, solved with the pressure
 *   spd_solve.c               the sparse Cholesky factorisation (CHOLMOD)
 *
 * The state is rebuilt every step from the points; nothing here is carried between steps, so a
 * checkpoint of the points is a checkpoint of the scheme.
 */
#ifndef PORO_SEMI_IMPLICIT_H
#define PORO_SEMI_IMPLICIT_H

#include "sim_internal.h"
#include "spd_solve.h"

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

/* The scheme's nodal fields (arrays of node_count, or DIM node_count interleaved), besides the
 * shared ones of grid.h, and its workspaces. Symbols of 000 §4.2. */
struct semi_implicit {
	struct pressure_system ps;
	double *v_s_star, *v_w_star; /* intermediate velocities, Eqs. 52-53 */
	double *drag_dt;         /* Q_I dt, Eq. 58 times the step, kg/m: the drag of both velocity updates */
	double *mobility_ratio;  /* mixture mobility with drag over that without (pressure.c), 1 without drag */
	double *dp;              /* p^{t+1} - p^t, Eq. 60 */
	double *rhs;             /* Poisson right-hand side, Eq. 60 */
	double *correction_s, *correction_w; /* G_s dp, G_w dp (Eqs. 67-68), N/m */
	signed char *cell_wet;   /* [cell_count] 1 if a pressure-carrying point lies in the cell */
	signed char *dirichlet;  /* 1 if the pressure increment is prescribed at the node (free surface,
				    drained face) */
	signed char *surface;    /* enum surface_node: the node's part in the interpolated or weak
				    free-surface condition */
	double *cell_fill;       /* [cell_count] volume of pressure-carrying points per cell, m^3/m */
	double *cell_fill_soil;  /* [cell_count] volume of soil points per cell (double point), m^3/m */
	double plate_velocity[FACE_COUNT]; /* normal velocity of each face's rigid plate this step, m/s,
					      along the grid axis (plate.c; 0 on faces without one) */
	double *plate_work;      /* [(FACE_COUNT + 2) node_count] the plates' pressure responses and
				    reduced right-hand side and solution (plate.c); NULL without plates */
};

/* The scheme's state of a simulation that runs it. */
static inline struct semi_implicit *semi_implicit_of(const struct sim *s)
{
	return (struct semi_implicit *)s->scheme_state;
}

/* The soil points of the saturated bodies, the first s->saturated_soil of the soil set: the skeleton
 * whose pores hold the water of Eqs. 32 and 60-68. A dry body's points ("saturated": false) carry
 * no pore pressure and do not take part in the mixture's continuity (their pores hold air), so the
 * pressure matrix, its right-hand side and the pressure's push on the soil are sums over these
 * alone (docs/numerics.md, "Dry bodies"). The whole soil set when every body is saturated. */
static inline struct particles semi_implicit_wet_soil(const struct sim *s)
{
	struct particles wet = s->soil;
	wet.n = s->saturated_soil;
	return wet;
}

/* semi_implicit.c: the scheme's entry in scheme.h, and its step (000 §4.5). */
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

#endif
