/*
 * initial_state_test.c - the initialisation of 000 §5.4 (gravity.loading_conductivity and
 * gravity.water_attached) on the Mohr-Coulomb slope of tests/cases/mc_slope_k1e-7_double_point.json
 * at Table 4's cell (h = 1 m, 2x2 points per cell, dt 0.004 s), run to the end of the 1 s ramp:
 *  - with water_attached every water point ends where its soil point is (double point seeds one water
 *    point on every soil point, in the same order): both move with the soil's nodal velocity, so
 *    the distance must be round-off; without it seepage separates them;
 *  - with loading_conductivity = 1 m/s the pore pressure at the end of the ramp is hydrostatic
 *    below the free surface (rho_w g depth); with the body's own k = 1e-7 m/s the ramp's loading is
 *    undrained and leaves an excess pressure;
 *  - the soil points' plastic strain stays zero (elastic loading) and the keys are refused without
 *    a ramp, naming the key.
 * Hydrostatic oracle: the surface above a point is the slope's polygon (crest y = 15 m for x < 10,
 * toe plain y = 5 m beyond x = 20); points within two cells of it are skipped, since the nodal
 * free-surface condition places p = 0 up to a cell away from the true surface, and so are points
 * within 5 m of the face (FAR_CREST, FAR_TOE).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <jansson.h>

#include "../harness.h"
#include "case.h"
#include "particles.h"
#include "poro.h"

#define CASE_FILE "tests/cases/mc_slope_k1e-7_double_point.json"
#define H 1.0                 /* m */
#define RHO_W 1000.0
#define G 9.81
/* Hydrostatic error allowed after a drained ramp, relative to rho_w g H_slope (147 kPa): the
 * pressure solve sees the surface at nodes, and the points two cells down still feel it. */
#define HYDROSTATIC_TOLERANCE 0.03
/* Hydrostatic only far from the face: water standing at the surface of a slope seeps out of its
 * face, and the pressure solve (which does not know the water is held to the soil) sees that flow;
 * near the face the pressure is below hydrostatic. Points under the crest (x < FAR_CREST) and
 * under the toe plain (x > FAR_TOE) are compared. */
#define FAR_CREST 5.0
#define FAR_TOE 25.0

static double surface_height(double x)
{
	return x < 10.0 ? 15.0 : x < 20.0 ? 25.0 - x : 5.0;
}

struct ramp_outcome {
	int ok;
	double separation;        /* m: largest water-soil point distance */
	double hydrostatic_error; /* RMS (p - rho_w g depth) / (rho_w g 15 m) over deep points */
	double max_plastic;
};

static struct ramp_outcome run_ramp(double loading_conductivity, int attached)
{
	struct ramp_outcome o = {0};
	struct case_spec *c = NULL;
	struct sim *s = NULL;
	struct poro_error err = {0};
	o.ok = !case_load_file(CASE_FILE, &c, &err);
	if (o.ok) {
		c->time.dt *= H / c->grid.cell_size;
		c->grid.cell_size = H;
		c->bodies[0].particles_per_cell = 2;
		c->gravity.loading_conductivity = loading_conductivity;
		c->gravity.water_attached = attached;
		c->time.end = c->gravity.ramp_time;
		o.ok = !sim_create(&s, c, &err);
	}
	while (o.ok && !sim_done(s))
		o.ok = !sim_step(s);
	if (!o.ok) {
		printf("INFO initial state run failed: %s\n", s ? sim_error(s)->message : err.message);
		sim_destroy(&s);
		case_destroy(&c);
		return o;
	}
	const struct particles *soil = sim_soil(s), *water = sim_water(s);
	for (idx_t q = 0; q < soil->n && q < water->n; q++) {
		o.separation = fmax(o.separation, hypot(water->x[2 * q] - soil->x[2 * q],
							water->x[2 * q + 1] - soil->x[2 * q + 1]));
		o.max_plastic = fmax(o.max_plastic, soil->plastic_strain[q]);
	}
	idx_t n = sim_pressure_point_count(s);
	double *p = malloc(sizeof(double) * (size_t)n), *x = malloc(2 * sizeof(double) * (size_t)n);
	double sum = 0;
	long count = 0;
	sim_pore_pressure(s, p, x);
	for (idx_t q = 0; q < n; q++) {
		double depth = surface_height(x[2 * q]) - x[2 * q + 1];
		if (depth < 2 * H || (x[2 * q] > FAR_CREST && x[2 * q] < FAR_TOE))
			continue;
		double e = (p[q] - RHO_W * G * depth) / (RHO_W * G * 15.0);
		sum += e * e, count++;
	}
	o.hydrostatic_error = count ? sqrt(sum / count) : INFINITY;
	free(p);
	free(x);
	sim_destroy(&s);
	case_destroy(&c);
	return o;
}

/* The case with no gravity ramp and only `key` of the initialisation keys set: refused, naming it. */
static void check_refused_without_ramp(const char *key, json_t *value)
{
	char name[96], pointer[64];
	struct case_spec *c = NULL;
	struct poro_error err = {0};
	json_t *root = json_load_file(CASE_FILE, 0, NULL), *gravity = json_object_get(root, "gravity");
	json_object_set_new(gravity, "ramp_time", json_real(0.0));
	json_object_del(gravity, "elastic_loading");
	json_object_del(gravity, "loading_conductivity");
	json_object_del(gravity, "water_attached");
	json_object_set_new(gravity, key, value);
	char *text = json_dumps(root, 0);
	int refused = text && case_load_string(text, &c, &err) != PORO_OK;
	snprintf(pointer, sizeof pointer, "/gravity/%s", key);
	snprintf(name, sizeof name, "%s_refused_without_ramp", key);
	CHECK(refused && strstr(err.message, pointer), name, "%s", refused ? err.message : "accepted");
	case_destroy(&c);
	free(text);
	json_decref(root);
}

int main(void)
{
	struct ramp_outcome attached = run_ramp(1.0, 1), free_water = run_ramp(1.0, 0),
			    undrained = run_ramp(0.0, 1);
	printf("INFO slope ramp h=1 m: water-soil separation attached %.2e m, free %.2e m; hydrostatic error "
	       "k_loading = 1 m/s %.4f, own k = 1e-7 m/s %.4f (of rho_w g 15 m); max plastic strain %.1e\n",
	       attached.separation, free_water.separation, attached.hydrostatic_error, undrained.hydrostatic_error,
	       attached.max_plastic);
	CHECK(attached.ok && free_water.ok && undrained.ok, "initial_state_ramps_run", "a ramp failed");
	CHECK(attached.ok && attached.separation < 1e-12, "water_attached_keeps_points_together",
	      "separation %.3e m", attached.separation);
	CHECK(free_water.ok && free_water.separation > 1e3 * fmax(attached.separation, 1e-15),
	      "without_water_attached_points_separate", "separation %.3e m", free_water.separation);
	CHECK(attached.ok && attached.hydrostatic_error < HYDROSTATIC_TOLERANCE,
	      "loading_conductivity_leaves_hydrostatic_pressure", "RMS error %.4f", attached.hydrostatic_error);
	CHECK(undrained.ok && undrained.hydrostatic_error > 2 * attached.hydrostatic_error,
	      "own_low_conductivity_leaves_excess_pressure", "RMS error %.4f vs %.4f", undrained.hydrostatic_error,
	      attached.hydrostatic_error);
	CHECK(attached.ok && attached.max_plastic == 0.0, "initial_state_ramp_is_elastic", "plastic strain %.3e",
	      attached.max_plastic);
	check_refused_without_ramp("water_attached", json_true());
	check_refused_without_ramp("loading_conductivity", json_real(1.0));
	HARNESS_EXIT();
}
