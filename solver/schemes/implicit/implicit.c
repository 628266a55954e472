/*
 * implicit.c - paper 001's fully implicit u-p-U scheme (Zheng, Pisanò, Vardon and Hicks 2022, §2;
 * spec-001.md is its worked reading): the solid's displacement, the pore pressure and the water's
 * displacement solved together each step by Newmark's average acceleration (Eqs. 7-9) and the
 * modified Newton-Raphson method, then carried to the points (Eq. 11). One step is spec-001 §5:
 *
 *   1. shapes at x_n (uGIMP) and the B-bar factors (Eqs. 12-16)
 *   2. the unknowns: which are active, which held (constraints; p = 0 where the soil drains)
 *   3. the step-start nodal velocities and accelerations, mass-weighted from the points
 *   4. the Newmark matrix K = M / (beta dt^2) + gamma C / (beta dt) + K (Eq. 9) at x_n, factorised
 *   5. the loads at t_{n+1}
 *   6-7. the Newton loop: r = f_{n+1} - f_int - M a_{n+1} - C v_{n+1}, K delta = r, until the
 *      energy |delta . r| falls below newton_tolerance of the first iteration's
 *   8-9. the points: accelerations (11a-b), velocities (11c), stress (11d), pore pressure (MLSA
 *      recovery, replacing 11e), positions (11f), volumes and porosity
 *
 * Convergence (spec-001 §4.2; 001 gives no tolerance): an iteration has converged when
 * |delta^k . r^k| <= newton_tolerance |delta^0 . r^0| and the largest displacement correction is
 * at most DISPLACEMENT_TOLERANCE h (the solid's: spec-001 §4.2) or the largest residual at most
 * RESIDUAL_TOLERANCE of the step's force scale, or when the residual has fallen
 * to RESIDUAL_FLOOR of that scale (a state already in equilibrium, where the energy of the first iteration is
 * round-off itself). A step that has not converged after newton_max_iterations stops the run with
 * the step, the iteration count and the last energy ratio named, exit status 3 (001 gives no
 * cut-back). The run's last checkpoint is left as it was; it resumes only the case it was written
 * for, so a smaller dt or the consistent tangent is a new run (tests/cli/newton_failure_test.sh).
 *
 * The tangent: the elastic D of every point (001 A.1f), factorised once a step: the modified
 * Newton-Raphson of 001 §2.2, which converges linearly once points yield; or, with formulation
 * tangent "consistent", the materials' consistent tangents (material.h) at the current iterate,
 * refactorised every iteration: full Newton, quadratic near the solution.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "implicit.h"
#include "phases.h"
#include "scheme.h"
#include "transfer.h"

/* A nodal mass below this share of the largest leaves the node's unknowns out of the problem
 * (spec-001 §3.5): uGIMP's weights reach a node with a sliver of a point's domain. */
#define ACTIVE_MASS_SHARE 1e-9
/* A cell whose points' volumes fill less than this share of it is open to the air: the nodes
 * around it drain (spec-001 §3.5, 000 step 5b's FREE_SURFACE_FILL). */
#define DRAINED_FILL 0.5
/* The displacement correction of a converged iteration, in cells (spec-001 §4.2). */
#define DISPLACEMENT_TOLERANCE 1e-8
/* A residual this small against the step's forces is equilibrium whatever the energy ratio. */
#define RESIDUAL_FLOOR 1e-12
/* Below this share of the step's forces the residual stands in for the displacement test once the
 * energy test holds: along a mechanism forming under a footing or in a slope the stiffness nearly
 * vanishes, and the corrections stayed above 1e-8 h for 100 iterations with the energy at 1e-14
 * to 1e-20 of the first's and the residual at 1e-6 to 5e-4 N/m, stopping 001's footings and slopes
 * before their limit loads (docs/numerics.md, "Convergence"). */
#define RESIDUAL_TOLERANCE 1e-6

static void destroy(struct sim *s)
{
	struct implicit_state *e = implicit_of(s);
	if (!e)
		return;
	implicit_system_release(e);
	free(e->kind);
	free(e->prescribed);
	free(e->increment);
	free(e->delta);
	free(e->residual);
	free(e->external);
	free(e->velocity);
	free(e->acceleration);
	free(e->velocity_new);
	free(e->acceleration_new);
	free(e->scaled);
	free(e->nodal_pressure);
	free(e->fill);
	free(e->cell_pressure);
	free(e->patch);
	free(e->patch_edge);
	free(e->patch_full);
	free(e->bbar);
	free(e->stress_n);
	free(e->Be_n);
	free(e->state_n);
	free(e->plastic_n);
	free(e->strain_increment);
	free(e->volume_rate);
	free(e->pressure_increment);
	free(e->tangent);
	free(e);
	s->scheme_state = NULL;
}

/* alpha of the scaled pressure unknowns: the largest Young's modulus over a cell, so that the
 * coupling entries (1 - n) V mB S alpha are of the stiffness entries' order (spec-001 §4.3). */
static double pressure_scale(const struct sim *s)
{
	double E = 0.0;
	for (int m = 0; m < s->spec->material_count; m++)
		E = fmax(E, s->materials[m].E);
	return (E > 0.0 ? E : 1.0) * s->grid.inv_h;
}

static enum poro_status create(struct sim *s)
{
	struct implicit_state *e = calloc(1, sizeof *e);
	if (!(s->scheme_state = e))
		return poro_error_set(&s->err, PORO_ENOMEM, "cannot allocate the implicit scheme's state");
	TRY(particles_add_implicit_state(&s->soil, &s->err));
	TRY(particles_add_implicit_state(&s->water, &s->err));
	TRY(implicit_system_create(s));
	const size_t N = (size_t)e->unknowns, nodes = (size_t)s->grid.node_count, n = (size_t)s->soil.n + 1;
	const int consistent = s->spec->formulation.tangent == NEWTON_TANGENT_CONSISTENT;
	const int ok = (e->kind = calloc(N, 1)) && (e->prescribed = calloc(N, sizeof(double))) &&
		       (e->increment = calloc(N, sizeof(double))) && (e->delta = calloc(N, sizeof(double))) &&
		       (e->residual = calloc(N, sizeof(double))) && (e->external = calloc(N, sizeof(double))) &&
		       (e->velocity = calloc(N, sizeof(double))) && (e->acceleration = calloc(N, sizeof(double))) &&
		       (e->velocity_new = calloc(N, sizeof(double))) &&
		       (e->acceleration_new = calloc(N, sizeof(double))) && (e->scaled = calloc(N, sizeof(double))) &&
		       (e->nodal_pressure = calloc(nodes, sizeof(double))) &&
		       (e->fill = calloc((size_t)s->grid.cell_count, sizeof(double))) &&
		       (e->cell_pressure = calloc((size_t)s->grid.cell_count, sizeof(double))) &&
		       (e->patch = calloc(3 * nodes, sizeof(double))) &&
		       (e->patch_edge = calloc(3 * nodes, sizeof(double))) && (e->patch_full = calloc(nodes, 1)) &&
		       (e->bbar = calloc(BBAR_FACTORS * n, sizeof(double))) &&
		       (e->stress_n = calloc(4 * n, sizeof(double))) && (e->Be_n = calloc(4 * n, sizeof(double))) &&
		       (e->state_n = calloc(STATE_MAX * n, sizeof(double))) &&
		       (e->plastic_n = calloc(n, sizeof(double))) &&
		       (e->strain_increment = calloc(4 * n, sizeof(double))) &&
		       (e->volume_rate = calloc(n, sizeof(double))) &&
		       (e->pressure_increment = calloc(n, sizeof(double))) &&
		       (!consistent || (e->tangent = calloc(16 * n, sizeof(double))));
	if (!ok)
		return poro_error_set(&s->err, PORO_ENOMEM, "cannot allocate the implicit scheme's arrays for %ld unknowns "
				      "and %ld points", (long)N, (long)s->soil.n);
	e->pressure_scale = pressure_scale(s);
	return PORO_OK;
}

/* Step 1: shapes at x_n, their B-bar factors, and the step-start state each iteration restarts
 * from (the stress is integrated from it with the step's whole increment, spec-001 §4.2). */
static enum poro_status shapes_and_start(struct sim *s)
{
	struct implicit_state *e = implicit_of(s);
	const struct particles *p = &s->soil;
	TRY(point_map_shapes(s));
	implicit_bbar_factors(s);
	memcpy(e->stress_n, p->stress, sizeof(double) * 4 * (size_t)p->n);
	memcpy(e->Be_n, p->Be, sizeof(double) * 4 * (size_t)p->n);
	memcpy(e->state_n, p->state, sizeof(double) * STATE_MAX * (size_t)p->n);
	memcpy(e->plastic_n, p->plastic_strain, sizeof(double) * (size_t)p->n);
	return PORO_OK;
}

/* Step 3 with the masses step 2 needs: the nodal masses of both phases, the points' volumes per
 * node (p is active where saturated points reach) and per cell (the fill), the mass-weighted
 * velocities and accelerations of both phases at the unknowns, and the step-start pore pressure
 * p~ (solid-mass weighted, tension positive) for the drained nodes. */
static void map_kinematics(struct sim *s)
{
	struct implicit_state *e = implicit_of(s);
	struct grid_fields *f = &s->f;
	const struct grid *g = &s->grid;
	const struct particles *p = &s->soil;
	struct particles *w = &s->water;
	grid_fields_reset(f, g);
	memset(e->velocity, 0, sizeof(double) * (size_t)e->unknowns);
	memset(e->acceleration, 0, sizeof(double) * (size_t)e->unknowns);
	memset(e->nodal_pressure, 0, sizeof(double) * (size_t)g->node_count);
	memset(e->fill, 0, sizeof(double) * (size_t)g->cell_count);
	double *v = e->velocity, *a = e->acceleration;
	/* a scatter into q's support and q's cell, both reached from q's block only: in parallel
	 * (point_blocks.h) */
	FOR_POINTS_BY_BLOCK(p, q, {
		const double ms = p->mass[q], mw = q < w->n ? p->porosity[q] * s->rho_w * p->volume[q] : 0.0;
		const double V = q < w->n ? p->volume[q] : 0.0, pi = q < w->n ? w->pressure[q] : 0.0;
		const double *vs = p->v + 2 * q, *as = p->acceleration + 2 * q;
		const double *vw = w->v + 2 * q, *aw = w->acceleration + 2 * q;
		if (q < w->n)
			w->mass[q] = mw;
		FOR_SUPPORT(g, p, q, {
			double *vI = v + DOFS_PER_NODE * (size_t)I, *aI = a + DOFS_PER_NODE * (size_t)I;
			f->mass_s[I] += wk * ms;
			f->mass_w[I] += wk * mw;
			f->mass_w_v[I] += wk * V;
			e->nodal_pressure[I] += wk * ms * pi;
			for (int c = 0; c < 2; c++) {
				vI[DOF_UX + c] += wk * ms * vs[c], aI[DOF_UX + c] += wk * ms * as[c];
				if (mw > 0.0)
					vI[DOF_WX + c] += wk * mw * vw[c], aI[DOF_WX + c] += wk * mw * aw[c];
			}
		});
		const idx_t i = (idx_t)floor((p->x[2 * q] - g->origin[0]) * g->inv_h);
		const idx_t j = (idx_t)floor((p->x[2 * q + 1] - g->origin[1]) * g->inv_h);
		const idx_t ci = i < g->cells[0] ? i : g->cells[0] - 1, cj = j < g->cells[1] ? j : g->cells[1] - 1;
		e->fill[ci + cj * g->cells[0]] += p->volume[q] * g->inv_h * g->inv_h;
	});
#pragma omp parallel for schedule(static)
	for (idx_t I = 0; I < g->node_count; I++) {
		double *vI = v + DOFS_PER_NODE * (size_t)I, *aI = a + DOFS_PER_NODE * (size_t)I;
		const double Ms = f->mass_s[I], Mw = f->mass_w[I];
		for (int c = 0; c < 2; c++) {
			vI[DOF_UX + c] = Ms > 0.0 ? vI[DOF_UX + c] / Ms : 0.0;
			aI[DOF_UX + c] = Ms > 0.0 ? aI[DOF_UX + c] / Ms : 0.0;
			vI[DOF_WX + c] = Mw > 0.0 ? vI[DOF_WX + c] / Mw : 0.0;
			aI[DOF_WX + c] = Mw > 0.0 ? aI[DOF_WX + c] / Mw : 0.0;
		}
		e->nodal_pressure[I] = Ms > 0.0 ? e->nodal_pressure[I] / Ms : 0.0;
	}
}

/* 1 when node (i, j) touches a cell open to the air: one inside the grid filled below
 * DRAINED_FILL, or one beyond a drained grid face. */
static int node_drains(const struct sim *s, idx_t i, idx_t j)
{
	const struct implicit_state *e = implicit_of(s);
	const struct grid *g = &s->grid;
	const struct case_boundary *bc = s->spec->boundaries;
	if ((i == 0 && bc[FACE_LEFT].drainage == DRAINAGE_DRAINED) ||
	    (i == g->cells[0] && bc[FACE_RIGHT].drainage == DRAINAGE_DRAINED) ||
	    (j == 0 && bc[FACE_BOTTOM].drainage == DRAINAGE_DRAINED) ||
	    (j == g->cells[1] && bc[FACE_TOP].drainage == DRAINAGE_DRAINED))
		return 1;
	for (idx_t cj = j - 1; cj <= j; cj++)
		for (idx_t ci = i - 1; ci <= i; ci++)
			if (ci >= 0 && ci < g->cells[0] && cj >= 0 && cj < g->cells[1] &&
			    e->fill[ci + cj * g->cells[0]] < DRAINED_FILL)
				return 1;
	return 0;
}

/* Step 2: each unknown's kind and prescribed increment (spec-001 §3.5). A phase's displacement is
 * active where the phase has mass, held at 0 on constrained components; the pressure is active
 * where saturated points reach, held at p = 0 (its increment -p~) where the node drains. The
 * constrained components' step-start velocity and acceleration are zeroed. */
static void mark_unknowns(struct sim *s)
{
	struct implicit_state *e = implicit_of(s);
	const struct grid_fields *f = &s->f;
	const struct grid *g = &s->grid;
	double Ms_max = 0.0, Mw_max = 0.0, V_max = 0.0;
	for (idx_t I = 0; I < g->node_count; I++) {
		Ms_max = fmax(Ms_max, f->mass_s[I]);
		Mw_max = fmax(Mw_max, f->mass_w[I]);
		V_max = fmax(V_max, f->mass_w_v[I]);
	}
	memset(e->prescribed, 0, sizeof(double) * (size_t)e->unknowns);
	for (idx_t I = 0; I < g->node_count; I++) {
		unsigned char *kind = e->kind + DOFS_PER_NODE * (size_t)I;
		double *v = e->velocity + DOFS_PER_NODE * (size_t)I, *a = e->acceleration + DOFS_PER_NODE * (size_t)I;
		const int solid = f->mass_s[I] > ACTIVE_MASS_SHARE * Ms_max;
		const int water = f->mass_w[I] > ACTIVE_MASS_SHARE * Mw_max;
		for (int c = 0; c < 2; c++) {
			const int held_s = f->fix_s[I] & (1 << c), held_w = f->fix_w[I] & (1 << c);
			kind[DOF_UX + c] = !solid ? DOF_INACTIVE : held_s ? DOF_PRESCRIBED : DOF_FREE;
			kind[DOF_WX + c] = !water ? DOF_INACTIVE : held_w ? DOF_PRESCRIBED : DOF_FREE;
			if (held_s)
				v[DOF_UX + c] = a[DOF_UX + c] = 0.0;
			if (held_w)
				v[DOF_WX + c] = a[DOF_WX + c] = 0.0;
		}
		kind[DOF_P] = DOF_INACTIVE;
		if (f->mass_w_v[I] > ACTIVE_MASS_SHARE * V_max) {
			const int drains = node_drains(s, I % g->nodes[0], I / g->nodes[0]);
			kind[DOF_P] = drains ? DOF_PRESCRIBED : DOF_FREE;
			/* p = -pi: the increment that brings the node's pressure to zero */
			if (drains)
				e->prescribed[DOFS_PER_NODE * (size_t)I + DOF_P] = e->nodal_pressure[I];
		}
	}
}

/* Step 5: f_{n+1}, the tractions on the solid and both phases' weight (001 A.2) at the nodes. */
static void external_forces(struct sim *s)
{
	struct implicit_state *e = implicit_of(s);
	struct grid_fields *f = &s->f;
	const idx_t nodes = s->grid.node_count;
	memset(f->force, 0, sizeof(double) * DIM * (size_t)nodes);
	loads_add_tractions(s, s->time + s->dt, f->force);
	memset(e->external, 0, sizeof(double) * (size_t)e->unknowns);
#pragma omp parallel for schedule(static)
	for (idx_t I = 0; I < nodes; I++) {
		double *fI = e->external + DOFS_PER_NODE * (size_t)I;
		for (int c = 0; c < 2; c++) {
			fI[DOF_UX + c] = f->force[2 * I + c] + f->mass_s[I] * s->gravity[c];
			fI[DOF_WX + c] = f->mass_w[I] * s->gravity[c];
		}
	}
}

/* The largest |value| over the unknowns of the kinds in mask (1 << kind) and the components in
 * dofs (1 << DOF_*). */
static double largest(const struct implicit_state *e, const double *x, unsigned dofs)
{
	double m = 0.0;
	for (idx_t k = 0; k < e->unknowns; k++)
		if (e->kind[k] == DOF_FREE && (dofs & (1u << (k % DOFS_PER_NODE))))
			m = fmax(m, fabs(x[k]));
	return m;
}

/* K delta = r on the scaled system: the pressure rows of r and unknowns of delta carry alpha. */
static enum poro_status solve_correction(struct sim *s)
{
	struct implicit_state *e = implicit_of(s);
	const double alpha = e->pressure_scale;
	for (idx_t k = 0; k < e->unknowns; k++)
		e->scaled[k] = k % DOFS_PER_NODE == DOF_P ? alpha * e->residual[k] : e->residual[k];
	TRY(lu_solver_solve(e->lu, e->scaled, e->delta, NULL, &s->err));
	for (idx_t k = 0; k < e->unknowns; k++)
		e->delta[k] = e->kind[k] != DOF_FREE ? 0.0 : k % DOFS_PER_NODE == DOF_P ? alpha * e->delta[k] : e->delta[k];
	return PORO_OK;
}

static double dot(const double *a, const double *b, idx_t n)
{
	double sum = 0.0;
	for (idx_t k = 0; k < n; k++)
		sum += a[k] * b[k];
	return sum;
}

static enum poro_status assemble_and_factorise(struct sim *s)
{
	struct implicit_state *e = implicit_of(s);
	PHASE(PHASE_PRESSURE_ASSEMBLY, implicit_system_assemble(s));
	enum poro_status st = PORO_OK;
	PHASE(PHASE_PRESSURE_SOLVE, st = lu_solver_factorise(e->lu, e->values, &s->err));
	if (st)
		poro_error_append(&s->err, "at step %ld (t = %.6g s)", s->step + 1, s->time + s->dt);
	return st;
}

/* Steps 6-7: the modified Newton-Raphson loop from Delta d = the prescribed increments. */
static enum poro_status newton(struct sim *s)
{
	struct implicit_state *e = implicit_of(s);
	const struct case_formulation *form = &s->spec->formulation;
	const int full_newton = e->tangent != NULL;
	memcpy(e->increment, e->prescribed, sizeof(double) * (size_t)e->unknowns);
	enum poro_status st = PORO_OK;
	PHASE(PHASE_STRESS, st = implicit_system_residual(s));
	if (st)
		return st;
	/* the tangent of the first iteration: the elastic one, or the materials' at the step's start
	 * configuration (the residual just filled e->tangent at the prescribed increments) */
	TRY(assemble_and_factorise(s));
	const double force_scale = fmax(largest(e, e->external, 0x1f), largest(e, e->residual, 0x1f));
	double first = 0.0, energy = 0.0;
	e->history_count = 0;
	for (e->iterations = 0;; e->iterations++) {
		if (largest(e, e->residual, 0x1f) <= RESIDUAL_FLOOR * force_scale)
			return PORO_OK;
		if (e->iterations == form->newton_max_iterations)
			break;
		if (e->iterations > 0 && full_newton)
			TRY(assemble_and_factorise(s));
		PHASE(PHASE_CORRECT, st = solve_correction(s));
		if (st)
			return st;
		energy = fabs(dot(e->delta, e->residual, e->unknowns));
		if (e->iterations == 0)
			first = energy;
		if (e->history_count < SIM_ITERATIONS_KEPT)
			e->residual_history[e->history_count++] = energy;
		for (idx_t k = 0; k < e->unknowns; k++)
			e->increment[k] += e->delta[k];
		e->iterations_total++;
		PHASE(PHASE_STRESS, st = implicit_system_residual(s));
		if (st)
			return st;
		const double du = largest(e, e->delta, (1u << DOF_UX) | (1u << DOF_UY));
		const int balanced = largest(e, e->residual, 0x1f) <= RESIDUAL_TOLERANCE * force_scale;
		if (energy <= form->newton_tolerance * first && (du <= DISPLACEMENT_TOLERANCE * s->grid.h || balanced)) {
			e->iterations++;
			return PORO_OK;
		}
	}
	return poro_error_set(&s->err, PORO_ESOLVER, "step %ld (t = %.6g s): the Newton iteration did not converge in "
			      "%d iterations: the energy |delta . r| of the last is %.3g of the first's (tolerance %g), "
			      "the largest residual %.3g N/m; a smaller dt%s may converge",
			      s->step + 1, s->time + s->dt, e->iterations, first > 0.0 ? energy / first : energy,
			      form->newton_tolerance, largest(e, e->residual, 0x1f),
			      full_newton ? "" : ", or tangent \"consistent\",");
}

/* Step 9: the points from the converged increments (001 Eq. 11). */
static enum poro_status update_points(struct sim *s)
{
	struct implicit_state *e = implicit_of(s);
	const struct case_formulation *form = &s->spec->formulation;
	const struct grid *g = &s->grid;
	struct particles *p = &s->soil, *w = &s->water;
	const double dt = s->dt, beta = form->newmark_beta;
	const double cM = 1.0 / (beta * dt * dt), cV = 1.0 / (beta * dt), cA = 0.5 / beta - 1.0;
	/* a_{n+1} at the nodes (Eq. 8; 001's footnote to Eq. 11 corrected, spec-001 E4) */
	double *a_new = e->acceleration_new, *du = s->f.du_s;
#pragma omp parallel for schedule(static)
	for (idx_t k = 0; k < e->unknowns; k++)
		a_new[k] = cM * e->increment[k] - cV * e->velocity[k] - cA * e->acceleration[k];
#pragma omp parallel for schedule(static)
	for (idx_t I = 0; I < g->node_count; I++)
		for (int c = 0; c < 2; c++)
			du[2 * I + c] = e->increment[DOFS_PER_NODE * (size_t)I + DOF_UX + c];
	implicit_pressure_recovery(s, e->pressure_increment);
	double moved = 0.0;   /* the largest displacement, in cells */
#pragma omp parallel for schedule(static) reduction(max : moved)
	for (idx_t q = 0; q < p->n; q++) {
		double a_u[2] = {0}, a_w[2] = {0}, x_u[2] = {0}, eps_u = 0.0, eps_w = 0.0;
		FOR_SUPPORT(g, p, q, {
			const double *d = e->increment + DOFS_PER_NODE * (size_t)I, *A = a_new + DOFS_PER_NODE * (size_t)I;
			for (int c = 0; c < 2; c++) {
				a_u[c] += wk * A[DOF_UX + c];
				a_w[c] += wk * A[DOF_WX + c];
				x_u[c] += wk * d[DOF_UX + c];
			}
		});
		implicit_point_volumetric(s, q, &eps_u, &eps_w);
		for (int c = 0; c < 2; c++) {                                    /* (11a-c) */
			p->v[2 * q + c] += 0.5 * dt * (p->acceleration[2 * q + c] + a_u[c]);
			p->acceleration[2 * q + c] = a_u[c];
			if (q < w->n) {
				w->v[2 * q + c] += 0.5 * dt * (w->acceleration[2 * q + c] + a_w[c]);
				w->acceleration[2 * q + c] = a_w[c];
			}
			p->x[2 * q + c] += x_u[c];                                /* (11f) */
		}
		moved = fmax(moved, hypot(x_u[0], x_u[1]) * g->inv_h);
		e->volume_rate[q] = eps_u / dt;
		if (q < w->n)
			w->pressure[q] -= e->pressure_increment[q];   /* compression positive increment */
	}
	e->moved_step = moved;
	/* F from the displacement increment's gradient; V, n, k from B-bar's volumetric strain */
	deformation_increment(s, du);
	return deformation_apply_volumetric(s, e->volume_rate);
}

static enum poro_status implicit_step(struct sim *s)
{
	struct implicit_state *e = implicit_of(s);
	enum poro_status st = PORO_OK;
	loads_gravity(s->spec, s->time + s->dt, s->gravity);
	PHASE(PHASE_SHAPE, st = shapes_and_start(s));                         /* (1) */
	if (st)
		return st;
	PHASE(PHASE_P2G, {                                                    /* (2), (3), (5) */
		map_kinematics(s);
		mark_unknowns(s);
		external_forces(s);
	});
	TRY(newton(s));                                                       /* (4), (6), (7) */
	PHASE(PHASE_G2P, st = update_points(s));                              /* (8), (9) */
	if (st)
		return st;
	if (e->moved_step > 0.5 && !s->warning[0])
		snprintf(s->warning, sizeof s->warning, "points moved up to %.2f of a cell in step %ld (t = %.6g s): the implicit step "
				 "evaluates its shapes at the step's start, so a smaller dt follows the motion better",
			 e->moved_step, s->step + 1, s->time + s->dt);
	s->time = (double)(s->step + 1) * s->dt;
	s->step++;
	return PORO_OK;
}

static int iterations(const struct sim *s, int *last, long *total, const double **energies, int *count)
{
	const struct implicit_state *e = implicit_of(s);
	*last = e->iterations, *total = e->iterations_total, *count = e->history_count;
	if (energies)
		*energies = e->residual_history;
	return 1;
}

static int solver_counts(const struct sim *s, long *analyses, long *factorisations, long *solves,
			 long *factor_nonzeros)
{
	lu_solver_counts(implicit_of(s)->lu, analyses, factorisations, solves, factor_nonzeros);
	return 1;
}

const struct scheme implicit_upU_scheme = {
	.name = "implicit_upU",
	.phase_names = { "shape functions, B-bar", "nodal kinematics, loads", NULL, "Newmark matrix",
			 "factorisation", "solves", "point update, recovery", NULL, "residual, stress" },
	.create = create,
	.destroy = destroy,
	.step = implicit_step,
	.iterations = iterations,
	.solver_counts = solver_counts,
};
