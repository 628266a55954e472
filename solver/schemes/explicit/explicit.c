/*
 * explicit.c - the explicit stabilised single-point v-w scheme of paper 002 (Tang et al. 2025,
 * §2-3; spec-002.md is its worked reading): both phases' momentum equations solved explicitly on
 * the grid, a compressible pore fluid whose pressure follows the volumetric strain rates (Eq. 9),
 * and two stabilisations: the cell average of the volumetric strain rates (Eqs. 26-27) and the
 * node-based multi-field projection of the pressure rate (Eqs. 28-34). One step is the nine steps
 * of 002 §3.3.
 *
 * Symbols (002 §2): m_s, m_f the points' solid and fluid masses; M_s, M_f their nodal sums; n
 * porosity; k (K_s of the paper) hydraulic conductivity; c_d = n^2 rho_f g / k the Darcy drag
 * coefficient (Eq. 12, with the apparent fluid density: spec-002 §12 E1); C_I = sum S c_d V its
 * nodal sum; v^t, v^L the nodal velocities at the step's start and after the momentum update.
 * Pore pressure is tension positive inside the solver (pi = -p_f).
 *
 * Choices the paper leaves open (spec-002 §5, [C]):
 *  - the drag is integrated implicitly at the nodes by default (backward Euler on the relative
 *    velocity, phase_coupling.h): with the drag explicit, as Eq. 22 prints it, 002 §4.2 is
 *    unstable at its own dt (lambda dt = 6.8, stable_dt.h); formulation.drag "explicit" keeps the
 *    printed form for comparison;
 *  - the velocity constraints hold v^t as well as v^L on constrained components, so their
 *    acceleration, the FLIP increment, is zero there (spec-002 §5 step 3);
 *  - positions move with the step's momentum-updated nodal velocity v_s^L (MUSL practice, E11);
 *  - the fluid body force uses the fluid mass (Eq. 23 prints the solid's: E2);
 *  - the stress update's strain rate is the 3-D split of Eq. 27, zz included (E9);
 *  - a face drains where its water moves freely: the natural condition P = 0 of Eq. 22 (E16).
 * A step that moves a point more than UNSTABLE_CELL_FRACTION of a cell has gone unstable (an
 * explicit scheme past its critical step grows without bound well before a NaN) and stops with
 * the point named, before the state is written anywhere.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "explicit.h"
#include "phase_coupling.h"
#include "phases.h"
#include "scheme.h"
#include "transfer.h"

/* A point that moves this much of a cell in one step has left the scheme's stability: in a stable
 * run the waves cross at most a cell a step and the material moves far slower than they do. */
#define UNSTABLE_CELL_FRACTION 0.5

static void destroy(struct sim *s)
{
	struct explicit_state *e = explicit_of(s);
	if (!e)
		return;
	free(e->drag);
	free(e->rate_moments);
	free(e->rate_nodal);
	free(e->cell_sums);
	free(e->cell);
	free(e->pressure_s);
	free(e->pressure_f);
	free(e->drag_point);
	free(e->grad_n);
	free(e->div_s);
	free(e->div_f);
	free(e->rate_s);
	free(e->rate_f);
	free(e->pressure_rate);
	free(e);
	s->scheme_state = NULL;
}

static enum poro_status create(struct sim *s)
{
	const size_t nodes = (size_t)s->grid.node_count, cells = (size_t)s->grid.cell_count;
	const size_t n = (size_t)s->soil.n + 1;
	struct explicit_state *e = calloc(1, sizeof *e);
	if (!(s->scheme_state = e))
		return poro_error_set(&s->err, PORO_ENOMEM, "cannot allocate the explicit scheme's state");
	/* constant basis: sum S V pdot*, sum S V; linear: the moments of the local linear fit */
	e->rate_width = s->spec->formulation.pressure_rate_basis == PRESSURE_RATE_BASIS_LINEAR ? 9 : 2;
	const int ok = (e->drag = calloc(nodes, sizeof(double))) &&
		       (e->rate_moments = calloc(nodes * (size_t)e->rate_width, sizeof(double))) &&
		       (e->rate_nodal = calloc(3 * nodes, sizeof(double))) &&
		       (e->cell_sums = calloc(4 * cells, sizeof(double))) && (e->cell = calloc(n, sizeof(idx_t))) &&
		       (e->pressure_s = calloc(n, sizeof(double))) && (e->pressure_f = calloc(n, sizeof(double))) &&
		       (e->drag_point = calloc(n, sizeof(double))) && (e->grad_n = calloc(2 * n, sizeof(double))) &&
		       (e->div_s = calloc(n, sizeof(double))) &&
		       (e->div_f = calloc(n, sizeof(double))) && (e->rate_s = calloc(n, sizeof(double))) &&
		       (e->rate_f = calloc(n, sizeof(double))) && (e->pressure_rate = calloc(n, sizeof(double)));
	if (!ok)
		return poro_error_set(&s->err, PORO_ENOMEM, "cannot allocate the explicit scheme's arrays for %ld nodes "
				      "and %ld points", (long)nodes, (long)s->soil.n);
	return particles_add_out_of_plane(&s->soil, &s->err);
}

/* Step 2's per-point coefficients: the fluid mass m_f = n rho_f V, the pressure's shares on the
 * two phases (Eqs. 21, 23) and the drag c_d V (Eq. 12). */
static void point_coefficients(struct sim *s)
{
	struct explicit_state *e = explicit_of(s);
	const struct particles *p = &s->soil;
	struct particles *w = &s->water;
	const double rho_f = s->rho_w;
#pragma omp parallel for schedule(static)
	for (idx_t q = 0; q < p->n; q++) {
		const double n = p->porosity[q], V = p->volume[q], pi = w->pressure[q];
		w->mass[q] = n * rho_f * V;
		e->pressure_s[q] = (1.0 - n) * pi;
		e->pressure_f[q] = n * pi;
		e->drag_point[q] = n * n * rho_f * CONDUCTIVITY_GRAVITY / p->conductivity[q] * V;
	}
}

/* Step 2a: both phases' nodal masses and momenta, the nodal porosity n_I = sum S m_s n / M_s (the
 * buoyancy's, 2b) and the nodal drag C_I of the implicit drag (step 3). */
static void map_masses(struct sim *s)
{
	struct explicit_state *e = explicit_of(s);
	struct grid_fields *f = &s->f;
	const struct grid *g = &s->grid;
	const struct particles *p = &s->soil, *w = &s->water;
	const int implicit_drag = s->spec->formulation.drag == DRAG_IMPLICIT;
	double *Ms = f->mass_s, *Mf = f->mass_w, *Ps = f->v_s, *Pf = f->v_w, *n = f->porosity, *C = e->drag;
	FOR_POINTS_BY_BLOCK(p, q, {   /* a scatter into q's support: in parallel (point_blocks.h) */
		const double ms = p->mass[q], mf = w->mass[q], msn = ms * p->porosity[q];
		const double *vs = p->v + 2 * q, *vf = w->v + 2 * q, cd = implicit_drag ? e->drag_point[q] : 0.0;
		FOR_SUPPORT(g, p, q, {
			Ms[I] += wk * ms;
			Mf[I] += wk * mf;
			n[I] += wk * msn;
			Ps[2 * I] += wk * ms * vs[0];
			Ps[2 * I + 1] += wk * ms * vs[1];
			Pf[2 * I] += wk * mf * vf[0];
			Pf[2 * I + 1] += wk * mf * vf[1];
			C[I] += wk * cd;
		});
	});
	point_map_normalise(g->node_count, n, 1, Ms);
}

/* Step 2b: the internal forces of Eqs. 21 and 23,
 *     f_s = -sum_p V_p (sigma'_p + (1 - n_p) pi_p I) . grad S_Ip,   f_f = -sum_p V_p n_p pi_p grad S_Ip,
 * the weak forms of div sigma_s and div sigma_f (Eqs. 14-15), with the buoyancy f_b = p grad n of
 * Eq. 13 that Eqs. 10-11 add to them: -f_b on the solid and +f_b on the fluid, at each point from
 * the gradient of the nodal porosity. Eqs. 21-23 print no f_b, which leaves the fluid pushed by
 * -grad(n p) = -n grad p - p grad n instead of Eq. 17's -n grad p: where consolidation has made
 * the porosity vary (the top of 002 §4.1.2's column, n from 0.30 to 0.15) that extra push out of
 * the compacted soil drained the column 10-12% of its final settlement ahead of the Gibson
 * solution (docs/numerics.md, "The explicit scheme of paper 002", its buoyancy). The explicit drag, when chosen,
 * takes f_d V = c_d V (v_s - v_f) from the solid and gives it to the fluid (Eq. 22). */
static void map_forces(struct sim *s)
{
	struct explicit_state *e = explicit_of(s);
	struct grid_fields *f = &s->f;
	const struct grid *g = &s->grid;
	const struct particles *p = &s->soil, *w = &s->water;
	const int explicit_drag = s->spec->formulation.drag == DRAG_EXPLICIT;
	const double *n = f->porosity;
	double *Fs = f->force, *Ff = f->force_w;
	FOR_POINTS_BY_BLOCK(p, q, {   /* a scatter into q's support, q's own grad n: in parallel */
		double *grad_n = e->grad_n + 2 * q;
		grad_n[0] = grad_n[1] = 0.0;
		FOR_SUPPORT(g, p, q, {
			grad_n[0] += n[I] * gx;
			grad_n[1] += n[I] * gy;
		});
		const double V = p->volume[q], *vs = p->v + 2 * q, *vf = w->v + 2 * q, *sigma = p->stress + 4 * q;
		const double sxx = V * (sigma[0] + e->pressure_s[q]), syy = V * (sigma[1] + e->pressure_s[q]);
		const double sxy = V * sigma[2], pf = V * e->pressure_f[q], cd = explicit_drag ? e->drag_point[q] : 0.0;
		/* what the solid loses and the fluid gains, per unit S: f_d V + f_b V, p = -pi */
		const double bx = cd * (vs[0] - vf[0]) - V * w->pressure[q] * grad_n[0];
		const double by = cd * (vs[1] - vf[1]) - V * w->pressure[q] * grad_n[1];
		FOR_SUPPORT(g, p, q, {
			Fs[2 * I] -= sxx * gx + sxy * gy + wk * bx;
			Fs[2 * I + 1] -= sxy * gx + syy * gy + wk * by;
			Ff[2 * I] += wk * bx - pf * gx;
			Ff[2 * I + 1] += wk * by - pf * gy;
		});
	});
}

/* Step 2: maps and forces (2a, 2b), the velocities v^t, the tractions. */
static void map_to_grid(struct sim *s)
{
	struct explicit_state *e = explicit_of(s);
	struct grid_fields *f = &s->f;
	const struct grid *g = &s->grid;
	const struct particles *p = &s->soil, *w = &s->water;
	grid_fields_reset(f, g);
	memset(e->drag, 0, sizeof(double) * (size_t)g->node_count);
	point_coefficients(s);
	map_masses(s);
	map_forces(s);
	double *Ms = f->mass_s, *Mf = f->mass_w;
	s->mapped_mass_s = s->mapped_mass_w = 0.0;
	for (idx_t q = 0; q < p->n; q++)
		s->mapped_mass_s += p->mass[q], s->mapped_mass_w += w->mass[q];
	/* momenta to velocities v^t, held on constrained components (file comment) */
	const idx_t nodes = g->node_count;
	point_map_normalise(nodes, f->v_s, DIM, Ms);
	point_map_normalise(nodes, f->v_w, DIM, Mf);
	memcpy(f->mass_w_points, Mf, sizeof(double) * (size_t)nodes);   /* sim_grid_masses' water sum */
	boundary_apply(g, f->fix_s, f->v_s);
	boundary_apply(g, f->fix_w, f->v_w);
	loads_add_tractions(s, s->time + s->dt, f->force);   /* T_s of Eq. 22, on the solid */
}

/* Step 3: the nodal momentum equations of both phases (Eqs. 20, 23) over the step, with the body
 * force M b (Eqs. 22-23) and the drag. With the implicit drag the relative velocity is taken at
 * the step's end:
 *     M_s (v_s^L - v_s) = dt (F_s - C (v_s^L - v_f^L)),   M_f (v_f^L - v_f) = dt (F_f + C (v_s^L - v_f^L)),
 * the 2x2 system of phase_coupling.h per node and component (D = C dt), stable at any
 * permeability; a constrained or massless phase keeps v = 0 and the other feels the drag against
 * it. With the explicit drag D = 0 and the drag is in F already. v^t goes to v_s_old, v_w_old for
 * the FLIP increment; v^L to v_s, v_w. */
static void integrate_nodes(struct sim *s)
{
	struct explicit_state *e = explicit_of(s);
	struct grid_fields *f = &s->f;
	const idx_t nodes = s->grid.node_count;
	const double dt = s->dt, *b = s->gravity;
	const int implicit_drag = s->spec->formulation.drag == DRAG_IMPLICIT;
	memcpy(f->v_s_old, f->v_s, sizeof(double) * DIM * (size_t)nodes);
	memcpy(f->v_w_old, f->v_w, sizeof(double) * DIM * (size_t)nodes);
#pragma omp parallel for schedule(static)
	for (idx_t I = 0; I < nodes; I++) {
		const double Ms = f->mass_s[I], Mf = f->mass_w[I], C = implicit_drag ? e->drag[I] : 0.0;
		for (int c = 0; c < DIM; c++) {
			const idx_t k = DIM * I + c;
			const double relative = f->v_s[k] - f->v_w[k];
			const double fs = dt * (f->force[k] + Ms * b[c] - C * relative);
			const double ff = dt * (f->force_w[k] + Mf * b[c] + C * relative);
			const struct phase_coupling K = phase_coupling_inverse(Ms, Mf, C * dt, f->fix_s[I] & (1 << c),
									       f->fix_w[I] & (1 << c));
			f->v_s[k] = Ms > 0.0 ? f->v_s[k] + K.ss * fs + K.sw * ff : 0.0;
			f->v_w[k] = Mf > 0.0 ? f->v_w[k] + K.sw * fs + K.ww * ff : 0.0;
		}
	}
}

/* Step 5: the MUSL remap, v_I = sum_p S_Ip m_p v_p / M_I for both phases, with the constraints:
 * the strain rates of step 6 come from the points' updated velocities. */
static void remap_velocities(struct sim *s)
{
	struct grid_fields *f = &s->f;
	const struct grid *g = &s->grid;
	const size_t bytes = sizeof(double) * DIM * (size_t)g->node_count;
	memset(f->v_s, 0, bytes);
	memset(f->v_w, 0, bytes);
	point_map_momentum(s, &s->soil, f->v_s);
	point_map_momentum(s, &s->water, f->v_w);
	point_map_normalise(g->node_count, f->v_s, DIM, f->mass_s);
	point_map_normalise(g->node_count, f->v_w, DIM, f->mass_w);
	boundary_apply(g, f->fix_s, f->v_s);
	boundary_apply(g, f->fix_w, f->v_w);
}

/* Fails naming the first point that moved more than UNSTABLE_CELL_FRACTION of a cell in the step. */
static enum poro_status check_motion(struct sim *s)
{
	const struct particles *p = &s->soil, *w = &s->water;
	const double limit = UNSTABLE_CELL_FRACTION * s->grid.h / s->dt;
	idx_t bad = p->n;   /* the lowest such point, as a serial search would find it */
#pragma omp parallel for schedule(static) reduction(min : bad)
	for (idx_t q = 0; q < p->n; q++)
		if (q < bad && !(hypot(p->v[2 * q], p->v[2 * q + 1]) <= limit &&
				 hypot(w->v[2 * q], w->v[2 * q + 1]) <= limit))
			bad = q;
	if (bad == p->n)
		return PORO_OK;
	const char *phase = hypot(p->v[2 * bad], p->v[2 * bad + 1]) <= limit ? "fluid" : "solid";
	const double *v = (phase[0] == 's' ? p->v : w->v) + 2 * bad;
	return poro_error_set(&s->err, PORO_ESOLVER, "soil point %ld at (%.6g, %.6g) m: its %s velocity %.6g m/s "
			      "moves it more than %g of a cell in one step at step %ld (t = %.6g s): the explicit "
			      "step has gone unstable", (long)bad, p->x[2 * bad], p->x[2 * bad + 1], phase,
			      hypot(v[0], v[1]), UNSTABLE_CELL_FRACTION, s->step + 1, s->time + s->dt);
}

static enum poro_status explicit_step(struct sim *s)
{
	struct explicit_state *e = explicit_of(s);
	enum poro_status st = PORO_OK;
	loads_gravity(s->spec, s->time + s->dt, s->gravity);
	PHASE(PHASE_SHAPE, {                                                  /* (1) */
		st = point_map_shapes(s);
		if (!st)
			explicit_locate_cells(s);
	});
	if (st)
		return st;
	PHASE(PHASE_P2G, map_to_grid(s));                                     /* (2) Eqs. 20-23 */
	PHASE(PHASE_PREDICT, integrate_nodes(s));                             /* (3) */
	PHASE(PHASE_G2P, {                                                    /* (4), (8) positions */
		point_motion_update(s, &s->soil, s->f.v_s, s->f.v_s_old, 1);
		point_motion_update(s, &s->water, s->f.v_w, s->f.v_w_old, 0);
		st = check_motion(s);
	});
	if (st)
		return st;
	PHASE(PHASE_CORRECT, remap_velocities(s));                            /* (5) */
	PHASE(PHASE_KINEMATICS, explicit_strain_rates(s));                    /* (6) Eqs. 24-27 */
	PHASE(PHASE_PRESSURE_ASSEMBLY, explicit_pressure_rate(s));            /* (7) Eqs. 9, 28-34 */
	PHASE(PHASE_KINEMATICS, st = deformation_apply_volumetric(s, e->rate_s));   /* (8) V, n, k */
	if (st)
		return st;
	PHASE(PHASE_STRESS, st = stress_update(s));                           /* (7) sigma' */
	if (st)
		return st;
	s->time = (double)(s->step + 1) * s->dt;   /* no drift from summing dt */
	s->step++;
	return PORO_OK;
}

const struct scheme explicit_scheme = {
	.name = "explicit",
	.phase_names = { "shape functions", "particle-to-grid", "nodal momentum", "pressure rate", NULL,
			 "MUSL remap", "grid-to-particle", "strain rates, volumes", "stress update" },
	.create = create,
	.destroy = destroy,
	.step = explicit_step,
};
