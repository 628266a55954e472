/*
 * specific_volume_test.c - Nor-Sand's specific volume in the semi-implicit scheme
 * (formulation.specific_volume; 000 Eqs. 95-97).
 *
 * The reduced loose landslide (double point, Nor-Sand) is stepped through the elastic gravity
 * ramp and 240 steps into the plastic slide, once with each point's own J (Eq. 95, the default)
 * and once with J mapped to the nodes by mass and back (Eq. 97). Each point's state keeps the
 * specific volume v of its last update, and its volume gives J = V / V0. Checked:
 *  - "point": v = J v0 at every point, bit for bit;
 *  - "nodal_average": the mapping conserves the mass-weighted sum, sum m v = v0 sum m J (the
 *    B-splines sum to one at every point inside the grid, so sum_p m_p sum_I S_Ip Jbar_I =
 *    sum_I Jbar_I M_I = sum_p m_p J_p), to round-off; it smooths, the mass-weighted spread of v
 *    about its mean being below that of J v0; and it is not the identity (some point's v differs
 *    from J v0 by more than round-off).
 */
#include <math.h>

#include "../harness.h"
#include "../verify/slope_case.h"
#include "case.h"
#include "material.h"
#include "poro.h"
#include "sim_internal.h"

#define CASE_FILE "tests/cases/landslide_loose_double_point.json"
#define STEPS 4407   /* the ramp ends at step 4,167 */
#define REDUCED_H 0.05
#define REDUCED_PPC 2

static void set_specific_volume(json_t *doc, void *user)
{
	slope_case_set(doc, "time", "end", json_real(10.0));
	slope_case_set(doc, "formulation", "specific_volume", json_string(user));
	json_object_del(doc, "checkpoint");
}

/* Steps the case with `specific_volume` for STEPS steps; NULL (after an INFO line) on failure. */
static struct sim *stepped(const char *specific_volume, struct case_spec **c)
{
	struct sim *s = NULL;
	if (slope_case_create(CASE_FILE, REDUCED_H, REDUCED_PPC, set_specific_volume, (void *)specific_volume, c, &s)) {
		printf("INFO %s: the case does not load\n", CASE_FILE);
		return NULL;
	}
	for (long k = 0; k < STEPS; k++)
		if (sim_step(s) != PORO_OK) {
			printf("INFO %s, specific_volume %s: step %ld failed: %s\n", CASE_FILE, specific_volume, k + 1,
			       sim_error(s)->message);
			sim_destroy(&s);
			return NULL;
		}
	return s;
}

static double state_of(const struct particles *p, idx_t q, int slot)
{
	return p->state[STATE_MAX * q + slot];
}

/* The point's own specific volume, Eq. 95: J v0 with J = V / V0. */
static double point_J_v0(const struct particles *p, idx_t q)
{
	return p->volume[q] / p->volume0[q] * state_of(p, q, NOR_SAND_INITIAL_SPECIFIC_VOLUME);
}

static void check_point(void)
{
	struct case_spec *c = NULL;
	struct sim *s = stepped("point", &c);
	long differ = -1;
	if (s) {
		const struct particles *p = &s->soil;
		differ = 0;
		for (idx_t q = 0; q < p->n; q++)
			differ += state_of(p, q, NOR_SAND_SPECIFIC_VOLUME) != point_J_v0(p, q);
	}
	CHECK(differ == 0, "specific_volume_point_is_J_v0", "%ld points differ", differ);
	sim_destroy(&s);
	case_destroy(&c);
}

static void check_nodal_average(void)
{
	struct case_spec *c = NULL;
	struct sim *s = stepped("nodal_average", &c);
	double sum_v = 0, sum_Jv0 = 0, mass = 0, largest = 0, spread_v = 0, spread_J = 0;
	if (s) {
		const struct particles *p = &s->soil;
		for (idx_t q = 0; q < p->n; q++) {
			const double v = state_of(p, q, NOR_SAND_SPECIFIC_VOLUME);
			const double Jv0 = point_J_v0(p, q);
			sum_v += p->mass[q] * v;
			sum_Jv0 += p->mass[q] * Jv0;
			mass += p->mass[q];
			largest = fmax(largest, fabs(v - Jv0));
		}
		const double mean = sum_Jv0 / mass;
		for (idx_t q = 0; q < p->n; q++) {
			const double v = state_of(p, q, NOR_SAND_SPECIFIC_VOLUME);
			const double Jv0 = point_J_v0(p, q);
			spread_v += p->mass[q] * (v - mean) * (v - mean);
			spread_J += p->mass[q] * (Jv0 - mean) * (Jv0 - mean);
		}
	}
	const double conserved = s ? fabs(sum_v - sum_Jv0) / sum_Jv0 : NAN;
	printf("INFO specific_volume nodal_average after %d steps: sum m v against v0 sum m J %.2e relative; "
	       "largest |v - J v0| %.3g; mass-weighted spread of v %.3g, of J v0 %.3g\n", STEPS, conserved,
	       largest, s ? sqrt(spread_v / mass) : NAN, s ? sqrt(spread_J / mass) : NAN);
	CHECK(s && conserved <= 1e-13, "specific_volume_nodal_average_conserves_mass_weighted_sum", "see INFO");
	CHECK(s && spread_v < spread_J && largest > 1e-9, "specific_volume_nodal_average_smooths", "see INFO");
	sim_destroy(&s);
	case_destroy(&c);
}

int main(void)
{
	check_point();
	check_nodal_average();
	HARNESS_EXIT();
}
