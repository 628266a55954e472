/*
 * implicit.h - paper 001's fully implicit u-p-U scheme (Zheng, Pisanò, Vardon and Hicks 2022; read
 * with spec-001.md): its own state and the files that serve it (schemes/implicit/). Not public; the
 * rest of the solver sees the scheme through scheme.h.
 *
 *   implicit.c    the step (spec-001 §5): nodal kinematics, the Newmark system, the modified
 *                 Newton-Raphson loop, the points' update (Eq. 11)
 *   system.c      the unknowns (5 a node: the solid's displacement, the pore pressure, the
 *                 water's displacement, Eq. 5), the matrix of Eq. 9 on the grid's fixed pattern
 *                 and the residual of Eq. 10 at an iterate
 *   recovery.c    the MLSA patch recovery of the pore-pressure increments (001 §2.2)
 *   lu_solve.c    UMFPACK
 *
 * One set of points carries both phases (single point): the soil set holds the positions, the
 * solid's velocity, acceleration and volumetric strain eps_v^u, the effective stress; the water set
 * rides on it and holds the water's velocity, acceleration and eps_v^U, the pore pressure p and its
 * reference p0 (particles.h), all of which a checkpoint saves. Pore pressure is tension positive
 * inside the solver as everywhere; the equations below use 001's compression-positive p = -pi.
 */
#ifndef PORO_IMPLICIT_H
#define PORO_IMPLICIT_H

#include "lu_solve.h"
#include "sim_internal.h"

/* The unknowns of a node, in this order (001 Eq. 5 with the increments of a step). */
enum { DOF_UX, DOF_UY, DOF_P, DOF_WX, DOF_WY, DOFS_PER_NODE };

/* How an unknown is held: solved for, held at a prescribed increment (a constraint: 0; a drained
 * node: -p~ so that p = 0 there), or outside the problem (no mass: a unit diagonal). */
enum dof_kind { DOF_FREE, DOF_PRESCRIBED, DOF_INACTIVE };

/* Per point, the 1-D factors of uGIMP's cell-centre sampling (shape.h): G_x, W_x, G_y, W_y for the
 * 3 support nodes each; B-bar reads them. */
#define BBAR_FACTORS 12

struct implicit_state {
	idx_t unknowns;           /* DOFS_PER_NODE node_count */
	/* the matrix's pattern: the grid's, fixed (lu_solve.h); column DOFS_PER_NODE J + d lists the
	 * unknowns of every node within two cells of J, in ascending order */
	idx_t *colptr, *rowidx;
	signed char *rank;        /* [25 node_count] for node J and the neighbour offset (di, dj), k =
				     (di + 2) + 5 (dj + 2): its place among J's neighbours, -1 if outside */
	double *values;           /* [colptr[unknowns]] the Newmark matrix, pressure unknowns scaled */
	double pressure_scale;    /* alpha: p = alpha p^ in the solved system, Pa per unit */
	struct lu_solver *lu;
	/* per unknown */
	unsigned char *kind;      /* enum dof_kind */
	double *prescribed;       /* the increment of a prescribed unknown */
	double *increment;        /* Delta d: the step's increments so far (m, Pa, m) */
	double *delta;            /* the Newton correction */
	double *residual;         /* r of the current iterate */
	double *external;         /* f_{n+1} */
	double *velocity, *acceleration; /* v_n, a_n mapped from the points (u and U unknowns; 0 for p) */
	double *velocity_new, *acceleration_new; /* v_{n+1}, a_{n+1} of the iterate (Newmark, Eq. 8) */
	double *scaled;           /* the residual with its pressure rows scaled, the solve's right side */
	double *nodal_pressure;   /* [node_count] p~: the step-start pressure projected (drained nodes) */
	double *fill;             /* [cell_count] the points' volume in each cell over h^2 */
	double *cell_pressure;    /* [cell_count] the recovery's cell-centre Delta p (recovery.c) */
	double *patch;            /* [3 node_count] the recovery's plane a0, a1, a2 per node, its own fit */
	double *patch_edge;       /* [3 node_count] the same after the boundary nodes borrowed a plane */
	unsigned char *patch_full;/* [node_count] 1 where the node's four cells hold points */
	/* per point */
	double *bbar;             /* [BBAR_FACTORS n] */
	double *stress_n, *Be_n, *state_n, *plastic_n; /* the converged state at the step's start */
	double *strain_increment; /* [4 n] B-bar Delta u: (xx, yy, engineering xy, zz) */
	double *tangent;          /* [16 n] the materials' tangents with tangent "consistent", else NULL */
	double *volume_rate;      /* [n] mB Delta u / dt: the volume update's rate (deformation.c) */
	double *pressure_increment; /* [n] the points' converged Delta p (recovery.c), Pa, compression + */
	/* statistics */
	int iterations;           /* of the last step */
	long iterations_total;
	double residual_history[SIM_ITERATIONS_KEPT]; /* |delta . r| of the last step's iterations */
	int history_count;
	double moved_step;        /* the last step's largest point displacement, in cells */
};

static inline struct implicit_state *implicit_of(const struct sim *s)
{
	return s->scheme_state;
}

/* system.c */
enum poro_status implicit_system_create(struct sim *s);
void implicit_system_release(struct implicit_state *e);
/* Each point's B-bar factors at the step's start (after the shape functions). */
void implicit_bbar_factors(struct sim *s);
/* Assembles K = 1/(beta dt^2) M + gamma/(beta dt) C + K at the step's start configuration (001
 * Eq. 9, A.1) into e->values, with the elastic D (or the tangents in e->tangent when not NULL),
 * unit diagonals and zero rows and columns on unknowns that are not free, the pressure unknowns
 * scaled. */
void implicit_system_assemble(struct sim *s);
/* The residual r = f_{n+1} - f_int(Delta d) - M a_{n+1}(Delta d) - C v_{n+1}(Delta d) at the free
 * unknowns (001 Eqs. 9-10), updating every point's stress from its step-start state with the
 * strain increment of Delta d (with tangents when e->tangent is set). Fails as a material does. */
enum poro_status implicit_system_residual(struct sim *s);

/* mB Delta u and mB Delta U at point q: the volumetric strain increments of both phases of the
 * current increments (B-bar's, or the point gradient's without it). */
void implicit_point_volumetric(const struct sim *s, idx_t q, double *eps_u, double *eps_w);

/* recovery.c: the points' pore-pressure increments from the converged nodal ones (001 §2.2), into
 * out[n], Pa, compression positive. */
void implicit_pressure_recovery(struct sim *s, double *out);

#endif
