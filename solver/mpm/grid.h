/*
 * grid.h - the uniform Cartesian background grid and the nodal fields of one step.
 *
 * Nodes are numbered i + j * nodes[0] (i along x, fastest). Square cells of size h. The grid is
 * fixed for a run; nodal fields are reset at the start of every step (000 §4.5 step 2) and carry
 * no information between steps.
 *
 * Symbols follow 000 §4.2: M_s, M_w nodal masses (Eqs. 44, 50), n_I nodal porosity (Eq. 46),
 * k_I nodal conductivity (Eq. 47), v_s, v_w nodal velocities.
 */
#ifndef PORO_GRID_H
#define PORO_GRID_H

#include "case.h"
#include "particles.h"

/* The space dimension. The solver is 2-D, plane strain: nodal and per-point vectors are DIM
 * interleaved components, per-point 2x2 tensors 4 (row-major), stresses 4 (xx, yy, xy, zz: the
 * out-of-plane normal stress of plane strain), shape functions the tensor product of DIM 1-D
 * factors. Code that assumes 2-D beyond these names says so; 3-D changes these layouts and the
 * shape tables, not the phases. */
#define DIM 2

struct grid {
	double origin[2];        /* m */
	double h, inv_h;         /* cell size, m, and its inverse */
	idx_t cells[2];          /* cells per direction */
	idx_t nodes[2];          /* nodes per direction = cells + 1 */
	idx_t node_count;
	idx_t cell_count;
};

/* The nodal fields of one step that every scheme maps into; arrays of node_count (scalars) or
 * DIM node_count (vectors, interleaved). A scheme's own nodal fields are in its state (scheme.h). */
struct grid_fields {
	double *mass_s;          /* M_sI, Eq. 44, kg/m */
	double *mass_w;          /* M_wI, Eq. 50 */
	double *mass_w_points;   /* sum S m_wp: water mass with one dof, for Eq. 77 weights */
	double *mass_w_v;        /* sum S V_wp: water-point volume at the node (Eq. 50 without n rho_w) */
	double *volume_s;        /* sum S V_sp: soil-point volume at the node */
	double *v_s, *v_w;       /* v^t, then v^{t+1} after the correction (step 6) */
	double *v_s_old, *v_w_old; /* v^t kept for the FLIP increment (step 7b) */
	double *porosity;        /* n_I, Eq. 46 (1 where there is no soil) */
	double *conductivity;    /* k_I, Eq. 47, m/s */
	double *pressure;        /* p^t_I: water-mass-weighted projection of point pressures (Eq. 77's
				    inner sum, as a local linear fit: transfer.h), tension + */
	double *fit_moments;     /* [9 node_count] scratch of that fit (p2g_scalar_linear_fit) */
	double *force_w;         /* F_w^ext - F_w^int, Eqs. 56-57, N/m */
	double *force;           /* F^ext - F^int of the mixture, Eqs. 54-55 */
	double *du_s;            /* MUSL displacement increment, step 8a, m */
	unsigned char *fix_s;    /* velocity constraint bits per node: 1 = x fixed, 2 = y fixed (soil) */
	unsigned char *fix_w;    /* same for water */
};

enum poro_status grid_init(struct grid *g, const struct case_grid *spec, struct poro_error *err);
enum poro_status grid_fields_init(struct grid_fields *f, const struct grid *g, struct poro_error *err);
/* Zeroes the fields a step maps into (000 §4.5 step 2: the grid carries nothing between steps). */
void grid_fields_reset(struct grid_fields *f, const struct grid *g);

/* Zeroes count doubles of a nodal array on the calling team's threads: a step clears several MB
 * of nodal arrays and stencils, and one thread's memset leaves the other cores' share of the
 * memory bandwidth unused. */
void grid_zero(double *field, size_t count);
void grid_fields_release(struct grid_fields *f);

static inline idx_t grid_node(const struct grid *g, idx_t i, idx_t j)
{
	return i + j * g->nodes[0];
}

/* The grid face x lies beyond (the first of left, right, bottom, top that it crosses), or -1 if
 * it lies inside (a point on a face is inside; NaN counts as inside and is reported by the next
 * shape evaluation). */
static inline int grid_face_beyond(const struct grid *g, const double x[2])
{
	const double xi = (x[0] - g->origin[0]) * g->inv_h, eta = (x[1] - g->origin[1]) * g->inv_h;
	return xi < 0 ? FACE_LEFT : xi > g->cells[0] ? FACE_RIGHT : eta < 0 ? FACE_BOTTOM :
	       eta > g->cells[1] ? FACE_TOP : -1;
}

/* 1 if x lies beyond a grid face, else 0. */
static inline int grid_beyond_face(const struct grid *g, const double x[2])
{
	return grid_face_beyond(g, x) >= 0;
}

/* Cell index containing x, or -1 if x lies outside the grid. */
idx_t grid_cell_of(const struct grid *g, const double x[2]);

#endif
