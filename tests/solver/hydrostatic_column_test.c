/*
 * hydrostatic_column_test.c - a saturated column at rest under gravity must stay at rest
 * (tests/cases/hydrostatic_column.json: the 1 m Terzaghi column, no load, gravity -9.81 m/s^2,
 * drained at the top, E = 10 MPa, nu = 0.3, k = 1e-3 m/s, 0.3 s).
 *
 * The column starts in its geostatic state, set here (case files have no initial-stress key): every
 * water point at the hydrostatic pressure rho_w g d, every soil point at sigma'_yy = -gamma' d,
 * sigma'_xx = sigma'_zz = K0 sigma'_yy with gamma' = (1 - n)(rho_s - rho_w) g and K0 = nu / (1 - nu)
 * (uniaxial strain), d the depth below the top. That state is the closed form: nothing may change.
 * Over the run, for each variant:
 *  - pore pressure: every point deeper than two cells within 1% of rho_w g d, every point within
 *    1% of rho_w g H (the nodal free-surface condition places p = 0 up to a cell from the surface,
 *    initial_state_test.c);
 *  - effective stress: every soil point deeper than two cells keeps sigma'_yy and sigma'_xx within
 *    1% of gamma' d and K0 gamma' d;
 *  - velocities: the largest nodal velocity of either phase over the last tenth of the run stays
 *    below REST_SHARE of k / n, the Darcy velocity of a unit gradient (0.0033 m/s here, the seepage
 *    a spurious force of the water's own weight would drive), plus REST_FLOOR for the elastic
 *    transient of the first steps where k is small.
 * Variants: double and single point; the default formulation (the paper's Laplacian, Eq. 65, p = 0
 * on nodes) and the low-permeability one of terzaghi_low_permeability.json (consistent projection,
 * drag in the correction, second-difference stabilisation, weak free surface), read from that case;
 * k = 1e-3 and 1e-9 m/s; the top on the grid's drained face (the case) and a free water surface
 * inside the grid (the grid 1.1 m high, as terzaghi.json's), where the node one cell beyond the
 * surface keeps moving, in the default formulation at about k / n, at the weak condition's ghost
 * node at a tenth of that (docs/numerics.md, "Water at rest under gravity"): a known failure of
 * the velocity check; the pressure and stress are printed. The free surface inside the grid runs
 * once more with APIC point velocities (double point; the cases name FLIP), asserted in full: the
 * low-permeability formulation then comes to rest (6.9e-8 m/s), the default one still moves
 * (1.1e-3 m/s, a known failure; docs/numerics.md, "Default point velocities: FLIP against APIC").
 * Before the linear-fit nodal pressure (transfer.h) the default formulation's pressure near the
 * base fell 0.95% (k = 1e-3) and 4.1% (k = 1e-9) below hydrostatic within the run, and its
 * effective stress took up 3.4% (k = 1e-9).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../harness.h"
#include "case.h"
#include "material.h"
#include "poro.h"
#include "sim_internal.h"

#define CASE_FILE "tests/cases/hydrostatic_column.json"
#define LOW_K_FILE "tests/cases/terzaghi_low_permeability.json"
#define G 9.81
#define PRESSURE_TOLERANCE 0.01   /* of rho_w g d below two cells, and of rho_w g H everywhere */
#define STRESS_TOLERANCE 0.01     /* of the geostatic value, below two cells */
#define REST_SHARE 0.05           /* of k / n */
#define REST_FLOOR 1e-6           /* m/s */
#define SKIN_CELLS 2.0

struct rest_run {
	int ok;
	double pressure_deep;     /* largest |p - rho_w g d| / (rho_w g d) below the skin, over the run */
	double pressure_all;      /* largest |p - rho_w g d| / (rho_w g H), over the run */
	double stress;            /* largest |sigma' - geostatic| / |geostatic| below the skin */
	double v_early, v_late;   /* largest nodal speed of either phase, first and last tenth, m/s */
	double v_allowed;         /* m/s */
};

/* The geostatic state of the column of height H (file comment). */
static void set_geostatic(struct sim *s, double H, double K0)
{
	const struct case_spec *c = s->spec;
	const struct case_body *b = &c->bodies[0];
	const double rho_s = c->materials[b->material].density, n = b->porosity;
	const double gamma = (1.0 - n) * (rho_s - s->rho_w) * G;
	struct particles *p = &s->soil;
	for (idx_t q = 0; q < p->n; q++) {
		double *st = p->stress + 4 * q;
		st[1] = -gamma * (H - p->x[2 * q + 1]);
		st[0] = st[3] = K0 * st[1];
		st[2] = 0.0;
		material_init_state(&s->materials[b->material], st, p->Be + 4 * q, p->state + STATE_MAX * q);
	}
	struct particles *w = &s->water;   /* tension positive inside the solver */
	for (idx_t q = 0; q < w->n; q++)
		w->pressure[q] = -s->rho_w * G * (H - w->x[2 * q + 1]);
}

static double largest_nodal_speed(const struct sim *s)
{
	double v = 0.0;
	for (idx_t I = 0; I < s->grid.node_count; I++) {
		if (s->f.mass_s[I] > 0.0)
			v = fmax(v, hypot(s->f.v_s[2 * I], s->f.v_s[2 * I + 1]));
		if (s->f.mass_w[I] > 0.0)
			v = fmax(v, hypot(s->f.v_w[2 * I], s->f.v_w[2 * I + 1]));
	}
	return v;
}

/* Pressure and stress errors of the present state, folded into r. */
static void measure_state(const struct sim *s, double H, double K0, double *p, double *x, struct rest_run *r)
{
	const struct case_spec *c = s->spec;
	const struct case_body *b = &c->bodies[0];
	const double skin = SKIN_CELLS * c->grid.cell_size, rho_w = s->rho_w;
	const double gamma = (1.0 - b->porosity) * (c->materials[b->material].density - rho_w) * G;
	const idx_t np = sim_pressure_point_count(s);
	sim_pore_pressure(s, p, x);
	for (idx_t q = 0; q < np; q++) {
		const double d = H - x[2 * q + 1], e = fabs(p[q] - rho_w * G * d);
		r->pressure_all = fmax(r->pressure_all, e / (rho_w * G * H));
		if (d > skin)
			r->pressure_deep = fmax(r->pressure_deep, e / (rho_w * G * d));
	}
	const struct particles *soil = sim_soil(s);
	for (idx_t q = 0; q < soil->n; q++) {
		const double d = H - soil->x0[2 * q + 1], geo = gamma * d, *st = soil->stress + 4 * q;
		if (d <= skin)
			continue;
		r->stress = fmax(r->stress, fabs(st[1] + geo) / geo);
		if (K0 > 0.0)
			r->stress = fmax(r->stress, fabs(st[0] + K0 * geo) / (K0 * geo));
	}
}

/* low_k: the formulation of LOW_K_FILE; free_surface: the grid 1.1 m high, the top a free water
 * surface inside it; apic: APIC point velocities instead of the cases' FLIP. */
static struct rest_run run_column(enum case_phases phases, int low_k, double k, int free_surface, int apic)
{
	struct rest_run r = {0};
	struct case_spec *c = NULL, *formulation = NULL;
	struct sim *s = NULL;
	struct poro_error err = {0};
	r.ok = !case_load_file(CASE_FILE, &c, &err) && (!low_k || !case_load_file(LOW_K_FILE, &formulation, &err));
	if (r.ok) {
		if (low_k)
			c->formulation = formulation->formulation;
		c->formulation.phases = phases;
		if (apic)
			c->formulation.velocity_update = VELOCITY_UPDATE_APIC;
		c->bodies[0].hydraulic_conductivity = k;
		if (free_surface) {
			c->grid.extent[1] = 1.1;
			c->boundaries[FACE_TOP].drainage = DRAINAGE_IMPERMEABLE;
		}
		r.ok = !sim_create(&s, c, &err);
	}
	if (!r.ok) {
		printf("INFO hydrostatic column: %s\n", s ? sim_error(s)->message : err.message);
		sim_destroy(&s);
		case_destroy(&c);
		case_destroy(&formulation);
		return r;
	}
	const struct case_body *b = &c->bodies[0];
	const double H = b->max[1], nu = c->materials[b->material].poisson_ratio, K0 = nu / (1.0 - nu);
	const long steps = sim_steps_total(s), tenth = steps / 10;
	r.v_allowed = REST_SHARE * k / b->porosity + REST_FLOOR;
	set_geostatic(s, H, K0);
	const idx_t np = sim_pressure_point_count(s);
	double *p = malloc(sizeof(double) * (size_t)np), *x = malloc(2 * sizeof(double) * (size_t)np);
	while (r.ok && !sim_done(s)) {
		r.ok = !sim_step(s);
		const long step = sim_steps_taken(s);
		const double v = largest_nodal_speed(s);
		if (step <= tenth)
			r.v_early = fmax(r.v_early, v);
		if (step > steps - tenth)
			r.v_late = fmax(r.v_late, v);
		if (step % tenth == 0)
			measure_state(s, H, K0, p, x, &r);
	}
	if (!r.ok)
		printf("INFO hydrostatic column: %s\n", sim_error(s)->message);
	free(p);
	free(x);
	sim_destroy(&s);
	case_destroy(&c);
	case_destroy(&formulation);
	return r;
}

int main(void)
{
	static const double ks[] = {1e-3, 1e-9};
	for (int surface = 0; surface < 2; surface++)
		for (int low_k = 0; low_k < 2; low_k++)
			for (int phase = 0; phase < 2; phase++)
				for (int ik = 0; ik < 2; ik++)
				for (int apic = 0; apic < 2; apic++) {
					/* the free surface inside the grid at k = 1e-3 only: at 1e-9 the default
					 * formulation's top layer grows unstable (docs/numerics.md); APIC point
					 * velocities (the cases' are FLIP) there only, double point */
					if ((surface && ik) || (apic && (!surface || phase)))
						continue;
					const enum case_phases ph = phase ? PHASES_SINGLE_POINT : PHASES_DOUBLE_POINT;
					char name[160];
					const char *label_phase = phase ? "single_point" : "double_point";
					static const char *const forms[2][2] = {
						{"default_options", "default_options_apic"},
						{"low_permeability_options", "low_permeability_options_apic"}};
					const char *label_form = forms[low_k][apic];
					const char *label_top = surface ? "free_surface_in_grid" : "drained_top";
					double t0 = harness_wall_seconds();
					struct rest_run r = run_column(ph, low_k, ks[ik], surface, apic);
					printf("INFO hydrostatic column %s %s %s k=%g: pressure %.5f of rho_w g d (deeper than %g cells), "
					       "%.5f of rho_w g H (all points); effective stress %.5f of geostatic; largest nodal "
					       "speed %.2e m/s first tenth, %.2e last tenth (allowed %.2e); %.2f s\n",
					       label_phase, label_form, label_top, ks[ik], r.pressure_deep, SKIN_CELLS, r.pressure_all,
					       r.stress, r.v_early, r.v_late, r.v_allowed, harness_wall_seconds() - t0);
					snprintf(name, sizeof name, "hydrostatic_%s_%s_%s_k%g_", label_phase, label_form, label_top,
						 ks[ik]);
					char *tail = name + strlen(name);
					const size_t room = sizeof name - strlen(name);
					snprintf(tail, room, "runs");
					CHECK(r.ok, name, "run failed");
					if (surface && !apic) {
						/* known: the water beyond a free surface inside the grid (file comment);
						 * pressure and stress are on the INFO line */
						snprintf(tail, room, "at_rest");
						CHECK_KNOWN_FAILURE(r.ok && r.v_late < r.v_allowed, name,
								    "largest nodal speed %.2e m/s over the last tenth, allowed %.2e",
								    r.v_late, r.v_allowed);
						continue;
					}
					snprintf(tail, room, "pressure_hydrostatic");
					CHECK(r.ok && r.pressure_deep < PRESSURE_TOLERANCE && r.pressure_all < PRESSURE_TOLERANCE,
					      name, "%.5f of rho_w g d, %.5f of rho_w g H", r.pressure_deep, r.pressure_all);
					snprintf(tail, room, "effective_stress_geostatic");
					CHECK(r.ok && r.stress < STRESS_TOLERANCE, name, "%.5f of geostatic", r.stress);
					snprintf(tail, room, "at_rest");
					/* APIC slows the default formulation's surface node but does not stop it */
					if (surface && !low_k)
						CHECK_KNOWN_FAILURE(r.ok && r.v_late < r.v_allowed, name,
								    "largest nodal speed %.2e m/s over the last tenth, allowed %.2e",
								    r.v_late, r.v_allowed);
					else
						CHECK(r.ok && r.v_late < r.v_allowed, name,
						      "largest nodal speed %.2e m/s over the last tenth, allowed %.2e", r.v_late,
						      r.v_allowed);
				}
	HARNESS_EXIT();
}
