/*
 * pressure.c - the pore-pressure increment of the semi-implicit scheme (000 §4.5 step 5):
 * free-surface detection, assembly of dt L dp = D_s v_s* + D_w v_w* (Eqs. 60-63), and its solve.
 *
 * L (Eq. 61) is assembled as sum_p c_p grad S_Ip . grad S_Jp with c_p = V_sp (1 - n_sp) / rho_s for
 * soil points and V_wp n_wp / rho_w for water points. The paper writes the porosity as a nodal
 * factor of row I, which makes L unsymmetric wherever porosity varies; keeping it inside the sum
 * is the plain Galerkin discretisation of Eq. 32 (where n^t sits inside the integral), equal to
 * the paper's form for uniform porosity, and keeps L symmetric positive definite for CHOLMOD.
 * The divergence terms D_s, D_w (Eqs. 62-63) keep the paper's nodal porosity factors.
 *
 * Boundary conditions: impermeable faces need nothing (the natural condition of Eq. 32). Nodes
 * on the free water surface and on drained faces get p^{t+1} = 0, i.e. dp_I = -p^t_I. A node is
 * on the free surface when a cell next to it (inside the grid) holds no pressure-carrying point
 * (after Kularathna and Soga, cited in 000 step 5b); cells beyond the grid edge are walls.
 */
#include <stdlib.h>
#include <string.h>

#include "sim_internal.h"
#include "transfer.h"

enum poro_status pressure_system_init(struct pressure_system *ps, const struct grid *g, int support,
				      struct poro_error *err)
{
	memset(ps, 0, sizeof *ps);
	ps->radius = support - 1;
	ps->width = 2 * ps->radius + 1;
	const size_t nodes = (size_t)g->node_count, st = (size_t)ps->width * ps->width;
	const size_t nnz_max = nodes * (st + 1) / 2;
	ps->stencil = calloc(nodes * st, sizeof(double));
	ps->unknown = malloc(nodes * sizeof(idx_t));
	ps->colptr = malloc((nodes + 1) * sizeof(idx_t));
	ps->rowidx = malloc(nnz_max * sizeof(idx_t));
	ps->values = malloc(nnz_max * sizeof(double));
	ps->b = malloc(nodes * sizeof(double));
	ps->x = malloc(nodes * sizeof(double));
	if (!ps->stencil || !ps->unknown || !ps->colptr || !ps->rowidx || !ps->values || !ps->b || !ps->x) {
		pressure_system_release(ps);
		return poro_error_set(err, PORO_ENOMEM, "cannot allocate the pressure system");
	}
	return spd_solver_create(&ps->solver, (idx_t)nodes, (idx_t)nnz_max, err);
}

void pressure_system_release(struct pressure_system *ps)
{
	free(ps->stencil);
	free(ps->unknown);
	free(ps->colptr);
	free(ps->rowidx);
	free(ps->values);
	free(ps->b);
	free(ps->x);
	spd_solver_destroy(&ps->solver);
	memset(ps, 0, sizeof *ps);
}

/* Free surface and drained faces: marks f->dirichlet (see the file comment). */
void pressure_mark_dirichlet(struct sim *s)
{
	const struct grid *g = &s->grid;
	struct grid_fields *f = &s->f;
	const struct particles *w = &s->water;
	memset(f->cell_wet, 0, (size_t)g->cell_count);
	for (idx_t q = 0; q < w->n; q++) {
		idx_t c = grid_cell_of(g, w->x + 2 * q);
		if (c >= 0)
			f->cell_wet[c] = 1;
	}
	for (idx_t j = 0; j < g->nodes[1]; j++)
		for (idx_t i = 0; i < g->nodes[0]; i++) {
			int dry = 0;
			for (idx_t cj = j - 1; cj <= j; cj++)
				for (idx_t ci = i - 1; ci <= i; ci++)
					if (ci >= 0 && cj >= 0 && ci < g->cells[0] && cj < g->cells[1])
						dry |= !f->cell_wet[ci + cj * g->cells[0]];
			f->dirichlet[grid_node(g, i, j)] = (signed char)dry;
		}
	const struct case_boundary *bc = s->spec->boundaries;
	for (idx_t j = 0; j < g->nodes[1]; j++)
		for (idx_t i = 0; i < g->nodes[0]; i++) {
			int drained = (i == 0 && bc[FACE_LEFT].drainage == DRAINAGE_DRAINED) ||
				      (i == g->cells[0] && bc[FACE_RIGHT].drainage == DRAINAGE_DRAINED) ||
				      (j == 0 && bc[FACE_BOTTOM].drainage == DRAINAGE_DRAINED) ||
				      (j == g->cells[1] && bc[FACE_TOP].drainage == DRAINAGE_DRAINED);
			if (drained)
				f->dirichlet[grid_node(g, i, j)] = 1;
		}
}

/* Adds sum_p coef_p grad S_Ip . grad S_Jp into the stencil (Eq. 61). */
static void assemble_laplacian(struct sim *s, const struct particles *p, const double *coef)
{
	const struct grid *g = &s->grid;
	struct pressure_system *ps = &s->ps;
	const int S = p->support, nn = S * S, W = ps->width, R = ps->radius;
	for (idx_t q = 0; q < p->n; q++) {
		const double *dw = p->dw + (size_t)q * 2 * nn;
		const double c = coef[q];
		for (int k = 0; k < nn; k++) {
			const idx_t I = p->node0[q] + k % S + (k / S) * g->nodes[0];
			double *row = ps->stencil + (size_t)I * W * W;
			const double gx = c * dw[2 * k], gy = c * dw[2 * k + 1];
			for (int l = 0; l < nn; l++) {
				int dx = l % S - k % S, dy = l / S - k / S;
				row[(dx + R) + (dy + R) * W] += gx * dw[2 * l] + gy * dw[2 * l + 1];
			}
		}
	}
}

/* Right-hand side (D_s v_s* + D_w v_w*) / dt, Eqs. 62-63 evaluated through the point divergences. */
static void assemble_rhs(struct sim *s)
{
	struct grid_fields *f = &s->f;
	const struct grid *g = &s->grid;
	double *div_s = s->soil_scalar, *div_w = s->water_scalar;
	double *sum_s = f->correction_s, *sum_w = f->correction_w;   /* free until step 6 */
	memset(sum_s, 0, sizeof(double) * (size_t)g->node_count);
	memset(sum_w, 0, sizeof(double) * (size_t)g->node_count);
	g2p_divergence(g, &s->soil, f->v_s_star, div_s);
	p2g_scalar(g, &s->soil, s->soil.volume, div_s, sum_s);
	g2p_divergence(g, &s->water, f->v_w_star, div_w);
	p2g_scalar(g, &s->water, s->water.volume, div_w, sum_w);
	for (idx_t I = 0; I < g->node_count; I++)
		f->rhs[I] = ((1.0 - f->porosity[I]) * sum_s[I] + f->porosity[I] * sum_w[I]) / s->dt;
	memset(sum_s, 0, sizeof(double) * (size_t)g->node_count);
	memset(sum_w, 0, sizeof(double) * (size_t)g->node_count);
}

/* Numbers the unknowns and builds the upper triangle of L in CSC; moves prescribed values to b.
 * The system solved is L dp = (D_s v_s* + D_w v_w*) / dt, Eq. 60 divided by dt. */
static idx_t build_reduced_system(struct sim *s)
{
	const struct grid *g = &s->grid;
	struct grid_fields *f = &s->f;
	struct pressure_system *ps = &s->ps;
	const int W = ps->width, R = ps->radius, centre = R + R * W;
	idx_t n = 0;
	for (idx_t I = 0; I < g->node_count; I++) {
		int active = ps->stencil[(size_t)I * W * W + centre] > 0.0;
		ps->unknown[I] = active && !f->dirichlet[I] ? n++ : -1;
		f->dp[I] = active && f->dirichlet[I] ? -f->pressure[I] : 0.0;
	}
	idx_t nnz = 0;
	for (idx_t J = 0; J < g->node_count; J++) {
		idx_t col = ps->unknown[J];
		if (col < 0)
			continue;
		ps->colptr[col] = nnz;
		double b = f->rhs[J];
		const idx_t i = J % g->nodes[0], j = J / g->nodes[0];
		const double *row = ps->stencil + (size_t)J * W * W;
		for (int dy = -R; dy <= R; dy++)
			for (int dx = -R; dx <= R; dx++) {
				if (i + dx < 0 || i + dx >= g->nodes[0] || j + dy < 0 || j + dy >= g->nodes[1])
					continue;
				const idx_t I = J + dx + dy * g->nodes[0];
				const double L = row[(dx + R) + (dy + R) * W];
				if (ps->unknown[I] >= 0 && ps->unknown[I] <= col) {
					ps->rowidx[nnz] = ps->unknown[I];
					ps->values[nnz++] = L;
				} else if (f->dirichlet[I]) {
					b -= L * f->dp[I];
				}
			}
		ps->b[col] = b;
	}
	ps->colptr[n] = nnz;
	return n;
}

enum poro_status pressure_solve(struct sim *s)
{
	struct pressure_system *ps = &s->ps;
	const struct particles *p = &s->soil, *w = &s->water;
	memset(ps->stencil, 0, sizeof(double) * (size_t)s->grid.node_count * ps->width * ps->width);
	for (idx_t q = 0; q < p->n; q++) {
		const double rho_s = s->materials[s->spec->bodies[p->body[q]].material].density;
		s->soil_coef[q] = p->volume[q] * (1.0 - p->porosity[q]) / rho_s;
	}
	for (idx_t q = 0; q < w->n; q++)
		s->water_coef[q] = w->volume[q] * w->porosity[q] / s->rho_w;
	assemble_laplacian(s, p, s->soil_coef);
	assemble_laplacian(s, w, s->water_coef);
	pressure_mark_dirichlet(s);
	assemble_rhs(s);
	idx_t n = build_reduced_system(s);
	enum poro_status st = spd_solver_solve(ps->solver, n, ps->colptr, ps->rowidx, ps->values, ps->b,
					       ps->x, &s->err);
	if (st)
		return st;
	for (idx_t I = 0; I < s->grid.node_count; I++)
		if (ps->unknown[I] >= 0)
			s->f.dp[I] = ps->x[ps->unknown[I]];
	return PORO_OK;
}
