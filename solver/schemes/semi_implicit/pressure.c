/*
 * pressure.c - the pore-pressure increment of the semi-implicit scheme (000 §4.5 step 5): the
 * pressure matrix and right-hand side, and the solve (the free surface, step 5b, is marked before
 * the predictors: free_surface.c, semi_implicit.c).
 *
 * Two matrices are offered (case key formulation.pressure_projection):
 *  - "laplacian" (default, the paper): L dp = (D_s v_s* + D_w v_w*) / dt, Eqs. 60-63. L (Eq. 61) is
 *    assembled as sum_p c_p grad S_Ip . grad S_Jp with c_p = V_sp (1 - n_sp) / rho_s for soil points
 *    and V_wp n_wp / rho_w for water points. The paper writes the porosity as a nodal factor of
 *    row I, which makes L unsymmetric wherever porosity varies; keeping it inside the sum is the
 *    Galerkin discretisation of Eq. 32 (where n^t is inside the integral), equal to the paper's
 *    form for uniform porosity, and keeps L symmetric positive definite for CHOLMOD. D_s, D_w keep
 *    the paper's nodal porosity factors.
 *  - "consistent": A dp = -sum_a G_a^T v_a* / dt with A = sum_a G_a^T M_a^-1 G_a over the free
 *    velocity components, G_a the gradient operators of the correction (Eqs. 67-68). The corrected
 *    velocities then satisfy the weak continuity equation -G^T v = 0 exactly, and the pressure
 *    forces of the predictors use the same G on the nodal pressure, so a pressure error is removed
 *    in one step instead of being fed back (docs/numerics.md has the measurements).
 *    Equal-order B-splines leave a node-to-node pressure pattern nearly outside A's reach (on a
 *    regular seeding exactly: G of the alternation vanishes wherever the points are symmetric
 *    about the nodes, pressure_test), and the solve gives it whatever the near-null ratio of the
 *    right-hand side to its eigenvalue is, every step afresh: the failing Mohr-Coulomb slopes
 *    show it as stripes of period two cells (docs/numerics.md, "A pressure pattern of period two
 *    cells"). The case may hold it down with formulation.pressure_stabilisation
 *    (pressure_stabilisation.c).
 *
 * Boundary conditions: impermeable faces need nothing (the natural condition of Eq. 32). Where
 * the pressure is zero, on the free water surface and on drained faces, free_surface.c decides,
 * and how it is held: prescribed nodes get p^{t+1} = 0, i.e. dp_I = -p^t_I; with the
 * interpolated condition its penalty is added to the matrix once the unknowns are numbered.
 */
#include <assert.h>
#include <stdlib.h>
#include <string.h>

#include "phase_coupling.h"
#include "semi_implicit.h"
#include "transfer.h"

enum poro_status pressure_system_init(struct pressure_system *ps, const struct grid *g, int support,
				      enum pressure_projection projection, int surface_points, struct poro_error *err)
{
	memset(ps, 0, sizeof *ps);
	ps->exact = projection == PROJECTION_CONSISTENT;
	ps->g_radius = support - 1;
	ps->g_width = 2 * ps->g_radius + 1;
	ps->radius = ps->exact ? 2 * ps->g_radius : ps->g_radius;
	ps->width = 2 * ps->radius + 1;
	const size_t nodes = (size_t)g->node_count, st = (size_t)ps->width * ps->width;
	const size_t gst = (size_t)ps->g_width * ps->g_width * 2;
	const size_t nnz_max = nodes * (st + 1) / 2;
	ps->stencil = calloc(nodes * st, sizeof(double));
	ps->unknown = malloc(nodes * sizeof(idx_t));
	ps->colptr = malloc((nodes + 1) * sizeof(idx_t));
	ps->rowidx = malloc(nnz_max * sizeof(idx_t));
	ps->values = malloc(nnz_max * sizeof(double));
	ps->b = malloc(nodes * sizeof(double));
	ps->x = malloc(nodes * sizeof(double));
	int ok = ps->stencil && ps->unknown && ps->colptr && ps->rowidx && ps->values && ps->b && ps->x;
	if (ps->exact) {   /* G_s, G_w, the coupling and the stabilisation's arrays */
		ps->grad_s = calloc(nodes * gst, sizeof(double));
		ps->grad_w = calloc(nodes * gst, sizeof(double));
		ps->coupling = calloc(nodes * 6, sizeof(double));
		ps->diagonal = malloc(nodes * sizeof(double));
		ps->interior = malloc(nodes);
		ok = ok && ps->grad_s && ps->grad_w && ps->coupling && ps->diagonal && ps->interior;
	}
	if (surface_points) {   /* at most two surface points on each of a full cell's four faces */
		ps->sample_max = 8 * (idx_t)g->cell_count;
		ps->samples = malloc(2 * (size_t)ps->sample_max * sizeof(double));
		ps->sample_normal = malloc(2 * (size_t)ps->sample_max * sizeof(double));
		ok = ok && ps->samples && ps->sample_normal;
	}
	if (!ok) {
		pressure_system_release(ps);
		return poro_error_set(err, PORO_ENOMEM, "cannot allocate the pressure system");
	}
	return spd_solver_create(&ps->solver, (idx_t)nodes, (idx_t)nnz_max, err);
}

void pressure_system_release(struct pressure_system *ps)
{
	free(ps->stencil);
	free(ps->grad_s);
	free(ps->grad_w);
	free(ps->coupling);
	free(ps->unknown);
	free(ps->colptr);
	free(ps->rowidx);
	free(ps->values);
	free(ps->b);
	free(ps->x);
	free(ps->diagonal);
	free(ps->interior);
	free(ps->samples);
	free(ps->sample_normal);
	spd_solver_destroy(&ps->solver);
	memset(ps, 0, sizeof *ps);
}

/* A point's shape-function gradients over its support, grad S_Jp = (dx wy, wx dy) for J = lx + ly S,
 * formed once per point: the stencil loops below then read them from registers rather than
 * re-forming them for every row I (the compiler cannot hoist the products itself, since the
 * stencil stores might alias the shape cache). The products are the same, so are the sums. */
static inline void support_gradients(const struct shape_factors f, const int S, double *gx, double *gy)
{
	for (int ly = 0; ly < S; ly++)
		for (int lx = 0; lx < S; lx++) {
			gx[lx + ly * S] = f.dx[lx] * f.wy[ly];
			gy[lx + ly * S] = f.wx[lx] * f.dy[ly];
		}
}

/* Point q's terms of Eq. 61, c_q grad S_Iq . grad S_Jq, for a support of S nodes per direction;
 * called with S constant so that the quadratic B-spline's copy is unrolled. */
static inline void add_point_laplacian(struct pressure_system *ps, idx_t nx, const struct particles *p, idx_t q,
				       double c, const int S)
{
	const int W = ps->width, R = ps->radius;
	const struct shape_factors f = particle_shape(p, q);
	double gxJ[SHAPE_NODES_MAX], gyJ[SHAPE_NODES_MAX];
	support_gradients(f, S, gxJ, gyJ);
	for (int ky = 0; ky < S; ky++)
		for (int kx = 0; kx < S; kx++) {
			const idx_t I = p->node0[q] + kx + ky * nx;
			double *row = ps->stencil + (size_t)I * W * W;
			const double gx = c * gxJ[kx + ky * S], gy = c * gyJ[kx + ky * S];
			for (int ly = 0; ly < S; ly++) {   /* one grid line of J: adjacent entries */
				double *dst = row + (R - kx) + (ly - ky + R) * W;
				for (int lx = 0; lx < S; lx++)
					dst[lx] += gx * gxJ[lx + ly * S] + gy * gyJ[lx + ly * S];
			}
		}
}

/* Adds sum_p coef_p grad S_Ip . grad S_Jp into the stencil (Eq. 61). A point writes the rows of
 * its support nodes only, so the points run in the scatters' block order (point_blocks.h): in
 * parallel, and every entry the same bit for bit at any thread count. */
static void assemble_laplacian(struct sim *s, const struct particles *p, const double *coef)
{
	struct semi_implicit *si = semi_implicit_of(s);
	const idx_t nx = s->grid.nodes[0];
	FOR_POINTS_BY_BLOCK(p, q, {
		if (p->support == 3)
			add_point_laplacian(&si->ps, nx, p, q, coef[q], 3);
		else
			add_point_laplacian(&si->ps, nx, p, q, coef[q], p->support);
	});
}

/* Point q's terms of G_IJ = sum_p V_p S_Ip grad S_Jp (before the nodal porosity factor), for a
 * support of S nodes per direction (constant in the unrolled copy, as above). */
static inline void add_point_gradient(const struct pressure_system *ps, idx_t nx, const struct particles *p,
				      idx_t q, double *G, const int S)
{
	const int W = ps->g_width, R = ps->g_radius;
	const struct shape_factors f = particle_shape(p, q);
	double gxJ[SHAPE_NODES_MAX], gyJ[SHAPE_NODES_MAX];
	support_gradients(f, S, gxJ, gyJ);
	const double V = p->volume[q];
	for (int ky = 0; ky < S; ky++)
		for (int kx = 0; kx < S; kx++) {
			const idx_t I = p->node0[q] + kx + ky * nx;
			double *row = G + (size_t)I * W * W * 2;
			const double vs = V * (f.wx[kx] * f.wy[ky]);
			/* the support nodes J of one grid line are adjacent in the row: 2 S
			 * contiguous entries per line */
			for (int ly = 0; ly < S; ly++) {
				double *dst = row + 2 * ((R - kx) + (ly - ky + R) * W);
				for (int lx = 0; lx < S; lx++) {
					dst[2 * lx] += vs * gxJ[lx + ly * S];
					dst[2 * lx + 1] += vs * gyJ[lx + ly * S];
				}
			}
		}
}

/* G_IJ = f_I sum_p V_p S_Ip grad S_Jp for one set (Eqs. 67-68 before the nodal porosity factor),
 * in the scatters' block order, as the Laplacian above. */
static void add_gradient_operator(const struct sim *s, const struct particles *p, double *G)
{
	struct semi_implicit *si = semi_implicit_of(s);
	const idx_t nx = s->grid.nodes[0];
	FOR_POINTS_BY_BLOCK(p, q, {
		if (p->support == 3)
			add_point_gradient(&si->ps, nx, p, q, G, 3);
		else
			add_point_gradient(&si->ps, nx, p, q, G, p->support);
	});
}

void pressure_gradient_operators(struct sim *s)
{
	struct semi_implicit *si = semi_implicit_of(s);
	struct pressure_system *ps = &si->ps;
	const size_t gst = (size_t)ps->g_width * ps->g_width * 2, nodes = (size_t)s->grid.node_count;
	grid_zero(ps->grad_s, nodes * gst);
	grid_zero(ps->grad_w, nodes * gst);
	const struct particles wet = semi_implicit_wet_soil(s);   /* dry bodies feel no pore pressure */
	add_gradient_operator(s, &wet, ps->grad_s);
	add_gradient_operator(s, &s->water, ps->grad_w);
	if (s->spec->formulation.free_surface == FREE_SURFACE_WEAK) {   /* free_surface.c */
		free_surface_add_boundary_term(s, s->f.mass_s, ps->grad_s);
		free_surface_add_boundary_term(s, s->f.mass_w, ps->grad_w);
	}
	#pragma omp parallel for schedule(static)
	for (size_t I = 0; I < nodes; I++) {
		const double n = s->f.porosity[I];
		for (size_t k = 0; k < gst; k++) {
			ps->grad_s[I * gst + k] *= 1.0 - n;
			ps->grad_w[I * gst + k] *= n;
		}
	}
}

void pressure_apply_gradient(const struct sim *s, const double *G, const double *pressure, double *out)
{
	struct semi_implicit *si = semi_implicit_of(s);
	const struct grid *g = &s->grid;
	const int W = si->ps.g_width, R = si->ps.g_radius;
	#pragma omp parallel for schedule(static)
	for (idx_t I = 0; I < g->node_count; I++) {
		const idx_t i = I % g->nodes[0], j = I / g->nodes[0];
		const double *row = G + (size_t)I * W * W * 2;
		double fx = 0.0, fy = 0.0;
		for (int dy = -R; dy <= R; dy++)
			for (int dx = -R; dx <= R; dx++) {
				if (i + dx < 0 || i + dx >= g->nodes[0] || j + dy < 0 || j + dy >= g->nodes[1])
					continue;
				const int off = (dx + R) + (dy + R) * W;
				const double pJ = pressure[I + dx + dy * g->nodes[0]];
				fx += row[2 * off] * pJ;
				fy += row[2 * off + 1] * pJ;
			}
		out[2 * I] += fx;
		out[2 * I + 1] += fy;
	}
}

/* The drag the correction applies at node I (zero when formulation.drag_in_correction is off). */
static double correction_drag(const struct sim *s, idx_t I)
{
	struct semi_implicit *si = semi_implicit_of(s);
	return s->spec->formulation.drag_in_correction ? si->drag_dt[I] : 0.0;
}

/* K^-1 (ss, sw, ww) of the correction at every node and component, into ps->coupling. */
static void store_correction_coupling(struct sim *s)
{
	struct semi_implicit *si = semi_implicit_of(s);
	const struct grid_fields *f = &s->f;
	double *k = si->ps.coupling;
	#pragma omp parallel for schedule(static)
	for (idx_t I = 0; I < s->grid.node_count; I++)
		for (int c = 0; c < 2; c++) {
			const struct phase_coupling K = phase_coupling_inverse(f->mass_s[I], f->mass_w[I],
									       correction_drag(s, I), f->fix_s[I] & (1 << c),
									       f->fix_w[I] & (1 << c));
			double *kc = k + 6 * (size_t)I + 3 * c;
			kc[0] = K.ss, kc[1] = K.sw, kc[2] = K.ww;
		}
}

/* A = sum over nodes and velocity components of [G_s; G_w]^T K^-1 [G_s; G_w], K^-1 the phase
 * coupling of the correction (phase_coupling.h; without drag, G_s^T M_s^-1 G_s + G_w^T M_w^-1 G_w),
 * and b = -sum (G_s^T v_s* + G_w^T v_w*) / dt over the free components: the projection that
 * makes the corrected velocities satisfy -G^T v = 0 exactly. A is SPD because K^-1 is.
 *
 * Assembled row by row: row P gathers from the velocity nodes I whose G rows reach P, so each
 * thread writes only its own rows and a row stays in cache while it fills (scattering from I
 * into nine rows was bound by memory latency: 0.58 us per material-point step on the benchmark
 * block). I runs in ascending order and the components inside it, the order the scatter had, so
 * every entry sums the same terms in the same order. */
static void assemble_exact_projection(struct sim *s)
{
	struct semi_implicit *si = semi_implicit_of(s);
	const struct grid *g = &s->grid;
	struct pressure_system *ps = &si->ps;
	const int Wg = ps->g_width, Rg = ps->g_radius, W = ps->width, R = ps->radius;
	const idx_t nx = g->nodes[0], ny = g->nodes[1];
	/* node offsets (x, y) of the G stencil entries, tabulated once */
	enum { G_OFFSETS_MAX = (2 * SHAPE_SUPPORT_MAX - 1) * (2 * SHAPE_SUPPORT_MAX - 1) };
	int ox[G_OFFSETS_MAX], oy[G_OFFSETS_MAX];
	assert(Wg * Wg <= G_OFFSETS_MAX);
	for (int a = 0; a < Wg * Wg; a++)
		ox[a] = a % Wg - Rg, oy[a] = a / Wg - Rg;
	store_correction_coupling(s);
	#pragma omp parallel for schedule(static)
	for (idx_t P = 0; P < g->node_count; P++) {
		const idx_t pi = P % nx, pj = P / nx;
		double *prow = ps->stencil + (size_t)P * W * W;
		double b = 0.0;
		for (int a = Wg * Wg - 1; a >= 0; a--) {   /* P = I + offset a: I ascending */
			const int ax = ox[a], ay = oy[a];
			const idx_t i = pi - ax, j = pj - ay;
			if (i < 0 || i >= nx || j < 0 || j >= ny)
				continue;
			const idx_t I = i + j * nx;
			const double *gs = ps->grad_s + (size_t)I * Wg * Wg * 2, *gw = ps->grad_w + (size_t)I * Wg * Wg * 2;
			double ts[2] = {0.0, 0.0}, tw[2] = {0.0, 0.0};
			int active = 0;
			for (int c = 0; c < 2; c++) {
				const double *K = ps->coupling + 6 * (size_t)I + 3 * c;   /* ss, sw, ww */
				const double gsa = gs[2 * a + c], gwa = gw[2 * a + c];
				if ((K[0] == 0.0 && K[2] == 0.0) || (gsa == 0.0 && gwa == 0.0))
					continue;
				const double vs = K[0] > 0.0 ? si->v_s_star[2 * I + c] : 0.0;
				const double vw = K[2] > 0.0 ? si->v_w_star[2 * I + c] : 0.0;
				b -= (gsa * vs + gwa * vw) / s->dt;
				/* row a of K^-1 [G_s; G_w], to be contracted with the column of each bb */
				ts[c] = K[0] * gsa + K[1] * gwa, tw[c] = K[1] * gsa + K[2] * gwa;
				active = 1;
			}
			if (!active)
				continue;
			const int inside = i >= Rg && i < nx - Rg && j >= Rg && j < ny - Rg;
			double *row = prow + (R - ax) + (R - ay) * W;
			for (int bb = 0; bb < Wg * Wg; bb++) {
				const int bx = ox[bb], by = oy[bb];
				if (!inside && (i + bx < 0 || i + bx >= nx || j + by < 0 || j + by >= ny))
					continue;
				/* the x then the y component, the order in which they were always added */
				double *e = row + bx + by * W;
				*e = (*e + (ts[0] * gs[2 * bb] + tw[0] * gw[2 * bb])) +
				     (ts[1] * gs[2 * bb + 1] + tw[1] * gw[2 * bb + 1]);
			}
		}
		si->rhs[P] += b;
	}
}

/* The Laplacian of Eq. 61 weights the soil by (1 - n) / rho_s and the water by n / rho_w: the
 * mobilities of decoupled phases. With drag in the correction, the mixture's mobility at a node
 * is (1-n, n) K^-1 (1-n, n)^T (phase_coupling.h), which tends to 1 / (M_s + M_w) as k -> 0. Each
 * point's coefficient is scaled by the ratio of the two, interpolated from the nodes. */
static void scale_by_mobility_ratio(struct sim *s, const struct particles *p, double *coef, double *scratch)
{
	struct semi_implicit *si = semi_implicit_of(s);
	struct grid_fields *f = &s->f;
	if (!s->spec->formulation.drag_in_correction)
		return;
	#pragma omp parallel for schedule(static)
	for (idx_t I = 0; I < s->grid.node_count; I++) {
		const double n = f->porosity[I], Ms = f->mass_s[I], Mw = f->mass_w[I];
		si->mobility_ratio[I] = 1.0;
		if (!(Ms > 0.0 && Mw > 0.0))
			continue;
		const struct phase_coupling K = phase_coupling_inverse(Ms, Mw, si->drag_dt[I], 0, 0);
		const double with_drag = (1 - n) * (1 - n) * K.ss + 2 * n * (1 - n) * K.sw + n * n * K.ww;
		si->mobility_ratio[I] = with_drag / ((1 - n) * (1 - n) / Ms + n * n / Mw);
	}
	g2p_scalar(&s->grid, p, si->mobility_ratio, scratch);
	#pragma omp parallel for schedule(static)
	for (idx_t q = 0; q < p->n; q++)
		coef[q] *= scratch[q];
}

/* Right-hand side (D_s v_s + D_w v_w) / dt, Eqs. 62-63 evaluated through the point divergences. */
void pressure_divergence_rhs(struct sim *s, const double *v_s, const double *v_w, double *out)
{
	struct semi_implicit *si = semi_implicit_of(s);
	struct grid_fields *f = &s->f;
	const struct grid *g = &s->grid;
	double *sum_s = si->correction_s, *sum_w = si->correction_w;   /* free until step 6 */
	const struct particles wet = semi_implicit_wet_soil(s);   /* a dry body's volume change needs no water */
	memset(sum_s, 0, sizeof(double) * (size_t)g->node_count);
	memset(sum_w, 0, sizeof(double) * (size_t)g->node_count);
	p2g_point_divergence(g, &wet, wet.volume, v_s, sum_s);
	p2g_point_divergence(g, &s->water, s->water.volume, v_w, sum_w);
	#pragma omp parallel for schedule(static)
	for (idx_t I = 0; I < g->node_count; I++)
		out[I] = ((1.0 - f->porosity[I]) * sum_s[I] + f->porosity[I] * sum_w[I]) / s->dt;
	memset(sum_s, 0, sizeof(double) * (size_t)g->node_count);
	memset(sum_w, 0, sizeof(double) * (size_t)g->node_count);
}

/* Numbers the unknowns, adds the interpolated free-surface condition (free_surface.c) with its
 * weight scaled by `diagonal_mean`, and builds the upper triangle of L in CSC; moves prescribed
 * values to b. The system solved is L dp = (D_s v_s* + D_w v_w*) / dt, Eq. 60 divided by dt. */
static idx_t build_reduced_system(struct sim *s, double diagonal_mean)
{
	struct semi_implicit *si = semi_implicit_of(s);
	const struct grid *g = &s->grid;
	struct grid_fields *f = &s->f;
	struct pressure_system *ps = &si->ps;
	const int W = ps->width, R = ps->radius, centre = R + R * W;
	/* the consistent projection solves for the multiplier p^t + dp itself, so its boundary
	 * value must be reached through dp */
	const int remap = s->spec->formulation.pore_pressure_smoothing && !ps->exact;
	idx_t n = 0;
	for (idx_t I = 0; I < g->node_count; I++) {
		int active = ps->stencil[(size_t)I * W * W + centre] > 0.0;
		ps->unknown[I] = active && !si->dirichlet[I] ? n++ : -1;
		/* with the smoothing of step 7c the prescribed p^{t+1} = 0 is set on the nodal pressure
		 * itself (semi_implicit.c), and the increment the correction sees there is zero: the
		 * nodal p^t of a boundary node is a projection of the nearby points' pressures, not a
		 * pressure the boundary had, and subtracting it every step drives water through drained
		 * faces several times faster than Darcy's law */
		si->dp[I] = active && si->dirichlet[I] && !remap ? -f->pressure[I] : 0.0;
	}
	free_surface_add_penalty(s, diagonal_mean);
	idx_t nnz = 0;
	for (idx_t J = 0; J < g->node_count; J++) {
		idx_t col = ps->unknown[J];
		if (col < 0)
			continue;
		ps->colptr[col] = nnz;
		double b = si->rhs[J];
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
				} else if (si->dirichlet[I]) {
					b -= L * si->dp[I];
				}
			}
		ps->b[col] = b;
	}
	ps->colptr[n] = nnz;
	return n;
}

/* The mean of the matrix's positive diagonal entries: the scale of the surface penalty. */
static double mean_diagonal(const struct sim *s)
{
	struct semi_implicit *si = semi_implicit_of(s);
	const struct pressure_system *ps = &si->ps;
	const int W = ps->width, centre = ps->radius + ps->radius * W;
	double sum = 0.0;
	idx_t count = 0;
	for (idx_t I = 0; I < s->grid.node_count; I++) {
		const double d = ps->stencil[(size_t)I * W * W + centre];
		if (d > 0.0)
			sum += d, count++;
	}
	return count ? sum / (double)count : 0.0;
}

enum poro_status pressure_solve(struct sim *s)
{
	struct semi_implicit *si = semi_implicit_of(s);
	struct pressure_system *ps = &si->ps;
	const struct particles wet = semi_implicit_wet_soil(s), *p = &wet, *w = &s->water;
	double t0 = sim_clock();
	grid_zero(ps->stencil, (size_t)s->grid.node_count * ps->width * ps->width);
	double diagonal_mean = 0.0;
	if (ps->exact) {
		memset(si->rhs, 0, sizeof(double) * (size_t)s->grid.node_count);
		assemble_exact_projection(s);
		if (ps->samples)   /* the interpolated free surface's scale, before any penalty */
			diagonal_mean = mean_diagonal(s);
		pressure_stabilise(s);   /* pressure_stabilisation.c */
	} else {
		#pragma omp parallel for schedule(static)
		for (idx_t q = 0; q < p->n; q++) {
			const double rho_s = s->materials[s->spec->bodies[p->body[q]].material].density;
			s->soil_coef[q] = p->volume[q] * (1.0 - p->porosity[q]) / rho_s;
		}
		#pragma omp parallel for schedule(static)
		for (idx_t q = 0; q < w->n; q++)
			s->water_coef[q] = w->volume[q] * w->porosity[q] / s->rho_w;
		scale_by_mobility_ratio(s, p, s->soil_coef, s->soil_scalar);
		scale_by_mobility_ratio(s, w, s->water_coef, s->water_scalar);
		assemble_laplacian(s, p, s->soil_coef);
		assemble_laplacian(s, w, s->water_coef);
		pressure_divergence_rhs(s, si->v_s_star, si->v_w_star, si->rhs);
	}
	cavitation_add_storage(s);   /* cavitation.c */
	idx_t n = build_reduced_system(s, diagonal_mean);
	double t1 = sim_clock();
	s->phase_seconds[PHASE_PRESSURE_ASSEMBLY] += t1 - t0;
	enum poro_status st = spd_solver_solve(ps->solver, n, ps->colptr, ps->rowidx, ps->values, ps->b,
					       ps->x, &s->err);
	s->phase_seconds[PHASE_PRESSURE_SOLVE] += sim_clock() - t1;
	if (st)
		return st;
	#pragma omp parallel for schedule(static)
	for (idx_t I = 0; I < s->grid.node_count; I++)
		if (ps->unknown[I] >= 0)
			si->dp[I] = ps->x[ps->unknown[I]];
	return si->plate_work ? plate_couple_pressure(s, n) : PORO_OK;   /* rigid plates: plate.c */
}
