/*
 * xie_leo_test.c - 000 §5.2 against Xie and Leo's large-strain closed form.
 *
 * Table 2 column (E = 1 MPa, q = 200 kPa, h = 0.05 m, dt = 5e-4 s, to Tv = 2):
 *  - small-strain elastic: top settlement within 3% of Eq. 87 at U = 0.25, 0.5, 0.75 and at the
 *    end; RMS pore-pressure error (normalised by q) within 5% at U = 0.25, 0.5, 0.75 (Fig. 3a),
 *    the analytical pressure taken at each water point's material depth;
 *  - Hencky: the final settlement against Hencky's own closed form (with nu = 0 the Cauchy
 *    stress is E ln(l) / l for stretch l, so the column settles to H (1 - l) with
 *    E ln(l) / l = -q), and the difference to the small-strain run reported next to the
 *    paper's "about 17%";
 *  - soil and water mass conserved to 1e-12 at every step;
 *  - at the end, the settlement the soil points' volumes account for is within 2% of the top's
 *    (VOLUME_GAP_MAX). The cases move the soil points by the MUSL displacement whose gradient
 *    updates their volume (formulation.position_update "musl_displacement"): 0.22% apart in
 *    double point. With the grid-velocity update the FLIP noise of the first steps set the two
 *    7.2% apart (the volume follows the remapped point velocities, the position the grid
 *    velocity), the porosity and stress ran ahead of the motion and the column settled 5.7%
 *    short at Tv = 2 (docs/numerics.md, "Volumes that follow the motion").
 * The double-point cases (xie_leo.json, xie_leo_hencky.json) run with the second-difference
 * pressure stabilisation (docs/numerics.md): without it the node-to-node pressure pattern
 * stalled the column from U = 0.5 on (20% short at the end, Hencky 39% short).
 * All three cases use k = k0 (V/V0)^2 (permeability_law "volume_ratio_squared"), the law under
 * which Eqs. 87-90 are exact (tests/solver/permeability_test.c solves Gibson's equation to show it);
 * with k = k0 V/V0 the column ran 9-12% ahead of Eq. 87 at U = 0.25-0.75. They also take the drag
 * into the velocity correction (formulation.drag_in_correction): the paper's Eq. 65 gives every
 * pressure increment an apparent conductivity of about 9e-4 m/s at this dt, nearly the column's
 * own 1e-3 m/s, which made the single-point column run 6% ahead at U = 0.25.
 * The top surface is the top row of points plus half their current spacing (F_yy h / ppc / 2).
 * The double- and single-point columns run a second time with the weak free-surface condition
 * (free_surface.c), to the same tolerances: its surface crosses cells as the column settles, the
 * cut cells on which the divergence form of the pressure force failed (docs/numerics.md), and
 * a third time with APIC point velocities (formulation.velocity_update "apic", transfer.h).
 */
#include <stdlib.h>
#include <string.h>

#include "../harness.h"
#include "analytic.h"
#include "column.h"
#include "case.h"
#include "poro.h"

#define CASES "tests/cases/"
#define G 9.81
#define VOLUME_GAP_MAX 0.02

struct column {
	double H, q, k, rho_w, mv, E, spacing;
};

static struct column column_of(const struct case_spec *c)
{
	struct column col = {
		.H = c->bodies[0].max[1] - c->bodies[0].min[1],
		.q = -c->loads[0].traction[1],
		.k = c->bodies[0].hydraulic_conductivity,
		.rho_w = c->fluid.density,
		.E = c->materials[0].youngs_modulus,
		.spacing = c->grid.cell_size / c->bodies[0].particles_per_cell,
	};
	col.mv = 1.0 / col.E;     /* nu = 0 (Table 2) */
	return col;
}

/* Settlement of the top surface: mean over the top row of its current top edge. */
static double settlement(const struct sim *s, const struct column *col)
{
	const struct particles *p = sim_soil(s);
	double sum = 0;
	int count = 0;
	for (idx_t q = 0; q < p->n; q++) {
		if (p->x0[2 * q + 1] < col->H - col->spacing)
			continue;
		double top = p->x[2 * q + 1] + 0.5 * col->spacing * p->F[4 * q + 3];
		sum += col->H - top;
		count++;
	}
	return sum / count;
}

/* Material depth below the top of a current height. */
static double material_depth(const struct sim *s, const struct column *col, double y)
{
	return col->H - soil_reference_height(s, y, col->H);
}

static double pressure_rms(const struct sim *s, const struct column *col, double Tv, double surface)
{
	idx_t n = sim_pressure_point_count(s);
	double *p = malloc(sizeof(double) * n), *x = malloc(sizeof(double) * 2 * n);
	sim_pore_pressure(s, p, x);
	double sum = 0;
	long count = 0;
	for (idx_t i = 0; i < n; i++) {
		double y = x[2 * i + 1];
		if (y > surface)
			continue;          /* expelled water above the soil */
		double e = p[i] - xie_leo_pressure(material_depth(s, col, y), col->H, col->mv, col->q, Tv);
		sum += e * e;
		count++;
	}
	free(p), free(x);
	return sqrt(sum / count) / col->q;
}

struct run {
	double settle[4], analytic[4], rms[3], drift, soil_drift;
	double volume_settle;   /* m, at the end: sum_p (V0_p - V_p) over the column's width */
	int ok;
};

/* Settlement the soil points' volumes account for: in one dimension the column loses exactly the
 * volume its top moves down by, so this equals settlement() unless the volumes (which set the
 * porosity, the conductivity and the stress) drift from the motion of the points. */
static double volume_settlement(const struct sim *s, const struct case_spec *c)
{
	const struct particles *p = sim_soil(s);
	double lost = 0;
	for (idx_t q = 0; q < p->n; q++)
		lost += p->volume0[q] - p->volume[q];
	return lost / (c->bodies[0].max[0] - c->bodies[0].min[0]);
}

/* What a variant changes in its case. */
enum change { AS_GIVEN, WEAK_SURFACE, APIC };

static struct run run_case(const char *file, enum change change)
{
	struct run r = {0};
	struct case_spec *c = NULL;
	struct sim *s = NULL;
	struct poro_error err = {0};
	r.ok = !case_load_file(file, &c, &err);
	if (r.ok && change == WEAK_SURFACE)
		c->formulation.free_surface = FREE_SURFACE_WEAK;
	if (r.ok && change == APIC)
		c->formulation.velocity_update = VELOCITY_UPDATE_APIC;
	r.ok = r.ok && !sim_create(&s, c, &err);
	if (!r.ok) {
		printf("INFO cannot run %s: %s\n", file, err.message);
		return r;
	}
	struct column col = column_of(c);
	const double U[3] = {0.25, 0.5, 0.75};
	double Tv[4];
	for (int i = 0; i < 3; i++)
		Tv[i] = time_factor_for_degree(U[i]);
	Tv[3] = time_factor(col.k, c->time.end, col.rho_w, G, col.mv, col.H);
	double ms0 = sim_soil_mass(s), mw0 = sim_water_mass(s);
	for (int i = 0; i < 4 && r.ok; i++) {
		long target = lround(time_for_factor(col.k, Tv[i], col.rho_w, G, col.mv, col.H) / c->time.dt);
		while (r.ok && sim_steps_taken(s) < target) {
			if (sim_step(s)) {
				printf("INFO %s failed: %s\n", file, sim_error(s)->message);
				r.ok = 0;
				break;
			}
			double ds = fabs(sim_soil_mass(s) - ms0) / ms0;
			double dw = fabs(sim_water_mass(s) + sim_water_outflow_mass(s) - mw0) / mw0;
			r.drift = fmax(r.drift, fmax(ds, dw));
			r.soil_drift = fmax(r.soil_drift, ds);
		}
		r.settle[i] = settlement(s, &col);
		r.analytic[i] = xie_leo_settlement(col.H, col.mv, col.q, Tv[i]);
		if (i < 3)
			r.rms[i] = pressure_rms(s, &col, Tv[i], col.H - r.settle[i]);
	}
	r.volume_settle = volume_settlement(s, c);
	sim_destroy(&s);
	case_destroy(&c);
	return r;
}

/* Known failures are marked per variant (docs/numerics.md has the figures and the causes). */
struct expectation {
	const char *label, *file;
	enum change change;            /* the weak free-surface condition or APIC instead of the case's */
	int water_mass_conserved;      /* double point: water points keep their mass */
	int known_runs;                /* 1: running to Tv = 2 is a known failure */
	int known[4], known_pressure[3];   /* 1: the settlement / pressure check is a known failure */
};

static void check_variant(const struct expectation *e, struct run *out)
{
	const char *stage[4] = {"U0.25", "U0.50", "U0.75", "end"};
	struct run r = run_case(e->file, e->change);
	char name[128];
	snprintf(name, sizeof name, "xie_leo_%s_runs_to_Tv2", e->label);
	CHECK_UNLESS_KNOWN(e->known_runs, r.ok, name, "the run stopped before Tv = 2");
	for (int i = 0; i < 4; i++) {
		double rel = r.analytic[i] > 0 ? fabs(r.settle[i] - r.analytic[i]) / r.analytic[i] : 1;
		printf("INFO xie-leo %s %s: settlement %.5f m, Eq. 87 %.5f m, difference %.2f%%\n", e->label, stage[i],
		       r.settle[i], r.analytic[i], 100 * rel);
		snprintf(name, sizeof name, "xie_leo_%s_settlement_within_3pct_%s", e->label, stage[i]);
		CHECK_UNLESS_KNOWN(e->known[i], r.ok && rel <= 0.03, name, "%.2f%%", 100 * rel);
	}
	for (int i = 0; i < 3; i++) {
		printf("INFO xie-leo %s %s: pore pressure rms/q %.4f\n", e->label, stage[i], r.rms[i]);
		snprintf(name, sizeof name, "xie_leo_%s_pore_pressure_within_5pct_%s", e->label, stage[i]);
		CHECK_UNLESS_KNOWN(e->known_pressure[i], r.ok && r.rms[i] <= 0.05, name, "rms/q %.4f", r.rms[i]);
	}
	double gap = fabs(r.volume_settle - r.settle[3]) / r.settle[3];
	printf("INFO xie-leo %s end: settlement from the soil points' volumes %.5f m, from the top %.5f m "
	       "(%.2f%% apart)\n", e->label, r.volume_settle, r.settle[3], 100 * gap);
	snprintf(name, sizeof name, "xie_leo_%s_volumes_follow_the_settlement", e->label);
	CHECK(r.ok && gap <= VOLUME_GAP_MAX, name, "%.2f%% apart", 100 * gap);
	double drift = e->water_mass_conserved ? r.drift : r.soil_drift;
	printf("INFO xie-leo %s: max relative mass drift %.3e (%s)\n", e->label, drift,
	       e->water_mass_conserved ? "soil and water" : "soil; single-point water drains out");
	snprintf(name, sizeof name, "xie_leo_%s_mass_conserved", e->label);
	CHECK(drift <= 1e-12, name, "drift %.3e", drift);
	*out = r;
}

int main(void)
{
	const struct expectation variants[6] = {
		{"double_point", CASES "xie_leo.json", AS_GIVEN, 1, 0, {0, 0, 0, 0}, {0, 0, 0}},
		{"single_point", CASES "xie_leo_single_point.json", AS_GIVEN, 0, 0, {0, 0, 0, 0}, {0, 0, 0}},
		{"double_point_weak_surface", CASES "xie_leo.json", WEAK_SURFACE, 1, 0, {0, 0, 0, 0}, {0, 0, 0}},
		{"single_point_weak_surface", CASES "xie_leo_single_point.json", WEAK_SURFACE, 0, 0, {0, 0, 0, 0},
		 {0, 0, 0}},
		/* APIC drops the unresolved velocity FLIP keeps: 3.14% at U = 0.25 against the case's
		 * 2.79% (docs/numerics.md, "Point velocities") */
		{"double_point_apic", CASES "xie_leo.json", APIC, 1, 0, {1, 0, 0, 0}, {0, 0, 0}},
		{"single_point_apic", CASES "xie_leo_single_point.json", APIC, 0, 0, {0, 0, 0, 0}, {0, 0, 0}},
	};
	struct run small[6];
	for (int v = 0; v < 6; v++)
		check_variant(&variants[v], &small[v]);

	struct run hencky = run_case(CASES "xie_leo_hencky.json", AS_GIVEN);
	CHECK(hencky.ok, "xie_leo_hencky_runs_to_Tv2", "the run stopped before Tv = 2");
	/* Hencky's final state: E ln(l) / l = -q, by bisection on l in (0, 1) */
	const double E = 1e6, q = 2e5, H = 1.0;
	double lo = 0.5, hi = 1.0;
	for (int i = 0; i < 200; i++) {
		double l = 0.5 * (lo + hi);
		if (E * log(l) / l < -q)
			lo = l;
		else
			hi = l;
	}
	double l = 0.5 * (lo + hi);
	double hencky_final = H * (1 - l) * consolidation_degree(2.0);
	double rel = fabs(hencky.settle[3] - hencky_final) / hencky_final;
	printf("INFO xie-leo hencky (double point) at Tv = 2: settlement %.5f m, Hencky closed form %.5f m (%.2f%%); "
	       "small strain settles %.1f%% more (paper 000 §5.2: about 17%%)\n", hencky.settle[3], hencky_final,
	       100 * rel, 100 * (small[0].settle[3] / hencky.settle[3] - 1));
	CHECK(hencky.ok && rel <= 0.03, "xie_leo_hencky_final_settlement_within_3pct", "%.2f%%", 100 * rel);
	CHECK(hencky.drift <= 1e-12, "xie_leo_hencky_mass_conserved", "drift %.3e", hencky.drift);
	HARNESS_EXIT();
}
