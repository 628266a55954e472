/*
 * semi_implicit.c - the semi-implicit incremental fractional-step scheme of paper 000 (§3-4),
 * double-point and single-point, one step = the ten steps of the algorithm in §4.5.
 *
 * Symbols (000 §4.2): M_s, M_w nodal soil and water masses; n_I, k_I nodal porosity and
 * conductivity; v^t, v*, v^{t+1} nodal velocities; Q_I the drag coefficient (Eq. 58); dp the nodal
 * pore-pressure increment. Pressure is tension positive inside the solver, as in the paper.
 *
 * Choices the paper leaves open, each explained where it is made:
 *  - the water points' porosity and volume (steps 8h-8i) are projected at the start of the next
 *    step, from the soil porosity mapped in step 2c, so they use the points' current positions;
 *  - the water velocity (Eq. 51) is mass weighted with the water points' own masses, which equals
 *    the paper's rho_w V0 weighting whenever the initial porosity is uniform;
 *  - step 7c needs the nodal p^t_I, which the paper defines only as the inner sum of Eq. 77
 *    (the water-mass-weighted projection of the point pressures). With it, step 7c already is the
 *    node-wise mapping and remapping of Eq. 77 applied to p^t + dp, and the point pressures it
 *    yields are the smoothed ones the forces of Eqs. 55 and 57 use (§4.4.1). Step 9a is therefore
 *    not applied a second time. We measured the alternatives on the Terzaghi column
 *    (docs/numerics.md): applying Eq. 77 again after 7c makes the pressure grow without bound
 *    within 400 steps; keeping unsmoothed point pressures (p += sum S dp) and smoothing only for
 *    the forces leaves a mode the forces cannot see, which grows at k = 1e-9 m/s. With smoothing
 *    switched off the points keep their pressure and add the interpolated increment;
 *  - the two predictors are solved together at each node, and a wall-constrained phase takes
 *    the wall's reaction itself (see predict_velocities);
 *  - the drag of Eq. 58 is scaled by the node's soil share, so free water standing above the
 *    soil is not dragged as if it filled pores (see soil_fraction);
 *  - in the Laplacian L (Eq. 61) the porosity stays inside the point sum so that L is symmetric
 *    (see pressure.c);
 *  - formulation.position_update "musl_displacement" moves the soil points by the MUSL
 *    displacement of step 8a instead of the grid velocity of step 7b: the volume and F follow
 *    the gradient of that displacement, and with FLIP noise in the point velocities (which the
 *    MUSL remap carries and v^{t+1} does not) the two drift apart otherwise: 7.2% of the
 *    double-point Xie-Leo column's settlement (docs/numerics.md, "Volumes that follow the motion").
 *  - a rigid plate on a grid face (boundaries.<face>.soil "plate") makes the face's normal
 *    velocity, both phases, one degree of freedom, set after the predictors and solved with the
 *    pressure increment (plate.c): updated from the last step's pressure alone it diverged.
 * Single point: the water set rides on the soil points (same positions, volumes, porosity), so
 * every formula below serves both variants; only the water points' own motion differs.
 */
#include <math.h>
#include <string.h>

#include "permeability.h"
#include "phase_coupling.h"
#include "shape.h"
#include "sim_internal.h"
#include "transfer.h"

#define TRY(call)                                       \
	do {                                            \
		enum poro_status st_ = (call);          \
		if (st_ != PORO_OK)                     \
			return st_;                     \
	} while (0)

/* Time t is at or before the end of the gravity ramp; steps are compared within a billionth of dt,
 * so the step that lands on the ramp's end by rounding still counts as inside it. */
static int by_ramp_end(const struct sim *s, double t)
{
	return t <= s->spec->gravity.ramp_time + 1e-9 * s->dt;
}

/* True while the step being taken ends within the gravity ramp: the initialisation of 000 App. B.4
 * and §5.4, during which gravity.elastic_loading, loading_conductivity and water_attached act. */
static int in_gravity_ramp(const struct sim *s)
{
	return s->spec->gravity.ramp_time > 0 && by_ramp_end(s, s->time + s->dt);
}

/* 000 App. B.4 with gravity.elastic_loading: a step that ends within the gravity ramp is elastic
 * (1); the first step after it (2) first makes each point's present state, the one at the end of
 * the ramp, its reference (material_reset_reference: p0, eps_v0^e, the image pressure from OCR). */
static int gravity_loading_stage(const struct sim *s)
{
	if (!s->spec->gravity.elastic_loading)
		return 0;
	if (in_gravity_ramp(s))
		return 1;
	return by_ramp_end(s, s->time) ? 2 : 0;
}

/* Step 1: shape functions and gradients of soil and (double point) water points. */
static enum poro_status evaluate_shape_functions(struct sim *s)
{
	enum case_shape kind = s->spec->formulation.shape;
	TRY(shape_evaluate(&s->grid, kind, &s->soil, "soil", &s->err));
	if (s->double_point)
		TRY(shape_evaluate(&s->grid, kind, &s->water, "water", &s->err));
	return PORO_OK;
}

static void reset_grid(struct sim *s)
{
	const size_t n = (size_t)s->grid.node_count;
	struct grid_fields *f = &s->f;
	double *scalars[] = {f->mass_s, f->mass_w, f->mass_w_points, f->mass_w_v, f->volume_s, f->porosity,
			     f->conductivity, f->pressure, f->dp, f->rhs};
	double *vectors[] = {f->v_s, f->v_w, f->v_s_old, f->v_w_old, f->v_s_star, f->v_w_star,
			     f->force_w, f->force, f->correction_s, f->correction_w, f->du_s};
	for (size_t i = 0; i < sizeof scalars / sizeof *scalars; i++)
		memset(scalars[i], 0, n * sizeof(double));
	for (size_t i = 0; i < sizeof vectors / sizeof *vectors; i++)
		memset(vectors[i], 0, 2 * n * sizeof(double));
}

/* Divides a nodal field (width 1 or 2) by a nodal weight where the weight is positive. */
static void normalise(idx_t nodes, double *field, int width, const double *weight)
{
	for (idx_t I = 0; I < nodes; I++)
		for (int c = 0; c < width; c++)
			field[width * I + c] = weight[I] > 0.0 ? field[width * I + c] / weight[I] : 0.0;
}

/* The points carry APIC's affine velocity C_p ("apic" and "aflip", transfer.h). */
static int affine_velocities(const struct sim *s)
{
	return s->spec->formulation.velocity_update != VELOCITY_UPDATE_FLIP;
}

/* The point velocities' two transfers, with the affine part when the points carry one:
 * map_momentum adds out_I += sum_p S_Ip m_p v_p; gather_velocity sets v_p = sum_I S_Ip node_I
 * (PIC) and, with the affine part, the points' affine velocities C_p. */
static void map_momentum(const struct sim *s, const struct particles *p, double *out)
{
	if (affine_velocities(s))
		p2g_affine_momentum(&s->grid, p, p->mass, p->v, p->C, out);
	else
		p2g_vector(&s->grid, p, p->mass, p->v, out);
}

static void gather_velocity(const struct sim *s, struct particles *p, const double *node, double *v)
{
	if (affine_velocities(s))
		g2p_affine_velocity(&s->grid, p, node, v, p->C);
	else
		g2p_vector(&s->grid, p, node, v);
}

/* Step 2a-d: soil mass (Eq. 44), velocity (Eq. 45), porosity (Eq. 46), conductivity (Eq. 47). */
static void map_soil_to_grid(struct sim *s)
{
	const struct particles *p = &s->soil;
	struct grid_fields *f = &s->f;
	const int affine = affine_velocities(s);
	const struct p2g_batch b = {
		.scalars = 4,
		.scalar = {{NULL, p->mass, f->mass_s}, {p->mass, p->porosity, f->porosity},
			   {NULL, p->volume, f->volume_s}, {p->mass, p->conductivity, f->conductivity}},
		.vector = {p->mass, p->v, affine ? NULL : f->v_s},   /* the affine momentum: map_momentum */
	};
	p2g_batch(&s->grid, p, &b);
	if (affine)
		map_momentum(s, p, f->v_s);
	s->mapped_mass_s = 0.0;
	for (idx_t q = 0; q < p->n; q++)
		s->mapped_mass_s += p->mass[q];
	idx_t nodes = s->grid.node_count;
	normalise(nodes, f->v_s, 2, f->mass_s);
	normalise(nodes, f->conductivity, 1, f->mass_s);
	for (idx_t I = 0; I < nodes; I++)   /* where there is no soil the pores are all water */
		f->porosity[I] = f->mass_s[I] > 0.0 ? f->porosity[I] / f->mass_s[I] : 1.0;
	const double k_loading = s->spec->gravity.loading_conductivity;
	if (k_loading > 0.0 && in_gravity_ramp(s))   /* 000 §5.4: drain the loading's excess pressure */
		for (idx_t I = 0; I < nodes; I++)
			f->conductivity[I] = f->mass_s[I] > 0.0 ? k_loading : 0.0;
	memcpy(f->v_s_old, f->v_s, 2 * sizeof(double) * (size_t)nodes);
}

/* Step 2e-f: water mass (Eq. 50), water velocity (Eq. 51) and the nodal pressure p^t, in one
 * loop over the water points (with the Laplacian, p^t then again as a linear fit). Double point
 * first takes steps 8h-8i of the last step at each point, from the nodal porosity just mapped (so
 * they use the points' current positions): the soil porosity seen by the water point (Eq. 48) and
 * its volume V_wp = n0 / n V0 (Eq. 36). Single-point water shares the soil points' porosity and
 * volume. */
static void map_water_to_grid(struct sim *s)
{
	struct particles *w = &s->water;
	struct grid_fields *f = &s->f;
	const idx_t nodes = s->grid.node_count;
	const int affine = affine_velocities(s);
	const int mean_pressure = s->ps.exact;   /* the Laplacian fits p^t after the loop instead */
	const struct p2g_batch b = {
		.scalars = mean_pressure ? 3 : 2,
		.scalar = {{NULL, w->volume, f->mass_w_v}, {NULL, w->mass, f->mass_w_points},
			   {w->mass, w->pressure, f->pressure}},
		.vector = {w->mass, w->v, affine ? NULL : f->v_w},   /* the affine momentum: map_momentum */
	};
	s->mapped_mass_w = 0.0;
	for (idx_t q = 0; q < w->n; q++) {
		if (s->double_point) {
			w->porosity[q] = g2p_scalar_point(&s->grid, w, q, f->porosity);
			w->volume[q] = w->porosity0[q] / w->porosity[q] * w->volume0[q];
		}
		/* n rho_w V: constant n0 rho_w V0 in double point (Eq. 37) */
		w->mass[q] = w->porosity[q] * s->rho_w * w->volume[q];
		s->mapped_mass_w += w->mass[q];
		p2g_batch_point(&s->grid, w, q, &b);
	}
	if (affine)
		map_momentum(s, w, f->v_w);
	normalise(nodes, f->v_w, 2, f->mass_w_points);
	/* With the Laplacian, p^{t+1} = p^t + dp and the solve removes only the part of an error in
	 * p^t that drives a divergence, so Eq. 77's mass-weighted mean, which is the field's value at
	 * the points' centroid rather than at the node where the points lie to one side (walls, the
	 * free surface), biased the hydrostatic pressure and the bias accumulated: 1.3% at a column's
	 * base after 2 s. Its linear fit is exact for the hydrostatic field and equals the mean inside
	 * a regular lattice. The consistent projection solves for p^{t+1} itself, so the bias drops
	 * out there and the mean stays (docs/numerics.md, "Water at rest under gravity"). */
	if (mean_pressure)
		normalise(nodes, f->pressure, 1, f->mass_w_points);
	else   /* nodes no water point reaches keep reset_grid's 0, as the mean gives them */
		p2g_scalar_linear_fit(&s->grid, w, w->mass, w->pressure, f->fit_moments, f->pressure);
	for (idx_t I = 0; I < nodes; I++)   /* Eq. 50: grid porosity times sum S rho_w V_wp */
		f->mass_w[I] = f->porosity[I] * s->rho_w * f->mass_w_v[I];
	memcpy(f->v_w_old, f->v_w, 2 * sizeof(double) * (size_t)nodes);
}

/* Steps 3-4: the water and soil predictors (Eqs. 52-53 with Eqs. 54-59).
 *
 * The paper evaluates the drag of the water predictor with the old soil velocity (Eq. 25), so
 * that Eq. 53 gives v_w* alone and Eq. 52 then gives v_s*. The soil then feels the drag
 * explicitly: an error e in v_s is multiplied each step by 1 - (M_w / M_s) Q dt / (M_w + Q dt),
 * which leaves (-1, 1) wherever water collects over little soil (M_w / M_s above about 4 for the
 * Xie-Leo column; the soil surface once expelled water stands on it), and the soil velocity there
 * grows without bound. We therefore solve the two predictors together at each node:
 *     M_w (v_w* - v_w) = dt (F_w - Q (v_w* - v_s*))                    (Eq. 53 with v_s*)
 *     M_s (v_s* - v_s) + M_w (v_w* - v_w) = dt F                        (Eq. 52)
 * a 2x2 system per node and component with a positive determinant M_s M_w + Q dt (M_s + M_w).
 * It is still local (no global system), and equals the paper's predictor as Q dt / M_w -> 0.
 * Nodal forces: F_w = F_w^ext - F_w^int (Eqs. 56-57), F = F^ext - F^int (Eqs. 54-55). */
/* Share of a node's water that lies in the soil: soil-point volume over water-point volume, at
 * most 1. Eqs. 46-47 give nodes at the soil surface the soil's porosity and conductivity however
 * little soil reaches them, so Eq. 58 would drag the free water expelled above the soil as if it
 * filled pores: that layer then resists drainage like soil and consolidation stalls (the
 * double-point Xie-Leo column stopped near U = 0.5). Single point: always 1. */
static double soil_fraction(const struct grid_fields *f, idx_t I)
{
	if (!(f->mass_w_v[I] > 0.0))
		return 1.0;
	return fmin(1.0, f->volume_s[I] / f->mass_w_v[I]);
}

static void predict_velocities(struct sim *s)
{
	struct grid_fields *f = &s->f;
	const struct particles *p = &s->soil, *w = &s->water;
	const double dt = s->dt;
	p2g_internal_force(&s->grid, p, p->volume, p->stress, NULL, f->force);
	if (s->ps.exact) {
		/* pressure forces through the same G the correction uses: G_w p^t and (G_s + G_w) p^t */
		pressure_gradient_operators(s);
		pressure_apply_gradient(s, s->ps.grad_w, f->pressure, f->force_w);
		pressure_apply_gradient(s, s->ps.grad_w, f->pressure, f->force);
		pressure_apply_gradient(s, s->ps.grad_s, f->pressure, f->force);
	} else {
		p2g_internal_force(&s->grid, w, w->volume, NULL, w->pressure, f->force_w);
		p2g_internal_force(&s->grid, w, w->volume, NULL, w->pressure, f->force);
	}
	loads_add_tractions(s, s->time + dt, f->force);
	for (idx_t I = 0; I < s->grid.node_count; I++) {
		const double n = f->porosity[I], Ms = f->mass_s[I], Mw = f->mass_w[I];
		double Q = 0.0;            /* Eq. 58, for the water that lies in the soil */
		if (Ms > 0.0 && Mw > 0.0 && f->conductivity[I] > 0.0)
			Q = CONDUCTIVITY_GRAVITY * n / f->conductivity[I] * Mw * soil_fraction(f, I);
		for (int c = 0; c < 2; c++) {
			const int k = 2 * I + c;
			/* Eq. 56 is M_wI b; Eq. 57 carries the nodal porosity; Eq. 54 adds M_s b */
			const double Fw = (s->ps.exact ? 1.0 : n) * f->force_w[k] + Mw * s->gravity[c];
			const double F = f->force[k] + (Ms + Mw) * s->gravity[c];
			f->force_w[k] = Fw;
			f->force[k] = F;
			/* the 2x2 system of the comment above (phase_coupling.h); a constrained phase
			 * keeps v* = 0 and takes the wall's reaction, the other feels drag against it
			 * (the mixture equation would hand the reaction to the free phase) */
			const struct phase_coupling K = phase_coupling_inverse(Ms, Mw, Q * dt, f->fix_s[I] & (1 << c),
									       f->fix_w[I] & (1 << c));
			const double r_s = Ms * f->v_s[k] + dt * (F - Fw), r_w = Mw * f->v_w[k] + dt * Fw;
			f->v_s_star[k] = K.ss * r_s + K.sw * r_w;
			f->v_w_star[k] = K.sw * r_s + K.ww * r_w;
		}
		f->drag_dt[I] = Q * dt;
	}
	boundary_apply(&s->grid, f->fix_w, f->v_w_star);   /* (3e) */
	boundary_apply(&s->grid, f->fix_s, f->v_s_star);   /* (4d) */
	plate_predict(s);                                  /* rigid plates: their walls move with V* */
}

/* Step 6: velocity correction, Eqs. 64-68. The pressure increment pushes the soil with
 * f_s = dt G_s dp and the water with f_w = dt G_w dp (G = G_s + G_w, so their sum is Eq. 64).
 * The paper's Eq. 65 moves the water by f_w / M_w alone, without drag: each step the phases then
 * separate by dt^2 grad(dp) / rho whatever the permeability, which at k = 1e-9 m/s is a million
 * times the Darcy flux and drains a column far faster than it can (docs/numerics.md). With
 * formulation.drag_in_correction the correction takes the drag at the new
 * velocities, as the predictors do (phase_coupling.h), and the pressure matrix agrees with it.
 * Off by default while its effect on the verification cases is measured (docs/numerics.md). */
static void correct_velocities(struct sim *s)
{
	struct grid_fields *f = &s->f;
	const struct grid *g = &s->grid;
	const int drag = s->spec->formulation.drag_in_correction;
	/* with the weak free-surface condition G carries the surface's push (free_surface.c), which
	 * a sum over the points cannot rebuild; G also carries the nodal porosity factors */
	const int weak = s->spec->formulation.free_surface == FREE_SURFACE_WEAK;
	if (weak) {
		memset(f->correction_s, 0, 2 * sizeof(double) * (size_t)g->node_count);
		memset(f->correction_w, 0, 2 * sizeof(double) * (size_t)g->node_count);
		pressure_apply_gradient(s, s->ps.grad_s, f->dp, f->correction_s);
		pressure_apply_gradient(s, s->ps.grad_w, f->dp, f->correction_w);
	} else {
		p2g_point_gradient(g, &s->soil, s->soil.volume, f->dp, f->correction_s);
		p2g_point_gradient(g, &s->water, s->water.volume, f->dp, f->correction_w);
	}
	for (idx_t I = 0; I < g->node_count; I++) {
		const double n = f->porosity[I], share_s = weak ? 1.0 : 1.0 - n, share_w = weak ? 1.0 : n;
		for (int c = 0; c < 2; c++) {
			const int k = 2 * I + c;
			const struct phase_coupling K = phase_coupling_inverse(
				f->mass_s[I], f->mass_w[I], drag ? f->drag_dt[I] : 0.0, f->fix_s[I] & (1 << c),
				f->fix_w[I] & (1 << c));
			const double f_s = s->dt * share_s * f->correction_s[k], f_w = s->dt * share_w * f->correction_w[k];
			f->v_s[k] = f->mass_s[I] > 0.0 ? f->v_s_star[k] + K.ss * f_s + K.sw * f_w : 0.0;
			f->v_w[k] = f->mass_w[I] > 0.0 ? f->v_w_star[k] + K.sw * f_s + K.ww * f_w : 0.0;
		}
	}
	boundary_apply(g, f->fix_w, f->v_w);
	boundary_apply(g, f->fix_s, f->v_s);
	plate_correct(s);   /* rigid plates: V = V* + the increment's push on them */
}

/* x_p += dt v_p for every point of the set; returns how many then lie beyond a grid face. */
static idx_t advance_positions(const struct sim *s, struct particles *p)
{
	idx_t beyond = 0;
	for (idx_t q = 0; q < p->n; q++) {
		p->x[2 * q] += s->dt * p->v[2 * q];
		p->x[2 * q + 1] += s->dt * p->v[2 * q + 1];
		beyond += grid_beyond_face(&s->grid, p->x + 2 * q);
	}
	return beyond;
}

/* Step 7a-b for one set: the velocity update, FLIP blended with PIC by flip_fraction (000 §4.5),
 * APIC, or AFLIP (the FLIP blend, and APIC's affine velocity gathered beside it; transfer.h), and
 * the position update x += dt sum S v^{t+1}. v_old is overwritten with the nodal increment.
 * Returns how many moved points lie beyond a grid face (0 if the positions stay). */
static idx_t move_points(struct sim *s, struct particles *p, const double *v_new, double *v_old, int move_positions)
{
	if (s->spec->formulation.velocity_update == VELOCITY_UPDATE_APIC) {
		gather_velocity(s, p, v_new, p->v);   /* APIC's point velocity is the PIC one */
		return move_positions ? advance_positions(s, p) : 0;
	}
	for (idx_t I = 0; I < 2 * s->grid.node_count; I++)
		v_old[I] = v_new[I] - v_old[I];
	const idx_t beyond = g2p_flip_update(&s->grid, p, v_new, v_old, s->spec->formulation.flip_fraction, s->dt,
					     move_positions);
	if (s->spec->formulation.velocity_update == VELOCITY_UPDATE_AFLIP)
		g2p_affine_velocity(&s->grid, p, v_new, NULL, p->C);
	return beyond;
}

/* 000 §5.4's initialisation with gravity.water_attached: the water points take the soil's nodal
 * velocity (PIC) and move with it, so the loading causes no seepage between the point sets; the
 * pressure solve still carries the water's weight. Single point: the positions are the soil's. */
static idx_t attach_water_to_soil(struct sim *s)
{
	struct particles *w = &s->water;
	gather_velocity(s, w, s->f.v_s, w->v);
	return s->double_point ? advance_positions(s, w) : 0;
}

/* Step 7: points take velocities, positions and the new pore pressure from the grid. Returns how
 * many water points lie beyond a grid face (for remove_outflowing_water). */
static idx_t update_points(struct sim *s)
{
	struct grid_fields *f = &s->f;
	idx_t water_beyond;
	move_points(s, &s->soil, f->v_s, f->v_s_old,
		    s->spec->formulation.position_update == POSITION_UPDATE_GRID_VELOCITY);
	if (s->spec->gravity.water_attached && in_gravity_ramp(s))
		water_beyond = attach_water_to_soil(s);
	else
		water_beyond = move_points(s, &s->water, f->v_w, f->v_w_old, s->double_point);
	if (s->spec->formulation.pore_pressure_smoothing) {
		/* 7c with 9a: p^{t+1}_I = p^t_I + dp_I, p^t_I being the smoothed nodal pressure of
		 * step 2 (Eq. 77's inner sum), interpolated back to the points (Eq. 77's outer sum) */
		for (idx_t I = 0; I < s->grid.node_count; I++)   /* free surface, drained faces: 0 */
			f->pressure[I] = f->dirichlet[I] && !s->ps.exact ? 0.0 : f->pressure[I] + f->dp[I];
		g2p_scalar(&s->grid, &s->water, f->pressure, s->water.pressure);
	} else {
		/* unsmoothed: each point keeps its pressure and adds the interpolated increment */
		g2p_scalar(&s->grid, &s->water, f->dp, s->water_scalar);
		for (idx_t q = 0; q < s->water.n; q++)
			s->water.pressure[q] += s->water_scalar[q];
	}
	return water_beyond;
}

/* Water points that crossed a grid face where water moves freely (a drained face, or open air)
 * have left the domain: they are removed and their mass booked as outflow, so the water balance
 * stays checkable (double point only: the single-point water has no points of its own). Point
 * probes following a removed point stop. Crossing a wall is an error reported by step 1. The
 * search is skipped when step 7 found no water point beyond a face (beyond: its count). */
static void remove_outflowing_water(struct sim *s, idx_t beyond)
{
	struct particles *w = &s->water;
	const struct case_boundary *bc = s->spec->boundaries;
	if (!s->double_point || beyond == 0)
		return;
	for (idx_t q = w->n - 1; q >= 0; q--) {
		const int face = grid_face_beyond(&s->grid, w->x + 2 * q);
		if (face < 0 || bc[face].water != CONSTRAINT_FREE)
			continue;
		s->water_outflow_mass += w->mass[q];
		for (int i = 0; i < s->spec->probe_count; i++) {
			if (s->spec->probes[i].kind != PROBE_PORE_PRESSURE)
				continue;
			if (s->probe_point[i] == q)
				s->probe_point[i] = -1;
			else if (s->probe_point[i] == w->n - 1)
				s->probe_point[i] = (int)q;
		}
		particles_remove(w, q);
	}
}

/* Node-wise mapping and remapping of a soil-point scalar (000 Eq. 80, steps 9b-9c):
 * avg_p = sum_I S_Ip (sum_q S_Iq m_q value_q / M_sI). The nodal pressure array is free after
 * step 7 and holds the nodal average. */
static void average_nodewise(struct sim *s, const double *value, double *avg)
{
	struct particles *p = &s->soil;
	double *nodal = s->f.pressure;
	memset(nodal, 0, sizeof(double) * (size_t)s->grid.node_count);
	p2g_scalar(&s->grid, p, p->mass, value, nodal);
	normalise(s->grid.node_count, nodal, 1, s->f.mass_s);
	g2p_scalar(&s->grid, p, nodal, avg);
}

/* The patch of point q in the fixed tiling laid out by stabilisation_patches_init. */
static idx_t patch_of(const struct sim *s, idx_t q)
{
	idx_t ij[2];
	for (int d = 0; d < 2; d++) {
		double u = (s->soil.x[2 * q + d] - s->grid.origin[d]) / s->patch_width[d];
		idx_t i = (idx_t)floor(u);
		ij[d] = i < 0 ? 0 : i >= s->patches[d] ? s->patches[d] - 1 : i;
	}
	return ij[0] + ij[1] * s->patches[0];
}

/* Patch-wise mass average of a soil-point scalar (000 Eq. 83): every point of a patch gets
 * sum_{q in patch} m_q value_q / sum_{q in patch} m_q. */
static void average_patchwise(struct sim *s, const double *value, double *avg)
{
	const struct particles *p = &s->soil;
	const idx_t count = s->patches[0] * s->patches[1];
	memset(s->patch_mass, 0, sizeof(double) * (size_t)count);
	memset(s->patch_mass_Je, 0, sizeof(double) * (size_t)count);
	for (idx_t q = 0; q < p->n; q++) {
		idx_t k = patch_of(s, q);
		s->patch_mass[k] += p->mass[q];
		s->patch_mass_Je[k] += p->mass[q] * value[q];
	}
	for (idx_t q = 0; q < p->n; q++) {
		idx_t k = patch_of(s, q);   /* a point's own patch has its mass: the division is safe */
		avg[q] = s->patch_mass_Je[k] / s->patch_mass[k];
	}
}

/* The patch size h_patch of 000 §4.4.2: 1.5 h for quadratic and cubic B-splines, the cell for
 * linear shape functions and for the cell-wise variant (App. A's h_patch = h). The grid is tiled
 * by round(extent / h_patch) patches per direction of equal width, so no sliver patch is left at
 * the far edge (10 m at h = 0.2 m: 33 patches of 0.303 m). Patches are fixed in space for the run
 * ("defined only once"); a point belongs to the patch that contains it at the time. */
void stabilisation_patches_init(struct sim *s)
{
	const struct case_formulation *f = &s->spec->formulation;
	const double cells_per_patch = f->soil_stabilisation == STABILISATION_MODIFIED_FBAR &&
				       f->shape != SHAPE_LINEAR ? 1.5 : 1.0;
	for (int d = 0; d < 2; d++) {
		idx_t n = (idx_t)lround((double)s->grid.cells[d] / cells_per_patch);
		s->patches[d] = n < 1 ? 1 : n;
		s->patch_width[d] = (double)s->grid.cells[d] * s->grid.h / (double)s->patches[d];
	}
}

/* Steps 9c-9d, F-bar (000 Eqs. 79-80): each soil point's deformation-gradient increment is scaled
 * so that its volume change equals the node-wise average dJbar, dFbar = (dJbar / dJ)^(1/dof) dF,
 * dof = 2. The scaled increment serves the volume, porosity and stress updates alike, so the
 * points' volumes stay those the stress sees. Shared by the standard and the modified F-bar. */
static void apply_fbar(struct sim *s)
{
	struct particles *p = &s->soil;
	double *dJ = s->soil_scalar, *dJbar = s->soil_coef;
	for (idx_t q = 0; q < p->n; q++) {
		const double *dF = p->dF + 4 * q;
		dJ[q] = dF[0] * dF[3] - dF[1] * dF[2];
	}
	average_nodewise(s, dJ, dJbar);
	for (idx_t q = 0; q < p->n; q++) {
		if (!(dJ[q] > 0.0) || !(dJbar[q] > 0.0))
			continue;   /* an inverted point is reported by the caller */
		const double scale = sqrt(dJbar[q] / dJ[q]);
		for (int c = 0; c < 4; c++)
			p->dF[4 * q + c] *= scale;
	}
}

/* Steps 9e-9g, modified F-bar (000 Eqs. 81-83): the elastic Jacobian of the last step,
 * J^e = sqrt(det Be^t) with det over the full 3x3 tensor (Be_zz included), is replaced by its
 * patch-wise mass average: Be^t is scaled so that its J^e becomes Jbar^e. Eq. 82 writes the factor
 * (Jbar^e / J^e)^(2/3), which scales all of a 3-D Be; in plane strain we scale the in-plane block
 * by (Jbar^e / J^e)^(2/dof), dof = 2 (as Eq. 79 does for dF), and keep Be_zz: the determinant then
 * reaches Jbar^e^2 just the same and the out-of-plane stretch stays that of plane strain. Models
 * without an evolving Be (small strain) keep Be = I, J^e = 1, and are untouched. */
static void stabilise_elastic_strain(struct sim *s)
{
	struct particles *p = &s->soil;
	double *Je = s->soil_scalar, *Jebar = s->soil_coef;
	for (idx_t q = 0; q < p->n; q++) {
		const double *Be = p->Be + 4 * q;
		double det = (Be[0] * Be[1] - Be[2] * Be[2]) * Be[3];
		Je[q] = det > 0.0 ? sqrt(det) : 0.0;
	}
	average_patchwise(s, Je, Jebar);
	for (idx_t q = 0; q < p->n; q++) {
		if (!(Je[q] > 0.0) || !(Jebar[q] > 0.0))
			continue;   /* a degenerate Be is reported by the stress update */
		const double scale = Jebar[q] / Je[q];
		for (int c = 0; c < 3; c++)
			p->Be[4 * q + c] *= scale;
	}
}

/* Step 9b-9g: the soil-phase stabilisation chosen by the case (000 §4.4.2). The pore-pressure
 * smoothing (9a) is part of step 7c (see the top of this file). */
static void stabilise_soil(struct sim *s)
{
	const enum soil_stabilisation kind = s->spec->formulation.soil_stabilisation;
	if (kind == STABILISATION_NONE)
		return;
	apply_fbar(s);                                     /* (9c-d) Eqs. 79-80 */
	if (kind == STABILISATION_MODIFIED_FBAR || kind == STABILISATION_MODIFIED_FBAR_CELLWISE)
		stabilise_elastic_strain(s);               /* (9e-g) Eqs. 82-83 */
}

/* Step 8: MUSL displacement increment (8a), deformation gradient increment (8b-c), volume,
 * Jacobian and porosity (8d-f), conductivity: Kozeny-Carman (8g) or proportional to J. */
static enum poro_status update_soil_kinematics(struct sim *s)
{
	struct particles *p = &s->soil;
	struct grid_fields *f = &s->f;
	map_momentum(s, p, f->du_s);
	for (idx_t I = 0; I < s->grid.node_count; I++)
		for (int c = 0; c < 2; c++)
			f->du_s[2 * I + c] = f->mass_s[I] > 0.0 ? s->dt * f->du_s[2 * I + c] / f->mass_s[I] : 0.0;
	boundary_apply(&s->grid, f->fix_s, f->du_s);
	plate_displace(s, f->du_s);
	g2p_vector_gradient(&s->grid, p, f->du_s, p->dF);
	if (s->spec->formulation.position_update == POSITION_UPDATE_MUSL_DISPLACEMENT) {
		/* 7b from the field whose gradient is dF, so volume and motion stay one (file comment) */
		g2p_vector(&s->grid, p, f->du_s, s->soil_grad);
		for (idx_t k = 0; k < 2 * p->n; k++)
			p->x[k] += s->soil_grad[k];
	}
	for (idx_t q = 0; q < p->n; q++) {
		p->dF[4 * q] += 1.0, p->dF[4 * q + 3] += 1.0;
	}
	stabilise_soil(s);   /* (9b-g) before the volume update, so volume and stress see one dF */
	idx_t bad = -1;
	for (idx_t q = 0; q < p->n; q++) {
		double *dF = p->dF + 4 * q, *F = p->F + 4 * q;
		double dJ = dF[0] * dF[3] - dF[1] * dF[2];
		double F0 = dF[0] * F[0] + dF[1] * F[2], F1 = dF[0] * F[1] + dF[1] * F[3];
		double F2 = dF[2] * F[0] + dF[3] * F[2], F3 = dF[2] * F[1] + dF[3] * F[3];
		F[0] = F0, F[1] = F1, F[2] = F2, F[3] = F3;
		p->volume[q] *= dJ;
		double J = p->volume[q] / p->volume0[q];
		double n = 1.0 - (1.0 - p->porosity0[q]) / J;
		if (!(dJ > 0.0) || !(n > 0.0 && n < 1.0)) {
			bad = q;
			break;
		}
		p->porosity[q] = n;
		const struct case_body *body = &s->spec->bodies[p->body[q]];
		p->conductivity[q] = permeability_conductivity(body->permeability_law, body->hydraulic_conductivity,
							       p->porosity0[q], n, J);   /* (8g) */
	}
	if (bad >= 0)
		return poro_error_set(&s->err, PORO_ESOLVER, "soil point %ld at (%.6g, %.6g) m: volume ratio %.6g "
				      "gives porosity outside (0, 1) or an inverted point at step %ld (J must stay "
				      "above 1 - n0 = %.6g, where the pores close)",
				      (long)bad, p->x[2 * bad], p->x[2 * bad + 1], p->volume[bad] / p->volume0[bad],
				      s->step + 1, 1.0 - p->porosity0[bad]);
	return PORO_OK;
}

/* Step 10: stress update through the material interface (Eqs. 69-76). The points are independent;
 * they are shared among the threads in small dynamic chunks (a plastic return costs several times an
 * elastic one, and plastic points cluster). Every point is updated, and the failure reported is the
 * lowest-numbered failing point's, as a serial loop would report it, whatever the thread count. */
static enum poro_status update_stress(struct sim *s)
{
	struct particles *p = &s->soil;
	const int stage = gravity_loading_stage(s);
	idx_t first_failure = p->n;
	/* 000 Eqs. 96-97: Nor-Sand's specific volume from J mapped to the nodes and back (step 9's
	 * node-wise averaging, on the total J^{t+1}); the stress keeps the point's own J */
	const double *J_v = NULL;
	if (s->spec->formulation.specific_volume == SPECIFIC_VOLUME_NODAL_AVERAGE) {
		for (idx_t q = 0; q < p->n; q++)
			s->soil_scalar[q] = p->volume[q] / p->volume0[q];
		average_nodewise(s, s->soil_scalar, s->soil_coef);
		J_v = s->soil_coef;
	}
	#pragma omp parallel
	{
		struct poro_error err;   /* filled by the thread's first failure only */
		idx_t failed = p->n;
		#pragma omp for schedule(dynamic, 64)
		for (idx_t q = 0; q < p->n; q++) {
			const struct material *m = &s->materials[s->spec->bodies[p->body[q]].material];
			const double *dF = p->dF + 4 * q;
			if (stage == 2) {   /* the volume is already this step's: J at the end of the ramp is J / dJ */
				const double J_ramp = p->volume[q] / p->volume0[q] / (dF[0] * dF[3] - dF[1] * dF[2]);
				material_reset_reference(m, p->stress + 4 * q, p->Be + 4 * q, J_ramp,
							 p->state + STATE_MAX * q);
				p->plastic_strain[q] = 0.0;
			}
			struct stress_update u = {
				.dF = dF,
				.J = p->volume[q] / p->volume0[q],
				.J_v = J_v ? J_v[q] : 0.0,
				.stress = p->stress + 4 * q,
				.Be = p->Be + 4 * q,
				.state = p->state + STATE_MAX * q,
				.plastic_strain = p->plastic_strain + q,
				.elastic_only = stage == 1,
			};
			/* a thread takes its chunks in increasing order: its first failure is its lowest */
			if (material_update(m, &u, failed < p->n ? NULL : &err) != PORO_OK && failed == p->n)
				failed = q;
		}
		#pragma omp critical(stress_update_failure)
		if (failed < first_failure) {
			first_failure = failed;
			s->err = err;
		}
	}
	return first_failure < p->n ? s->err.code : PORO_OK;
}

/* Runs one phase and adds its wall time to the phase's account. */
#define PHASE(which, call)                                              \
	do {                                                            \
		double t0_ = sim_clock();                               \
		call;                                                   \
		s->phase_seconds[which] += sim_clock() - t0_;           \
	} while (0)

enum poro_status semi_implicit_step(struct sim *s)
{
	enum poro_status st = PORO_OK;
	loads_gravity(s->spec, s->time + s->dt, s->gravity);                 /* b^{t+1} */
	PHASE(PHASE_SHAPE, st = evaluate_shape_functions(s));                /* (1) */
	if (st)
		return st;
	PHASE(PHASE_P2G, {
		reset_grid(s);
		map_soil_to_grid(s);                                         /* (2a-d) */
		map_water_to_grid(s);                                        /* (2e-f), (8h-i) */
	});
	/* (5b) ahead of the predictors: the weak free-surface condition's G (free_surface.c) needs
	 * the surface, and nothing it reads changes before the pressure solve */
	PHASE(PHASE_PRESSURE_ASSEMBLY, free_surface_mark(s));
	PHASE(PHASE_PREDICT, predict_velocities(s));                         /* (3)-(4) Eqs. 52-53 */
	TRY(pressure_solve(s));                                              /* (5) Eq. 60 */
	PHASE(PHASE_CORRECT, correct_velocities(s));                         /* (6) Eqs. 64-65 */
	PHASE(PHASE_G2P, {
		remove_outflowing_water(s, update_points(s));                /* (7) */
	});
	PHASE(PHASE_KINEMATICS, st = update_soil_kinematics(s));            /* (8) */
	if (st)
		return st;
	PHASE(PHASE_STRESS, st = update_stress(s));                          /* (10) */
	if (st)
		return st;
	s->time = (double)(s->step + 1) * s->dt;   /* no drift from summing dt */
	s->step++;
	return PORO_OK;
}
