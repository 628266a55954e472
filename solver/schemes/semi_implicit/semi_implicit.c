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
#include <stdlib.h>
#include <string.h>

#include "phase_coupling.h"
#include "phases.h"
#include "scheme.h"
#include "semi_implicit.h"
#include "transfer.h"

/* The scheme's nodal arrays of doubles with their widths and whether the step's reset zeroes them
 * (drag_dt and mobility_ratio are written at every node before they are read). */
#define SEMI_IMPLICIT_NODAL_FIELDS(X)                                                               \
	X(v_s_star, DIM, 1) X(v_w_star, DIM, 1) X(drag_dt, 1, 0) X(mobility_ratio, 1, 0) X(dp, 1, 1)   \
	X(rhs, 1, 1) X(correction_s, DIM, 1) X(correction_w, DIM, 1)

static void destroy(struct sim *s)
{
	struct semi_implicit *si = semi_implicit_of(s);
	if (!si)
		return;
	pressure_system_release(&si->ps);
#define FREE(name, width, reset) free(si->name);
	SEMI_IMPLICIT_NODAL_FIELDS(FREE)
#undef FREE
	free(si->cell_wet);
	free(si->dirichlet);
	free(si->surface);
	free(si->cell_fill);
	free(si->cell_fill_soil);
	free(si->plate_work);
	free(si);
	s->scheme_state = NULL;
}

static enum poro_status create(struct sim *s)
{
	const struct case_formulation *form = &s->spec->formulation;
	const size_t nodes = (size_t)s->grid.node_count, cells = (size_t)s->grid.cell_count;
	struct semi_implicit *si = calloc(1, sizeof *si);
	if (!(s->scheme_state = si))
		return poro_error_set(&s->err, PORO_ENOMEM, "cannot allocate the semi-implicit scheme's state");
	int ok = 1;
#define ALLOC(name, width, reset) if (ok) ok = (si->name = calloc(nodes * (width), sizeof(double))) != NULL;
	SEMI_IMPLICIT_NODAL_FIELDS(ALLOC)
#undef ALLOC
	ok = ok && (si->cell_wet = calloc(cells, 1)) && (si->dirichlet = calloc(nodes, 1)) &&
	     (si->surface = calloc(nodes, 1)) && (si->cell_fill = calloc(cells, sizeof(double))) &&
	     (si->cell_fill_soil = calloc(cells, sizeof(double)));
	int plates = 0;
	for (int f = 0; f < FACE_COUNT; f++)
		plates += s->spec->boundaries[f].soil == CONSTRAINT_PLATE;
	if (ok && plates)
		ok = (si->plate_work = calloc((size_t)(FACE_COUNT + 2) * nodes, sizeof(double))) != NULL;
	if (!ok)
		return poro_error_set(&s->err, PORO_ENOMEM, "cannot allocate the semi-implicit scheme's grid of %ld nodes",
				      (long)nodes);
	return pressure_system_init(&si->ps, &s->grid, s->soil.support, form->pressure_projection,
				    form->free_surface != FREE_SURFACE_NODES, &s->err);
}

/* Step 2's reset: the grid carries nothing from the last step (000 §4.5). */
static void reset_grid(struct sim *s)
{
	struct semi_implicit *si = semi_implicit_of(s);
	const size_t n = (size_t)s->grid.node_count;
	grid_fields_reset(&s->f, &s->grid);
#define ZERO(name, width, reset) if (reset) grid_zero(si->name, n * (width));
	SEMI_IMPLICIT_NODAL_FIELDS(ZERO)
#undef ZERO
}

/* Step 2f's nodal pressure p^t. With the Laplacian, p^{t+1} = p^t + dp and the solve removes only
 * the part of an error in p^t that drives a divergence, so Eq. 77's mass-weighted mean, which is
 * the field's value at the points' centroid rather than at the node where the points lie to one
 * side (walls, the free surface), biased the hydrostatic pressure and the bias accumulated: 1.3%
 * at a column's base after 2 s. Its linear fit is exact for the hydrostatic field and equals the
 * mean inside a regular lattice. The consistent projection solves for p^{t+1} itself, so the bias
 * drops out there and the mean stays (docs/numerics.md, "Water at rest under gravity"). */
static enum nodal_pressure nodal_pressure_of(const struct sim *s)
{
	struct semi_implicit *si = semi_implicit_of(s);
	return si->ps.exact ? NODAL_PRESSURE_MEAN : NODAL_PRESSURE_LINEAR_FIT;
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
	struct semi_implicit *si = semi_implicit_of(s);
	struct grid_fields *f = &s->f;
	const struct particles *p = &s->soil, *w = &s->water;
	const double dt = s->dt;
	p2g_internal_force(&s->grid, p, p->volume, p->stress, NULL, f->force);
	if (si->ps.exact) {
		/* pressure forces through the same G the correction uses: G_w p^t and (G_s + G_w) p^t */
		pressure_gradient_operators(s);
		pressure_apply_gradient(s, si->ps.grad_w, f->pressure, f->force_w);
		pressure_apply_gradient(s, si->ps.grad_w, f->pressure, f->force);
		pressure_apply_gradient(s, si->ps.grad_s, f->pressure, f->force);
	} else {
		p2g_internal_force(&s->grid, w, w->volume, NULL, w->pressure, f->force_w);
		p2g_internal_force(&s->grid, w, w->volume, NULL, w->pressure, f->force);
	}
	loads_add_tractions(s, s->time + dt, f->force);
	#pragma omp parallel for schedule(static)
	for (idx_t I = 0; I < s->grid.node_count; I++) {
		const double n = f->porosity[I], Ms = f->mass_s[I], Mw = f->mass_w[I];
		double Q = 0.0;            /* Eq. 58, for the water that lies in the soil */
		if (Ms > 0.0 && Mw > 0.0 && f->conductivity[I] > 0.0)
			Q = CONDUCTIVITY_GRAVITY * n / f->conductivity[I] * Mw * soil_fraction(f, I);
		for (int c = 0; c < 2; c++) {
			const int k = 2 * I + c;
			/* Eq. 56 is M_wI b; Eq. 57 carries the nodal porosity; Eq. 54 adds M_s b */
			const double Fw = (si->ps.exact ? 1.0 : n) * f->force_w[k] + Mw * s->gravity[c];
			const double F = f->force[k] + (Ms + Mw) * s->gravity[c];
			f->force_w[k] = Fw;
			f->force[k] = F;
			/* the 2x2 system of the comment above (phase_coupling.h); a constrained phase
			 * keeps v* = 0 and takes the wall's reaction, the other feels drag against it
			 * (the mixture equation would hand the reaction to the free phase) */
			const struct phase_coupling K = phase_coupling_inverse(Ms, Mw, Q * dt, f->fix_s[I] & (1 << c),
									       f->fix_w[I] & (1 << c));
			const double r_s = Ms * f->v_s[k] + dt * (F - Fw), r_w = Mw * f->v_w[k] + dt * Fw;
			si->v_s_star[k] = K.ss * r_s + K.sw * r_w;
			si->v_w_star[k] = K.sw * r_s + K.ww * r_w;
		}
		si->drag_dt[I] = Q * dt;
	}
	boundary_apply(&s->grid, f->fix_w, si->v_w_star);   /* (3e) */
	boundary_apply(&s->grid, f->fix_s, si->v_s_star);   /* (4d) */
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
	struct semi_implicit *si = semi_implicit_of(s);
	struct grid_fields *f = &s->f;
	const struct grid *g = &s->grid;
	const int drag = s->spec->formulation.drag_in_correction;
	/* with the weak free-surface condition G carries the surface's push (free_surface.c), which
	 * a sum over the points cannot rebuild; G also carries the nodal porosity factors */
	const int weak = s->spec->formulation.free_surface == FREE_SURFACE_WEAK;
	if (weak) {
		memset(si->correction_s, 0, 2 * sizeof(double) * (size_t)g->node_count);
		memset(si->correction_w, 0, 2 * sizeof(double) * (size_t)g->node_count);
		pressure_apply_gradient(s, si->ps.grad_s, si->dp, si->correction_s);
		pressure_apply_gradient(s, si->ps.grad_w, si->dp, si->correction_w);
	} else {   /* the pressure pushes the saturated skeleton only (semi_implicit_wet_soil) */
		const struct particles wet = semi_implicit_wet_soil(s);
		p2g_point_gradient(g, &wet, wet.volume, si->dp, si->correction_s);
		p2g_point_gradient(g, &s->water, s->water.volume, si->dp, si->correction_w);
	}
	#pragma omp parallel for schedule(static)
	for (idx_t I = 0; I < g->node_count; I++) {
		const double n = f->porosity[I], share_s = weak ? 1.0 : 1.0 - n, share_w = weak ? 1.0 : n;
		for (int c = 0; c < 2; c++) {
			const int k = 2 * I + c;
			const struct phase_coupling K = phase_coupling_inverse(
				f->mass_s[I], f->mass_w[I], drag ? si->drag_dt[I] : 0.0, f->fix_s[I] & (1 << c),
				f->fix_w[I] & (1 << c));
			const double f_s = s->dt * share_s * si->correction_s[k], f_w = s->dt * share_w * si->correction_w[k];
			f->v_s[k] = f->mass_s[I] > 0.0 ? si->v_s_star[k] + K.ss * f_s + K.sw * f_w : 0.0;
			f->v_w[k] = f->mass_w[I] > 0.0 ? si->v_w_star[k] + K.sw * f_s + K.ww * f_w : 0.0;
		}
	}
	boundary_apply(g, f->fix_w, f->v_w);
	boundary_apply(g, f->fix_s, f->v_s);
	plate_correct(s);   /* rigid plates: V = V* + the increment's push on them */
}

/* Step 7: points take velocities, positions and the new pore pressure from the grid. Returns how
 * many water points lie beyond a grid face (for point_motion_remove_outflow). */
static idx_t update_points(struct sim *s)
{
	struct semi_implicit *si = semi_implicit_of(s);
	struct grid_fields *f = &s->f;
	idx_t water_beyond;
	point_motion_update(s, &s->soil, f->v_s, f->v_s_old,
			    s->spec->formulation.position_update == POSITION_UPDATE_GRID_VELOCITY);
	if (s->spec->gravity.water_attached && loads_in_gravity_ramp(s))
		water_beyond = point_motion_attach_water(s);
	else
		water_beyond = point_motion_update(s, &s->water, f->v_w, f->v_w_old, s->double_point);
	if (s->spec->formulation.pore_pressure_smoothing) {
		/* 7c with 9a: p^{t+1}_I = p^t_I + dp_I, p^t_I being the smoothed nodal pressure of
		 * step 2 (Eq. 77's inner sum), interpolated back to the points (Eq. 77's outer sum) */
		#pragma omp parallel for schedule(static)
		for (idx_t I = 0; I < s->grid.node_count; I++)   /* free surface, drained faces: 0 */
			f->pressure[I] = si->dirichlet[I] && !si->ps.exact ? 0.0 : f->pressure[I] + si->dp[I];
		g2p_scalar(&s->grid, &s->water, f->pressure, s->water.pressure);
	} else {
		/* unsmoothed: each point keeps its pressure and adds the interpolated increment */
		g2p_scalar(&s->grid, &s->water, si->dp, s->water_scalar);
		#pragma omp parallel for schedule(static)
		for (idx_t q = 0; q < s->water.n; q++)
			s->water.pressure[q] += s->water_scalar[q];
	}
	return water_beyond;
}

/* Step 8a: the MUSL displacement increment du_s = dt sum S m v^{t+1} / M_s (the points' updated
 * velocities mapped back), with the walls' and plates' constraints. */
static void map_displacement(struct sim *s)
{
	struct grid_fields *f = &s->f;
	point_map_momentum(s, &s->soil, f->du_s);
	#pragma omp parallel for schedule(static)
	for (idx_t I = 0; I < s->grid.node_count; I++)
		for (int c = 0; c < DIM; c++)
			f->du_s[DIM * I + c] = f->mass_s[I] > 0.0 ? s->dt * f->du_s[DIM * I + c] / f->mass_s[I] : 0.0;
	boundary_apply(&s->grid, f->fix_s, f->du_s);
	plate_displace(s, f->du_s);
}

/* Step 8: the displacement increment (8a), the deformation-gradient increment (8b-c), the case's
 * soil stabilisation (9b-g) before the volume update so that volume and stress see one dF, then
 * volume, Jacobian, porosity and conductivity (8d-g). */
static enum poro_status update_soil_kinematics(struct sim *s)
{
	map_displacement(s);
	deformation_increment(s, s->f.du_s);
	fbar_stabilise(s);
	return deformation_apply(s);
}

enum poro_status semi_implicit_step(struct sim *s)
{
	enum poro_status st = PORO_OK;
	loads_gravity(s->spec, s->time + s->dt, s->gravity);                 /* b^{t+1} */
	PHASE(PHASE_SHAPE, st = point_map_shapes(s));                        /* (1) */
	if (st)
		return st;
	PHASE(PHASE_P2G, {
		reset_grid(s);
		point_map_soil(s);                                           /* (2a-d) */
		point_map_water(s, nodal_pressure_of(s));                    /* (2e-f), (8h-i) */
	});
	/* (5b) ahead of the predictors: the weak free-surface condition's G (free_surface.c) needs
	 * the surface, and nothing it reads changes before the pressure solve */
	PHASE(PHASE_PRESSURE_ASSEMBLY, free_surface_mark(s));
	PHASE(PHASE_PREDICT, predict_velocities(s));                         /* (3)-(4) Eqs. 52-53 */
	TRY(pressure_solve(s));                                              /* (5) Eq. 60 */
	PHASE(PHASE_CORRECT, correct_velocities(s));                         /* (6) Eqs. 64-65 */
	PHASE(PHASE_G2P, {
		point_motion_remove_outflow(s, update_points(s));            /* (7) */
	});
	PHASE(PHASE_KINEMATICS, st = update_soil_kinematics(s));             /* (8), (9b-g) */
	if (st)
		return st;
	PHASE(PHASE_STRESS, st = stress_update(s));                          /* (10) */
	if (st)
		return st;
	s->time = (double)(s->step + 1) * s->dt;   /* no drift from summing dt */
	s->step++;
	return PORO_OK;
}

const struct scheme semi_implicit_scheme = {
	.name = "semi_implicit",
	.phase_names = { "shape functions", "particle-to-grid", "predictors", "pressure assembly",
			 "pressure factor+solve", "correction", "grid-to-particle", "kinematics", "stress update" },
	.create = create,
	.destroy = destroy,
	.step = semi_implicit_step,
};
