/*
 * particles.h - one set of material points in structure-of-arrays storage.
 *
 * A simulation has a soil set and, for the double-point formulation (000 §2), a water set. In the
 * single-point formulation the water phase rides on the soil points: the water set then aliases
 * the soil set's position, volume, porosity and shape-function arrays (alias_of != NULL) and owns
 * only its velocity, mass and pressure.
 *
 * Conventions (DESIGN §2.4): 2-D plane strain, per unit thickness (a "volume" is an area times 1 m).
 * Tensors are stored row-major; symmetric stresses as 4 components (xx, yy, xy, zz).
 * Internally pore pressure follows the paper's sign: tension positive (000 §2, after Eq. 6), so
 * compression is negative; output converts to the physical pressure, positive in compression.
 *
 * Arrays are allocated once at create with capacity n and never during a step (STYLE rule 3).
 */
#ifndef PORO_PARTICLES_H
#define PORO_PARTICLES_H

#include <stdint.h>

#include "error.h"

typedef int32_t idx_t;            /* matches CHOLMOD's int interface */

#define SHAPE_SUPPORT_MAX 4         /* support nodes per direction: 2 linear, 3 quadratic, 4 cubic */
#define SHAPE_NODES_MAX (SHAPE_SUPPORT_MAX * SHAPE_SUPPORT_MAX)
#define STATE_MAX 8                 /* model internal variables per point */

struct point_blocks;                /* point_blocks.h */

struct particles {
	idx_t n;                    /* number of points */
	const struct particles *alias_of; /* single-point water set: the soil set it rides on */

	double *x;                  /* [2n] current position, m */
	double *x0;                 /* [2n] initial position, m (displacement = x - x0) */
	double *v;                  /* [2n] velocity, m/s */
	double *C;                  /* [4n] APIC's affine velocity (xx, xy, yx, yy: dv_x/dx, dv_x/dy, ...),
				       1/s; NULL with formulation.velocity_update "flip" */
	double *mass;               /* [n] kg per m thickness; soil: (1-n0) rho_s V0 (Eq. 33), constant;
				       water: n0 rho_w V0 (Eq. 37) in double point, constant */
	double *volume;             /* [n] current volume V^t, m^3 per m */
	double *volume0;            /* [n] initial volume V^0 */
	double *porosity;           /* [n] soil: n_sp (step 8f); water: soil porosity projected, n_wp (Eq. 48) */
	double *porosity0;          /* [n] initial porosity n0 */
	double *conductivity;       /* [n] hydraulic conductivity k, m/s (soil set) */
	double *pressure;           /* [n] pore water pressure p_w, Pa, TENSION POSITIVE (internal sign) */
	int *body;                  /* [n] index of the case body the point came from */

	/* soil skeleton state (soil set only; NULL for the water set) */
	double *stress;             /* [4n] effective Cauchy stress sigma' (xx, yy, xy, zz), Pa, tension + */
	double *F;                  /* [4n] deformation gradient (xx, xy, yx, yy); F_zz = 1 in plane strain */
	double *Be;                 /* [4n] elastic left Cauchy-Green tensor (xx, yy, xy, zz), Eq. 70 */
	double *state;              /* [STATE_MAX n] constitutive internal variables */
	double *plastic_strain;     /* [n] accumulated plastic strain (0 for elastic models) */
	double *dF;                 /* [4n] scratch: deformation gradient increment of this step */
	double *dF_zz;              /* [n] its out-of-plane stretch, for a scheme whose smoothed volumetric
				       rate has a zz part (002 Eq. 27); NULL: plane strain, dF_zz = 1 */

	/* the implicit u-p-U scheme's state between steps (001 Eq. 11; NULL for the other schemes),
	 * each set its own: the soil set's for the solid, the water set's for the water */
	double *acceleration;       /* [2n] the phase's acceleration at the point, m/s^2 (Eq. 11a-b) */
	double *surface;            /* [2n] loaded-face length vector N dA in the reference configuration,
				       m per m (zero for interior points); see loads.c */
	int *surface_load;          /* [n] index of the case load acting on the point, -1 if none */

	/* shape-function cache, filled once per step by shape_evaluate() (000 §4.5 step 1) */
	int support;                /* nodes per direction of the current shape function */
	idx_t *node0;               /* [n] linear index of the lower-left support node */
	double *shape;              /* [4 SHAPE_SUPPORT_MAX n] the 1-D factors of S_Ip: point q's block of
				       4 support values at 4 support q (see particle_shape) */
	struct point_blocks *blocks; /* the points by block of the cells that hold them, the order in
				       which the scatters run in parallel (point_blocks.h), sorted by
				       shape_evaluate with the cache; owned. NULL: scatters run
				       serially in index order. An aliased set has none and uses its
				       soil set's */
};

/* The shape functions are tensor products: for the support node a + b support (a along x, b
 * along y) S_Ip = wx[a] wy[b] and grad S_Ip = (dx[a] wy[b], wx[a] dy[b]), dx and dy per metre.
 * The cache keeps the 4 support 1-D factors rather than the 3 support^2 products (12 values a
 * point instead of 27 for quadratic B-splines): the loops that use them form the products as
 * they go, which costs less than moving the products through memory. */
struct shape_factors {
	const double *wx, *wy, *dx, *dy;   /* [support] each */
};

static inline struct shape_factors particle_shape(const struct particles *p, idx_t q)
{
	const int S = p->support;
	const double *f = p->shape + (size_t)q * 4 * S;
	return (struct shape_factors){ f, f + S, f + 2 * S, f + 3 * S };
}

/* Allocates a set of n points with every array zeroed; soil sets also get the skeleton arrays.
 * Returns PORO_ENOMEM on failure with nothing allocated. */
enum poro_status particles_init(struct particles *p, idx_t n, int with_skeleton, struct poro_error *err);

/* Makes w a single-point water set riding on soil: shares x, x0, volume, volume0, porosity,
 * porosity0, body and the shape cache; owns v, mass, pressure. */
enum poro_status particles_init_alias(struct particles *w, const struct particles *soil, struct poro_error *err);

/* Gives p an affine velocity array C, zeroed (APIC, transfer.h). Returns PORO_ENOMEM on failure. */
enum poro_status particles_add_affine(struct particles *p, struct poro_error *err);

/* Gives p an out-of-plane stretch array dF_zz, zeroed. Returns PORO_ENOMEM on failure. */
enum poro_status particles_add_out_of_plane(struct particles *p, struct poro_error *err);

/* Gives p the implicit scheme's acceleration array, zeroed.
 * Returns PORO_ENOMEM on failure. */
enum poro_status particles_add_implicit_state(struct particles *p, struct poro_error *err);

/* Gives p the scatter blocks of grid g for its n points, POINT_BLOCK_CELLS_X x POINT_BLOCK_CELLS_Y
 * cells each (point_blocks.h); shape_evaluate sorts them from then on. Returns PORO_ENOMEM on
 * failure. */
struct grid;
enum poro_status particles_add_blocks(struct particles *p, const struct grid *g, struct poro_error *err);

/* Removes point q by moving the last point into its place (order is not kept); the scatter
 * blocks are stale until the next shape_evaluate. Not for aliased sets or sets with skeleton
 * arrays. */
void particles_remove(struct particles *p, idx_t q);

void particles_release(struct particles *p);

#endif
