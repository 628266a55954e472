/*
 * plate.c - rigid smooth plates on grid faces (case key boundaries.<face>.soil "plate").
 *
 * A plate is a rigid, frictionless, impermeable platen pressed onto a face of the grid by a force
 * F(t) per metre of thickness (its own mass neglected). It leaves the tangential velocities free
 * and gives every node of the face one normal velocity V, the plate's, for the soil and the water
 * alike (no flow through it). The nodes' normal components are marked as a wall (boundary.c), so
 * that every step treats them as a slip wall, and the wall then moves with V: with the
 * interpolating edge basis (shape.h) the velocity on the face is exactly the edge nodes', so the
 * face moves as one.
 *
 * V is the velocity of one degree of freedom made of the tied components, mass
 * M = sum_I (M_sI + M_wI) over the face's nodes, on which the drag cancels (both phases move with
 * V). With F_I the mixture force of Eq. 52 at node I (stress, pressure p^t, tractions, body force)
 * and n the inward normal:
 *  - predictor (steps 3-4): M V* = sum_I (M_sI v_sI + M_wI v_wI) . n + dt (sum_I F_I . n + F(t));
 *  - pressure (step 5): V* enters the right-hand side of Eq. 60 through v*, and the increment's
 *    push on the plate, dV = impulse(dp) / M, is solved with dp (plate_couple_pressure). Updating V
 *    from the pressure of the last step instead makes the plate a mass on an incompressible
 *    mixture: in Mandel's problem its velocity grew by a factor of about -24 a step;
 *  - correction (step 6): V = V* + dV; the MUSL displacement of step 8a moves the face by dt V.
 * The push is the pressure force in the divergence form the predictors use,
 * -sum_w V_w dp(x_w) grad S_I(x_w), which holds the face's boundary term; the correction's
 * gradient form (Eqs. 67-68) leaves it out, as suits a wall that does not move.
 *
 * The face is the grid's: it does not move with the plate, so the plate suits settlements small
 * against a cell, as the other wall conditions do. The distribution of the force over the face is
 * left to the soil, as under a rigid plate (in Mandel's problem the contact stress first rises
 * towards the drained edge, then shifts to the centre).
 */
#include <math.h>
#include <string.h>

#include "semi_implicit.h"
#include "transfer.h"

/* The normal axis of a face (0: x for left and right) and its inward sign. */
static int face_axis(int face)
{
	return face == FACE_LEFT || face == FACE_RIGHT ? 0 : 1;
}

static double inward_sign(int face)
{
	return face == FACE_LEFT || face == FACE_BOTTOM ? 1.0 : -1.0;
}

/* Node I of face `face`, k = 0 .. face_node_count - 1 along it. */
static idx_t face_node_count(const struct grid *g, int face)
{
	return g->nodes[1 - face_axis(face)];
}

static idx_t face_node(const struct grid *g, int face, idx_t k)
{
	switch (face) {
	case FACE_LEFT:
		return grid_node(g, 0, k);
	case FACE_RIGHT:
		return grid_node(g, g->cells[0], k);
	case FACE_BOTTOM:
		return grid_node(g, k, 0);
	default:
		return grid_node(g, k, g->cells[1]);
	}
}

/* Sets the normal component of both phases' velocity (v_s, v_w: nodal, width 2) to V on the
 * face's nodes that carry mass of that phase. */
static void set_face_velocity(struct sim *s, int face, double V, double *v_s, double *v_w)
{
	const struct grid *g = &s->grid;
	const int c = face_axis(face);
	for (idx_t k = 0; k < face_node_count(g, face); k++) {
		const idx_t I = face_node(g, face, k);
		if (v_s && s->f.mass_s[I] > 0.0)
			v_s[2 * I + c] = V;
		if (v_w && s->f.mass_w[I] > 0.0)
			v_w[2 * I + c] = V;
	}
}

void plate_predict(struct sim *s)
{
	struct semi_implicit *si = semi_implicit_of(s);
	const struct grid_fields *f = &s->f;
	for (int face = 0; face < FACE_COUNT; face++) {
		const struct case_boundary *b = &s->spec->boundaries[face];
		if (b->soil != CONSTRAINT_PLATE)
			continue;
		const int c = face_axis(face);
		double momentum = 0.0, force = 0.0, mass = 0.0;
		for (idx_t k = 0; k < face_node_count(&s->grid, face); k++) {
			const idx_t I = face_node(&s->grid, face, k), i = 2 * I + c;
			momentum += f->mass_s[I] * f->v_s[i] + f->mass_w[I] * f->v_w[i];
			force += f->force[i];
			mass += f->mass_s[I] + f->mass_w[I];
		}
		force += inward_sign(face) * b->plate.force *
			 case_time_function_value(&b->plate.time_function, s->time + s->dt);
		si->plate_velocity[face] = mass > 0.0 ? (momentum + s->dt * force) / mass : 0.0;
		set_face_velocity(s, face, si->plate_velocity[face], si->v_s_star, si->v_w_star);
	}
}

/* M_j: the mass of plate j's degree of freedom, both phases of the face's nodes. */
static double plate_mass(const struct sim *s, int face)
{
	double mass = 0.0;
	for (idx_t k = 0; k < face_node_count(&s->grid, face); k++) {
		const idx_t I = face_node(&s->grid, face, k);
		mass += s->f.mass_s[I] + s->f.mass_w[I];
	}
	return mass;
}

/* The normal impulse, N s/m, a nodal pressure increment x gives plate j's nodes within the step:
 * the increment's share of the pressure force of Eqs. 54-55 on them, dt sum_I f_I . n with
 * f_I = -sum_w V_w x(x_w) grad S_I(x_w) over the water points, x interpolated to them as step 7c
 * does. This is the divergence form the predictors use, which carries the pressure's push on the
 * plate (the boundary term of the face); the correction's gradient form G dp of Eqs. 67-68 leaves
 * that term out, which suits a wall that does not move but would leave the plate unpushed by the
 * increment. */
static double plate_impulse(struct sim *s, int face, const double *x)
{
	struct semi_implicit *si = semi_implicit_of(s);
	const struct grid *g = &s->grid;
	double *force = si->correction_w;   /* scratch: free here, left zero */
	const int c = face_axis(face);
	memset(force, 0, 2 * sizeof(double) * (size_t)g->node_count);
	g2p_scalar(g, &s->water, x, s->water_scalar);
	p2g_internal_force(g, &s->water, s->water.volume, NULL, s->water_scalar, force);
	double impulse = 0.0;
	for (idx_t k = 0; k < face_node_count(g, face); k++)
		impulse += s->dt * force[2 * face_node(g, face, k) + c];
	memset(force, 0, 2 * sizeof(double) * (size_t)g->node_count);
	return impulse;
}

/* z = L^-1 d_j: the pressure increment a unit change of plate j's velocity calls for, d_j being
 * the right-hand side of Eq. 60 for that velocity alone on the face's nodes (both phases), into
 * z (nodal, zero on prescribed nodes). Solved on the reduced system pressure_solve factorised. */
static enum poro_status plate_response(struct sim *s, int face, idx_t n, double *z)
{
	struct semi_implicit *si = semi_implicit_of(s);
	struct pressure_system *ps = &si->ps;
	const struct grid *g = &s->grid;
	double *unit = s->f.du_s;   /* zero until step 8; left zero */
	double *b = si->plate_work + (size_t)FACE_COUNT * (size_t)g->node_count, *x = b + g->node_count;
	const int c = face_axis(face);
	for (idx_t k = 0; k < face_node_count(g, face); k++)
		unit[2 * face_node(g, face, k) + c] = 1.0;
	pressure_divergence_rhs(s, unit, unit, z);
	memset(unit, 0, 2 * sizeof(double) * (size_t)g->node_count);
	for (idx_t I = 0; I < g->node_count; I++)
		if (ps->unknown[I] >= 0)
			b[ps->unknown[I]] = z[I];
	enum poro_status st = spd_solver_solve(ps->solver, n, ps->colptr, ps->rowidx, ps->values, b, x, &s->err);
	for (idx_t I = 0; I < g->node_count; I++)
		z[I] = ps->unknown[I] >= 0 ? x[ps->unknown[I]] : 0.0;
	return st;
}

/* The plates' velocities enter Eq. 60's right-hand side (through v*) and take the impulse of the
 * increment (step 6), so with the plates' velocity changes dV the system is
 *     L dp = b + sum_k dV_k d_k,   M_j dV_j = impulse_j(dp),
 * and with y = L^-1 b (the solve just done) and z_k = L^-1 d_k,
 *     dV_j - sum_k impulse_j(z_k) dV_k / M_j = impulse_j(y) / M_j,   dp = y + sum_k dV_k z_k,
 * a system of one equation per plate (Sherman-Morrison for one plate). Left to the explicit
 * update of plate_correct alone, dV would follow the pressure of the last step: the plate is then
 * a mass on an incompressible mixture, and its velocity grew by a factor of about -24 a step. */
enum poro_status plate_couple_pressure(struct sim *s, idx_t n)
{
	struct semi_implicit *si = semi_implicit_of(s);
	const size_t nodes = (size_t)s->grid.node_count;
	int face_of[FACE_COUNT], plates = 0;
	double A[FACE_COUNT][FACE_COUNT + 1];
	for (int face = 0; face < FACE_COUNT; face++)
		if (s->spec->boundaries[face].soil == CONSTRAINT_PLATE)
			face_of[plates++] = face;
	for (int k = 0; k < plates; k++) {
		enum poro_status st = plate_response(s, face_of[k], n, si->plate_work + (size_t)k * nodes);
		if (st)
			return st;
	}
	for (int j = 0; j < plates; j++) {
		const double M = plate_mass(s, face_of[j]);
		for (int k = 0; k < plates; k++)
			A[j][k] = (j == k) - (M > 0.0 ? plate_impulse(s, face_of[j], si->plate_work + (size_t)k * nodes) / M : 0.0);
		A[j][plates] = M > 0.0 ? plate_impulse(s, face_of[j], si->dp) / M : 0.0;
	}
	/* Gaussian elimination with partial pivoting on the plates x plates system */
	for (int col = 0; col < plates; col++) {
		int pivot = col;
		for (int r = col + 1; r < plates; r++)
			if (fabs(A[r][col]) > fabs(A[pivot][col]))
				pivot = r;
		for (int k = 0; k <= plates; k++) {
			double t = A[col][k];
			A[col][k] = A[pivot][k], A[pivot][k] = t;
		}
		if (!(fabs(A[col][col]) > 0.0))
			return poro_error_set(&s->err, PORO_ESOLVER, "the rigid plates' system is singular at step %ld",
					      s->step + 1);
		for (int r = col + 1; r < plates; r++) {
			const double m = A[r][col] / A[col][col];
			for (int k = col; k <= plates; k++)
				A[r][k] -= m * A[col][k];
		}
	}
	double dV[FACE_COUNT];
	for (int j = plates - 1; j >= 0; j--) {
		double sum = A[j][plates];
		for (int k = j + 1; k < plates; k++)
			sum -= A[j][k] * dV[k];
		dV[j] = sum / A[j][j];
	}
	for (int k = 0; k < plates; k++)
		for (size_t I = 0; I < nodes; I++)
			si->dp[I] += dV[k] * si->plate_work[(size_t)k * nodes + I];
	return PORO_OK;
}

void plate_correct(struct sim *s)
{
	struct semi_implicit *si = semi_implicit_of(s);
	for (int face = 0; face < FACE_COUNT; face++) {
		if (s->spec->boundaries[face].soil != CONSTRAINT_PLATE)
			continue;
		const double mass = plate_mass(s, face);
		if (mass > 0.0)
			si->plate_velocity[face] += plate_impulse(s, face, si->dp) / mass;
		set_face_velocity(s, face, si->plate_velocity[face], s->f.v_s, s->f.v_w);
	}
}

void plate_displace(struct sim *s, double *du_s)
{
	struct semi_implicit *si = semi_implicit_of(s);
	for (int face = 0; face < FACE_COUNT; face++)
		if (s->spec->boundaries[face].soil == CONSTRAINT_PLATE)
			set_face_velocity(s, face, s->dt * si->plate_velocity[face], du_s, NULL);
}
