/*
 * system.c - the implicit u-p-U scheme's system (001 Eqs. 5-10, Appendix A; spec-001 §3-4): its
 * unknowns, the Newmark matrix on the grid's fixed pattern, and the residual at an iterate.
 *
 * Symbols (001 §2, spec-001 §3.3): d = [u; p; U] the increments of the solid's displacement, the
 * pore pressure (compression positive) and the water's displacement; S_i, grad S_i uGIMP (or any
 * shape) at the step's start; B-bar_i the strain operator of Eqs. 12-16 with the volumetric part
 * sampled at the cell centres (mB_i = m^T B-bar_i = the cell-centre gradient), or B_i without it;
 * m_s = (1 - n) rho_s V, m_w = n rho_w V; c_d = n^2 rho_w g / k the drag per volume (A.1c-e with
 * rho_w g restored, spec-001 E6); 1/Q = n / K_w + (1 - n) / K_s (Eq. 3). Per point and pair of its
 * support nodes (i, j), with c_M = 1 / (beta dt^2), c_C = gamma / (beta dt):
 *     uu:  c_M m_s S_i S_j I + c_C c_d V S_i S_j I + V B-bar_i^T D B-bar_j
 *     uU = Uu: -c_C c_d V S_i S_j I;   UU: c_M m_w S_i S_j I + c_C c_d V S_i S_j I
 *     up:  -(1 - n) V mB_i S_j (-G1);   pu: its transpose;   Up: -n V mB_i S_j (-G2), pU likewise
 *     pp:  -V S_i S_j / Q (-P, the sign spec-001 E2 restores so the matrix is symmetric)
 * and the internal forces of Eq. 10:
 *     f_u,i = V B-bar_i^T (sigma' - (1 - n) p m),   f_U,i = -V n p mB_i,
 *     f_p,i = -V S_i ((1 - n) Delta eps_v^u + Delta p / Q + n Delta eps_v^U),
 * the last Eq. 3 integrated over the step, with the step's porosity (docs/numerics.md, "Eq. 10b
 * over a step": spec-001 reconstructs it from the reference state, with the strains accumulated
 * at the points since t = 0, which is exact only while n and the points' supports stay as they
 * were, and the Xie-Leo column under 50 kPa blew up when its surface points moved into the next
 * row of cells).
 * Stress is tension positive with engineering shear; D the elastic matrix (001 A.1f, modified
 * Newton-Raphson) or the materials' tangent.
 *
 * The pattern. A point couples the nodes of its support, at most two cells apart, so the matrix's
 * pattern is fixed by the grid: each node's 5 unknowns against every unknown of the nodes within
 * two cells. Unknowns outside the problem (no mass), prescribed ones (constraints, drained nodes)
 * keep their entries at zero with a unit diagonal, so one symbolic analysis serves the whole run
 * (lu_solve.h). The pressure unknowns are scaled by pressure_scale (rows and columns) so the
 * blocks are of one order for the pivoting (spec-001 §4.3).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "implicit.h"
#include "material.h"
#include "point_blocks.h"
#include "shape.h"

#define NEIGHBOURS 25   /* nodes within two cells, 5 x 5 */

/* The offset code of node I against node J, both (i, j), for the rank table. */
static inline int offset_code(idx_t di, idx_t dj)
{
	return (int)(di + 2 + 5 * (dj + 2));
}

enum poro_status implicit_system_create(struct sim *s)
{
	struct implicit_state *e = implicit_of(s);
	const struct grid *g = &s->grid;
	const idx_t nodes = g->node_count, nx = g->nodes[0], ny = g->nodes[1];
	e->unknowns = DOFS_PER_NODE * nodes;
	e->rank = malloc((size_t)NEIGHBOURS * (size_t)nodes);
	e->colptr = malloc(sizeof(idx_t) * ((size_t)e->unknowns + 1));
	if (!e->rank || !e->colptr)
		return poro_error_set(&s->err, PORO_ENOMEM, "cannot allocate the implicit system's pattern");
	long entries = 0;
	for (idx_t J = 0; J < nodes; J++) {
		const idx_t i = J % nx, j = J / nx;
		int count = 0;
		for (int k = 0; k < NEIGHBOURS; k++) {
			const idx_t di = k % 5 - 2, dj = k / 5 - 2;
			const int inside = i + di >= 0 && i + di < nx && j + dj >= 0 && j + dj < ny;
			e->rank[(size_t)NEIGHBOURS * J + k] = inside ? (signed char)count++ : -1;
		}
		for (int d = 0; d < DOFS_PER_NODE; d++) {
			e->colptr[DOFS_PER_NODE * J + d] = (idx_t)entries;
			entries += DOFS_PER_NODE * count;
		}
	}
	if (entries > INT32_MAX)
		return poro_error_set(&s->err, PORO_EINVAL, "the implicit system of %ld unknowns would have %ld entries, "
				      "more than its index type holds: a coarser grid is needed", (long)e->unknowns, entries);
	e->colptr[e->unknowns] = (idx_t)entries;
	e->rowidx = malloc(sizeof(idx_t) * (size_t)entries);
	e->values = malloc(sizeof(double) * (size_t)entries);
	if (!e->rowidx || !e->values)
		return poro_error_set(&s->err, PORO_ENOMEM, "cannot allocate the implicit system's %ld entries", entries);
	for (idx_t J = 0; J < nodes; J++) {
		const idx_t i = J % nx, j = J / nx;
		for (int d = 0; d < DOFS_PER_NODE; d++) {
			idx_t *row = e->rowidx + e->colptr[DOFS_PER_NODE * J + d];
			for (int k = 0; k < NEIGHBOURS; k++) {
				if (e->rank[(size_t)NEIGHBOURS * J + k] < 0)
					continue;
				const idx_t I = (i + k % 5 - 2) + (j + k / 5 - 2) * nx;
				for (int r = 0; r < DOFS_PER_NODE; r++)
					*row++ = DOFS_PER_NODE * I + r;
			}
		}
	}
	return lu_solver_create(&e->lu, e->unknowns, e->colptr, e->rowidx, &s->err);
}

void implicit_system_release(struct implicit_state *e)
{
	lu_solver_destroy(&e->lu);
	free(e->rank);
	free(e->colptr);
	free(e->rowidx);
	free(e->values);
}

void implicit_bbar_factors(struct sim *s)
{
	struct implicit_state *e = implicit_of(s);
	const struct grid *g = &s->grid;
	const struct particles *p = &s->soil;
	if (s->spec->formulation.soil_stabilisation != STABILISATION_BBAR)
		return;
#pragma omp parallel for schedule(static)
	for (idx_t q = 0; q < p->n; q++) {
		double *f = e->bbar + (size_t)BBAR_FACTORS * q;
		const double lambda = shape_gimp_half_width(g, p->volume0[q]);
		idx_t i0, j0;
		/* inside the grid: step 1 has checked it */
		shape_1d_gimp_cell_centre((p->x[2 * q] - g->origin[0]) * g->inv_h, lambda, g->cells[0], g->inv_h, &i0, f,
					  f + 3);
		shape_1d_gimp_cell_centre((p->x[2 * q + 1] - g->origin[1]) * g->inv_h, lambda, g->cells[1], g->inv_h, &j0,
					  f + 6, f + 9);
	}
}

/* A point's operators at its support nodes, k = a + b S: the weight, the gradient, the cell-centre
 * gradient mB (B-bar's volumetric row) and B-bar's rows (xx, yy, xy, zz) x (x, y). */
struct point_operators {
	int count;
	idx_t node[SHAPE_NODES_MAX];
	double w[SHAPE_NODES_MAX], mB[SHAPE_NODES_MAX][2], B[SHAPE_NODES_MAX][4][2];
};

static void point_operators(const struct sim *s, idx_t q, struct point_operators *o)
{
	const struct implicit_state *e = implicit_of(s);
	const struct particles *p = &s->soil;
	const struct shape_factors f = particle_shape(p, q);
	const int bbar = s->spec->formulation.soil_stabilisation == STABILISATION_BBAR;
	const double *c = e->bbar + (size_t)BBAR_FACTORS * q;
	const int S = p->support;
	/* the support nodes a point reaches: uGIMP's domain inside one cell leaves the third node of a
	 * direction with nothing (weight, gradient and cell-centre factors all zero), and skipping it
	 * takes 9 node pairs' blocks to 4 in assembly */
	int xs[SHAPE_SUPPORT_MAX], ys[SHAPE_SUPPORT_MAX], nx = 0, ny = 0;
	for (int a = 0; a < S; a++) {
		if (f.wx[a] != 0.0 || f.dx[a] != 0.0 || (bbar && (c[a] != 0.0 || c[3 + a] != 0.0)))
			xs[nx++] = a;
		if (f.wy[a] != 0.0 || f.dy[a] != 0.0 || (bbar && (c[6 + a] != 0.0 || c[9 + a] != 0.0)))
			ys[ny++] = a;
	}
	o->count = nx * ny;
	for (int jb = 0; jb < ny; jb++)
		for (int ia = 0; ia < nx; ia++) {
			const int a = xs[ia], b = ys[jb], k = ia + jb * nx;
			const double gx = f.dx[a] * f.wy[b], gy = f.wx[a] * f.dy[b];
			/* 001 Eq. 16 with the 2-D cell-centre gradient of spec-001 §3.2 */
			const double cx = bbar ? 0.5 * c[a] * c[9 + b] : gx, cy = bbar ? 0.5 * c[3 + a] * c[6 + b] : gy;
			o->node[k] = p->node0[q] + a + b * s->grid.nodes[0];
			o->w[k] = f.wx[a] * f.wy[b];
			o->mB[k][0] = cx, o->mB[k][1] = cy;
			o->B[k][0][0] = (2.0 * gx + cx) / 3.0, o->B[k][0][1] = (-gy + cy) / 3.0;
			o->B[k][1][0] = (-gx + cx) / 3.0, o->B[k][1][1] = (2.0 * gy + cy) / 3.0;
			o->B[k][2][0] = gy, o->B[k][2][1] = gx;
			o->B[k][3][0] = (-gx + cx) / 3.0, o->B[k][3][1] = (-gy + cy) / 3.0;
		}
}

/* The point's material data: m_s, m_w, c_d V, 1/Q, V, n. */
struct point_physics {
	double V, n, ms, mw, drag, inv_Q;
};

static struct point_physics point_physics(const struct sim *s, idx_t q)
{
	const struct particles *p = &s->soil;
	const double n = p->porosity[q], V = p->volume[q], K_s = s->spec->fluid.grain_bulk_modulus;
	return (struct point_physics){
		.V = V, .n = n, .ms = p->mass[q], .mw = n * s->rho_w * V,
		.drag = n * n * s->rho_w * CONDUCTIVITY_GRAVITY / p->conductivity[q] * V,
		.inv_Q = n / s->spec->fluid.bulk_modulus + (K_s > 0.0 ? (1.0 - n) / K_s : 0.0),
	};
}

/* The elastic matrix (engineering shear) of the point's material, or its tangent (tensor shear:
 * the xy column halved). Rows and columns (xx, yy, xy, zz). */
static void point_stiffness(const struct sim *s, idx_t q, double D[4][4])
{
	const struct implicit_state *e = implicit_of(s);
	const struct material *m = &s->materials[s->spec->bodies[s->soil.body[q]].material];
	if (e->tangent) {
		const double *T = e->tangent + 16 * (size_t)q;
		for (int i = 0; i < 4; i++)
			for (int j = 0; j < 4; j++)
				D[i][j] = j == 2 ? 0.5 * T[4 * i + j] : T[4 * i + j];
		return;
	}
	const double l = m->lambda, mu = m->mu;
	const double E[4][4] = {{l + 2 * mu, l, 0, l}, {l, l + 2 * mu, 0, l}, {0, 0, mu, 0}, {l, l, 0, l + 2 * mu}};
	memcpy(D, E, sizeof E);
}

/* Adds a 5x5 block (rows of node I, columns of node J) to the matrix. */
static inline void add_block(struct implicit_state *e, idx_t I, idx_t J, idx_t nx, const double block[5][5])
{
	const int rank = e->rank[(size_t)NEIGHBOURS * J + offset_code(I % nx - J % nx, I / nx - J / nx)];
	for (int c = 0; c < DOFS_PER_NODE; c++) {
		double *column = e->values + e->colptr[DOFS_PER_NODE * J + c] + DOFS_PER_NODE * rank;
		for (int r = 0; r < DOFS_PER_NODE; r++)
			column[r] += block[r][c];
	}
}

void implicit_system_assemble(struct sim *s)
{
	struct implicit_state *e = implicit_of(s);
	const struct case_formulation *form = &s->spec->formulation;
	const struct particles *p = &s->soil;
	const idx_t nx = s->grid.nodes[0];
	const double dt = s->dt, cM = 1.0 / (form->newmark_beta * dt * dt);
	const double cC = form->newmark_gamma / (form->newmark_beta * dt), alpha = e->pressure_scale;
	const int lumped = form->mass_matrix == MASS_MATRIX_LUMPED;
	grid_zero(e->values, (size_t)e->colptr[e->unknowns]);
	/* a point adds into the columns of its support nodes only, rows of its support nodes: the
	 * scatter order of point_blocks.h runs it in parallel with sums independent of the threads */
	FOR_POINTS_BY_BLOCK(p, q, {
		struct point_operators o;
		point_operators(s, q, &o);
		const struct point_physics ph = point_physics(s, q);
		double D[4][4];
		point_stiffness(s, q, D);
		for (int kb = 0; kb < o.count; kb++) {
			double DB[4][2];   /* D B-bar_j */
			for (int r = 0; r < 4; r++)
				for (int c = 0; c < 2; c++)
					DB[r][c] = D[r][0] * o.B[kb][0][c] + D[r][1] * o.B[kb][1][c] + D[r][2] * o.B[kb][2][c] +
						   D[r][3] * o.B[kb][3][c];
			for (int ka = 0; ka < o.count; ka++) {
				const double SS = o.w[ka] * o.w[kb], drag = cC * ph.drag * SS;
				const double ms = lumped ? (ka == kb ? o.w[ka] * ph.ms : 0.0) : SS * ph.ms;
				const double mw = lumped ? (ka == kb ? o.w[ka] * ph.mw : 0.0) : SS * ph.mw;
				double block[5][5] = {{0}};
				for (int a = 0; a < 2; a++) {
					for (int b = 0; b < 2; b++)
						block[DOF_UX + a][DOF_UX + b] = ph.V * (o.B[ka][0][a] * DB[0][b] + o.B[ka][1][a] * DB[1][b] +
											o.B[ka][2][a] * DB[2][b] + o.B[ka][3][a] * DB[3][b]);
					block[DOF_UX + a][DOF_UX + a] += cM * ms + drag;
					block[DOF_WX + a][DOF_WX + a] = cM * mw + drag;
					block[DOF_UX + a][DOF_WX + a] = block[DOF_WX + a][DOF_UX + a] = -drag;
					block[DOF_UX + a][DOF_P] = -alpha * (1.0 - ph.n) * ph.V * o.mB[ka][a] * o.w[kb];
					block[DOF_P][DOF_UX + a] = -alpha * (1.0 - ph.n) * ph.V * o.w[ka] * o.mB[kb][a];
					block[DOF_WX + a][DOF_P] = -alpha * ph.n * ph.V * o.mB[ka][a] * o.w[kb];
					block[DOF_P][DOF_WX + a] = -alpha * ph.n * ph.V * o.w[ka] * o.mB[kb][a];
				}
				block[DOF_P][DOF_P] = -alpha * alpha * ph.inv_Q * ph.V * SS;
				add_block(e, o.node[ka], o.node[kb], nx, block);
			}
		}
	});
	/* unknowns that are not free: their rows and columns zero, a unit diagonal */
#pragma omp parallel for schedule(static)
	for (idx_t j = 0; j < e->unknowns; j++)
		for (idx_t k = e->colptr[j]; k < e->colptr[j + 1]; k++) {
			const idx_t i = e->rowidx[k];
			if (e->kind[i] != DOF_FREE || e->kind[j] != DOF_FREE)
				e->values[k] = i == j ? 1.0 : 0.0;
		}
}

/* Where a point's stress update writes: its stress, Be, internal state and plastic strain, and
 * the consistent tangent when wanted (NULL otherwise). */
struct stress_target {
	double *stress, *Be, *state, *plastic_strain, *tangent;
};

/* Point q's stress under the B-bar strain increment (xx, yy, engineering xy, zz) and volumetric
 * increment vol_u, integrated from the step-start state (path-independent within the step,
 * spec-001 §4.2) into out. */
static enum poro_status stress_from_step_start(const struct sim *s, idx_t q, const struct material *m,
					       const double strain[4], double vol_u, int elastic_only,
					       const struct stress_target *out, struct poro_error *err)
{
	const struct implicit_state *e = implicit_of(s);
	const struct particles *p = &s->soil;
	memcpy(out->stress, e->stress_n + 4 * (size_t)q, 4 * sizeof(double));
	memcpy(out->Be, e->Be_n + 4 * (size_t)q, 4 * sizeof(double));
	memcpy(out->state, e->state_n + STATE_MAX * (size_t)q, STATE_MAX * sizeof(double));
	*out->plastic_strain = e->plastic_n[q];
	const double dF[4] = {1.0 + strain[0], 0.5 * strain[2], 0.5 * strain[2], 1.0 + strain[1]};
	struct stress_update u = {
		.dF = dF, .dF_zz = 1.0 + strain[3], .J = p->volume[q] / p->volume0[q] * (1.0 + vol_u),
		.stress = out->stress, .Be = out->Be, .state = out->state, .plastic_strain = out->plastic_strain,
		.tangent = out->tangent, .elastic_only = elastic_only,
	};
	return material_update(m, &u, err);
}

/* The perturbation of a strain component for the numerical tangent: the forward difference's
 * truncation error is of order delta |d2 sigma / d eps2| and its round-off of order 1e-16 |sigma| /
 * delta, both at most about 1e-8 of the tangent at strains of 1e-4 to 1 */
#define TANGENT_PERTURBATION 1e-8

/* The consistent tangent of a finite-strain material at the iterate, by forward differences: each
 * column the stress response to a perturbation of one component of the B-bar strain increment,
 * integrated from the step-start state like the residual's (Miehe 1996, "Numerical computation of
 * algorithmic (consistent) tangent moduli in large-strain computational inelasticity"). The
 * materials' own tangent of a finite-strain model is d tau / d eps_trial (material.h), not the
 * derivative of the Cauchy stress the residual integrates with respect to the linearised strain
 * increment at x_n (spec-001 §3.4); this is, to about 1e-8. Layout of material.h (tensor shear):
 * column 2 answers eps_xy, half the engineering shear the strain vector carries. */
static enum poro_status numerical_tangent(const struct sim *s, idx_t q, const double strain[4], double vol_u,
					  const struct material *m, int elastic_only, double T[16],
					  struct poro_error *err)
{
	const struct particles *p = &s->soil;
	for (int c = 0; c < 4; c++) {
		double d[4] = {strain[0], strain[1], strain[2], strain[3]};
		d[c] += TANGENT_PERTURBATION;
		const double dvol = c == 2 ? 0.0 : TANGENT_PERTURBATION;   /* B-bar: vol = xx + yy + zz */
		double stress[4], Be[4], state[STATE_MAX], plastic;
		const struct stress_target out = {stress, Be, state, &plastic, NULL};
		TRY(stress_from_step_start(s, q, m, d, vol_u + dvol, elastic_only, &out, err));
		const double scale = (c == 2 ? 2.0 : 1.0) / TANGENT_PERTURBATION;
		for (int r = 0; r < 4; r++)
			T[4 * r + c] = (stress[r] - p->stress[4 * q + r]) * scale;
	}
	return PORO_OK;
}

/* The strain increment of the iterate at point q, B-bar Delta u (xx, yy, engineering xy, zz), and
 * the volumetric strain increments of both phases and the pressure increment there. */
struct point_increments {
	double strain[4], vol_u, vol_w, dp, du[2];
	double a_u[2], a_w[2], v_u[2], v_w[2];   /* the iterate's a_{n+1}, v_{n+1} at the point */
};

/* Keeps err as the step's error if point q is the lowest failing point so far (*failed). */
static void keep_lowest_failure(struct sim *s, idx_t q, const struct poro_error *err, idx_t *failed)
{
#pragma omp critical(implicit_residual_failure)
	if (q < *failed) {
		*failed = q;
		s->err = *err;
	}
}

enum poro_status implicit_system_residual(struct sim *s)
{
	struct implicit_state *e = implicit_of(s);
	const struct case_formulation *form = &s->spec->formulation;
	struct particles *p = &s->soil, *w = &s->water;
	const double dt = s->dt, beta = form->newmark_beta, gamma = form->newmark_gamma;
	const double cM = 1.0 / (beta * dt * dt), cV = 1.0 / (beta * dt), cA = 0.5 / beta - 1.0;
	const double cC = gamma / (beta * dt), cVv = gamma / beta - 1.0, cVa = dt * (0.5 * gamma / beta - 1.0);
	const int lumped = form->mass_matrix == MASS_MATRIX_LUMPED, elastic_only = loads_in_gravity_ramp(s) &&
		s->spec->gravity.elastic_loading;
	const idx_t N = e->unknowns;
	/* a_{n+1} and v_{n+1} of the iterate at the nodes (Newmark, 001 Eq. 8); the residual starts
	 * as f_{n+1} */
	double *a_new = e->acceleration_new, *v_new = e->velocity_new;
#pragma omp parallel for schedule(static)
	for (idx_t k = 0; k < N; k++) {
		a_new[k] = cM * e->increment[k] - cV * e->velocity[k] - cA * e->acceleration[k];
		v_new[k] = cC * e->increment[k] - cVv * e->velocity[k] - cVa * e->acceleration[k];
		e->residual[k] = e->external[k];
	}
	idx_t failed = p->n;
	/* q's stress and state, rows of q's support nodes: in parallel in the scatter order of
	 * point_blocks.h; every point is updated and the failure kept is the lowest point's */
	FOR_POINTS_BY_BLOCK(p, q, {
		struct point_operators o;
		point_operators(s, q, &o);
		const struct point_physics ph = point_physics(s, q);
		struct point_increments in;
		memset(&in, 0, sizeof in);
		for (int k = 0; k < o.count; k++) {
			const double *d = e->increment + DOFS_PER_NODE * (size_t)o.node[k];
			const double *A = a_new + DOFS_PER_NODE * (size_t)o.node[k], *Vn = v_new + DOFS_PER_NODE * (size_t)o.node[k];
			for (int r = 0; r < 4; r++)
				in.strain[r] += o.B[k][r][0] * d[DOF_UX] + o.B[k][r][1] * d[DOF_UY];
			in.vol_u += o.mB[k][0] * d[DOF_UX] + o.mB[k][1] * d[DOF_UY];
			in.vol_w += o.mB[k][0] * d[DOF_WX] + o.mB[k][1] * d[DOF_WY];
			in.dp += o.w[k] * d[DOF_P];
			for (int c = 0; c < 2; c++) {
				in.du[c] += o.w[k] * d[DOF_UX + c];
				in.a_u[c] += o.w[k] * A[DOF_UX + c], in.a_w[c] += o.w[k] * A[DOF_WX + c];
				in.v_u[c] += o.w[k] * Vn[DOF_UX + c], in.v_w[c] += o.w[k] * Vn[DOF_WX + c];
			}
		}
		memcpy(e->strain_increment + 4 * (size_t)q, in.strain, sizeof in.strain);
		const struct material *m = &s->materials[s->spec->bodies[p->body[q]].material];
		const int finite = material_is_finite_strain(m);
		const struct stress_target out = {
			p->stress + 4 * q, p->Be + 4 * q, p->state + STATE_MAX * q, p->plastic_strain + q,
			e->tangent && !finite ? e->tangent + 16 * (size_t)q : NULL,
		};
		struct poro_error err;   /* this point's: the threads' share s->err (keep_lowest_failure) */
		enum poro_status st = stress_from_step_start(s, q, m, in.strain, in.vol_u, elastic_only, &out, &err);
		if (!st && e->tangent && finite)
			st = numerical_tangent(s, q, in.strain, in.vol_u, m, elastic_only, e->tangent + 16 * (size_t)q, &err);
		if (st)
			keep_lowest_failure(s, q, &err, &failed);
		const double pressure = -w->pressure[q] + in.dp;   /* compression positive */
		const double *sg = p->stress + 4 * q, pn = (1.0 - ph.n) * pressure;
		const double partial[4] = {sg[0] - pn, sg[1] - pn, sg[2], sg[3] - pn};   /* sigma' - (1 - n) p m */
		const double balance = (1.0 - ph.n) * in.vol_u + in.dp * ph.inv_Q + ph.n * in.vol_w;
		const double drag[2] = {ph.drag * (in.v_u[0] - in.v_w[0]), ph.drag * (in.v_u[1] - in.v_w[1])};
		for (int k = 0; k < o.count; k++) {
			double *r = e->residual + DOFS_PER_NODE * (size_t)o.node[k];
			const double *A = a_new + DOFS_PER_NODE * (size_t)o.node[k];
			for (int c = 0; c < 2; c++) {
				const double f_u = ph.V * (o.B[k][0][c] * partial[0] + o.B[k][1][c] * partial[1] +
							   o.B[k][2][c] * partial[2] + o.B[k][3][c] * partial[3]);
				const double f_w = -ph.V * ph.n * pressure * o.mB[k][c];
				const double inertia_u = lumped ? o.w[k] * ph.ms * A[DOF_UX + c] : o.w[k] * ph.ms * in.a_u[c];
				const double inertia_w = lumped ? o.w[k] * ph.mw * A[DOF_WX + c] : o.w[k] * ph.mw * in.a_w[c];
				r[DOF_UX + c] -= f_u + inertia_u + o.w[k] * drag[c];
				r[DOF_WX + c] -= f_w + inertia_w - o.w[k] * drag[c];
			}
			r[DOF_P] += ph.V * o.w[k] * balance;   /* -f_p */
		}
	});
#pragma omp parallel for schedule(static)
	for (idx_t k = 0; k < N; k++)
		if (e->kind[k] != DOF_FREE)
			e->residual[k] = 0.0;
	return failed < p->n ? s->err.code : PORO_OK;
}

void implicit_point_volumetric(const struct sim *s, idx_t q, double *eps_u, double *eps_w)
{
	const struct implicit_state *e = implicit_of(s);
	struct point_operators o;
	point_operators(s, q, &o);
	double u = 0.0, w = 0.0;
	for (int k = 0; k < o.count; k++) {
		const double *d = e->increment + DOFS_PER_NODE * (size_t)o.node[k];
		u += o.mB[k][0] * d[DOF_UX] + o.mB[k][1] * d[DOF_UY];
		w += o.mB[k][0] * d[DOF_WX] + o.mB[k][1] * d[DOF_WY];
	}
	*eps_u = u, *eps_w = w;
}
