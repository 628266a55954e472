/*
 * sim.c - building a simulation from a case: grid, material points, materials, workspaces;
 * stepping and the read-only accessors of poro.h.
 *
 * Material points are seeded on a regular sub-grid: particles_per_cell^2 points per cell at the
 * centres of equal sub-cells, kept when strictly inside the body (not on a polygon edge; a point
 * already inside an earlier body belongs to that one). Each point gets the volume of its sub-cell.
 * A rectangle fills its own extent exactly, wherever its sides lie: a sub-cell that a side cuts
 * gets one point at the centre of its covered part with that part's volume, and a covered part
 * thinner than half a sub-cell joins its inner neighbour's point instead, so the rows cut by a
 * side are 1/2 to 3/2 sub-cells thick. Keeping only the sub-cells whose centres lie inside left
 * the points short of the side by up to a sub-cell (and a centre on the side itself was kept or
 * dropped by round-off), while the load and the free surface took the side where the case puts it
 * (docs/numerics.md, "Columns whose top cuts a cell").
 * Double point seeds one water point on every soil point (000 §5.1: "640 material points in total
 * for both water and soil") of a saturated body; a dry body ("saturated": false) gets none, and in
 * single point its points carry no water. The saturated bodies are seeded first, so the points that
 * carry water are the first ones: the single-point water set rides on them alone, and the
 * double-point one copies them (docs/numerics.md, "Dry bodies"). A case whose bodies are all
 * saturated is seeded in its bodies' order, as before.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "shape.h"
#include "phases.h"
#include "reference_kernel.h"
#include "scheme.h"
#include "step_health.h"

/* A seed point closer to a polygon edge than this many cell sizes lies on the edge: it is not
 * inside. Seeds fall exactly on 45-degree faces whenever the face runs through sub-cell centres
 * (the slopes of 000 §5.3 at 6x6 to 24x24 points per cell); round-off then decided each one,
 * keeping 0 to 8 of them, where the paper's point counts (Table 4) keep none. */
#define SEED_EDGE_TOLERANCE 1e-9

/* Distance from (x, y) to the segment a-b. */
static double segment_distance(const double *a, const double *b, double x, double y)
{
	double ex = b[0] - a[0], ey = b[1] - a[1], len2 = ex * ex + ey * ey;
	double t = len2 > 0.0 ? ((x - a[0]) * ex + (y - a[1]) * ey) / len2 : 0.0;
	t = fmin(fmax(t, 0.0), 1.0);
	return hypot(x - a[0] - t * ex, y - a[1] - t * ey);
}

/* Strictly inside the polygon: crossing number, and not on an edge (within eps). */
static int inside_polygon(const struct case_body *b, double x, double y, double eps)
{
	int inside = 0;
	for (int i = 0, j = b->polygon_count - 1; i < b->polygon_count; j = i++) {
		const double *pi = b->polygon[i], *pj = b->polygon[j];
		if (segment_distance(pi, pj, x, y) <= eps)
			return 0;
		if ((pi[1] > y) != (pj[1] > y) && x < (pj[0] - pi[0]) * (y - pi[1]) / (pj[1] - pi[1]) + pi[0])
			inside = !inside;
	}
	return inside;
}

static int inside_body(const struct case_body *b, double x, double y, double h)
{
	if (x < b->min[0] || x > b->max[0] || y < b->min[1] || y > b->max[1])
		return 0;
	return b->is_polygon ? inside_polygon(b, x, y, SEED_EDGE_TOLERANCE * h) : 1;
}

/* The part of sub-cell [a, a + d] that the interval [lo, hi] of a rectangle covers, with the
 * slivers of its neighbours that are thinner than d / 2 joined to it (file comment): 1 and the
 * part's centre and width; 2 and width d for the whole sub-cell; 0 when the sub-cell takes no
 * point. A side within `eps` of a sub-cell face counts as on it, so that a rectangle on the
 * sub-grid is seeded as before, centre for centre. */
static int covered_part(double a, double d, double lo, double hi, double eps, double *centre, double *width)
{
	const double b = a + d;
	/* a neighbour keeps its own point when it is covered at least d / 2 - eps: the same test
	 * decides here whether its part joins this one, so no part is counted twice */
	const double from = fabs(lo - a) <= eps ? a : lo > a - 0.5 * d + eps ? lo : a;
	const double to = fabs(hi - b) <= eps ? b : hi < b + 0.5 * d - eps ? hi : b;
	if (fmin(b, to) - fmax(a, from) < 0.5 * d - eps)
		return 0; /* outside, or a sliver its neighbour takes */
	if (from == a && to == b) {
		*width = d;
		return 2; /* the whole sub-cell: its centre as the caller has it */
	}
	*centre = 0.5 * (from + to), *width = to - from;
	return 1;
}

/* Whether the seed of sub-cell (x, y), d wide, puts a point into body b: 1 with the point's centre
 * in (x, y) and its width and height in wx, wy (file comment; d for a whole sub-cell), else 0. */
static int seed_in_body(const struct case_body *b, double d, double h, double *x, double *y, double *wx, double *wy)
{
	if (b->is_polygon)
		return inside_body(b, *x, *y, h);
	const double eps = SEED_EDGE_TOLERANCE * h;
	double cx, cy;
	int kx = covered_part(*x - 0.5 * d, d, b->min[0], b->max[0], eps, &cx, wx);
	int ky = covered_part(*y - 0.5 * d, d, b->min[1], b->max[1], eps, &cy, wy);
	if (!kx || !ky)
		return 0;
	if (kx == 1)
		*x = cx;
	if (ky == 1)
		*y = cy;
	return 1;
}

/* Visits every seed point of body b, points count, count + 1, ... of p: fills p when it is not
 * NULL; returns the new count. A point inside an earlier body of the case belongs to that one. */
static idx_t seed_body(const struct sim *s, int b, struct particles *p, idx_t count)
{
	const struct case_spec *c = s->spec;
	const struct grid *g = &s->grid;
	const struct case_body *body = &c->bodies[b];
	const int ppc = body->particles_per_cell;
	const double d = g->h / ppc;
	for (idx_t cj = 0; cj < g->cells[1]; cj++)
		for (idx_t ci = 0; ci < g->cells[0]; ci++)
			for (int sj = 0; sj < ppc; sj++)
				for (int si = 0; si < ppc; si++) {
					double x = g->origin[0] + ci * g->h + (si + 0.5) * d;
					double y = g->origin[1] + cj * g->h + (sj + 0.5) * d;
					double wx = d, wy = d;
					if (!seed_in_body(body, d, g->h, &x, &y, &wx, &wy))
						continue;
					int taken = 0;
					for (int e = 0; e < b && !taken; e++)
						taken = inside_body(&c->bodies[e], x, y, g->h);
					if (taken)
						continue;
					if (p) {
						p->x[2 * count] = p->x0[2 * count] = x;
						p->x[2 * count + 1] = p->x0[2 * count + 1] = y;
						p->volume[count] = p->volume0[count] = wx * wy;
						p->body[count] = b;
					}
					count++;
				}
	return count;
}

/* Visits every seed point, the saturated bodies' first (file comment): fills p when it is not NULL;
 * returns the count, and in *saturated how many of them carry water. */
static idx_t seed_points(const struct sim *s, struct particles *p, idx_t *saturated)
{
	const struct case_spec *c = s->spec;
	idx_t count = 0;
	for (int b = 0; b < c->body_count; b++)
		if (c->bodies[b].saturated)
			count = seed_body(s, b, p, count);
	*saturated = count;
	for (int b = 0; b < c->body_count; b++)
		if (!c->bodies[b].saturated)
			count = seed_body(s, b, p, count);
	return count;
}

static void init_soil_state(struct sim *s)
{
	struct particles *p = &s->soil;
	for (idx_t q = 0; q < p->n; q++) {
		const struct case_body *body = &s->spec->bodies[p->body[q]];
		const struct material *m = &s->materials[body->material];
		p->porosity[q] = p->porosity0[q] = body->porosity;
		p->conductivity[q] = body->hydraulic_conductivity;
		p->mass[q] = (1.0 - body->porosity) * m->density * p->volume0[q];   /* Eq. 33 */
		double *F = p->F + 4 * q;
		F[0] = F[3] = 1.0;
		material_init_state(m, p->stress + 4 * q, p->Be + 4 * q, p->state + STATE_MAX * q);
	}
}

/* The water of the first n soil points, those of the saturated bodies (seed_points). */
static enum poro_status init_water(struct sim *s, idx_t n)
{
	struct particles *p = &s->soil, *w = &s->water;
	if (!s->double_point) {
		enum poro_status st = particles_init_alias(w, p, &s->err);
		if (st)
			return st;
		w->n = n;   /* rides on the first n soil points; a dry body's points carry no water */
	} else {
		enum poro_status st = particles_init(w, n, 0, &s->err);
		if (st)
			return st;
		memcpy(w->x, p->x, sizeof(double) * 2 * (size_t)n);
		memcpy(w->x0, p->x0, sizeof(double) * 2 * (size_t)n);
		memcpy(w->volume, p->volume, sizeof(double) * (size_t)n);
		memcpy(w->volume0, p->volume0, sizeof(double) * (size_t)n);
		memcpy(w->porosity, p->porosity, sizeof(double) * (size_t)n);
		memcpy(w->porosity0, p->porosity0, sizeof(double) * (size_t)n);
		memcpy(w->conductivity, p->conductivity, sizeof(double) * (size_t)n);
		memcpy(w->body, p->body, sizeof(int) * (size_t)n);
	}
	w->support = p->support;
	for (idx_t q = 0; q < w->n; q++) {
		w->mass[q] = w->porosity0[q] * s->rho_w * w->volume0[q];   /* Eq. 37 */
		/* the case's is physical (compression positive); the solver's tension positive */
		const double p0 = s->spec->bodies[w->body[q]].initial_pore_pressure;
		w->pressure[q] = p0 != 0.0 ? -p0 : 0.0;
	}
	return PORO_OK;
}

static enum poro_status allocate_scratch(struct sim *s)
{
	size_t ns = (size_t)s->soil.n + 1, nw = (size_t)s->water.n + 1;
	s->soil_grad = calloc(4 * ns, sizeof(double));
	s->soil_scalar = calloc(ns, sizeof(double));
	s->soil_coef = calloc(ns, sizeof(double));
	s->water_scalar = calloc(nw, sizeof(double));
	s->water_coef = calloc(nw, sizeof(double));
	s->patch_mass = calloc((size_t)s->grid.cell_count, sizeof(double));
	s->patch_mass_Je = calloc((size_t)s->grid.cell_count, sizeof(double));
	s->probe_point = calloc((size_t)s->spec->probe_count + 1, sizeof(int));
	s->load_bands = calloc((size_t)s->spec->load_count + 1, sizeof *s->load_bands);
	if (!s->soil_grad || !s->soil_scalar || !s->soil_coef || !s->water_scalar ||
	    !s->water_coef || !s->patch_mass || !s->patch_mass_Je ||
	    !s->probe_point || !s->load_bands)
		return poro_error_set(&s->err, PORO_ENOMEM, "cannot allocate step workspaces");
	return PORO_OK;
}

static enum poro_status build(struct sim *s)
{
	const struct case_spec *c = s->spec;
	enum poro_status st;
	if ((st = grid_init(&s->grid, &c->grid, &s->err)) || (st = grid_fields_init(&s->f, &s->grid, &s->err)))
		return st;
	s->materials = calloc((size_t)c->material_count, sizeof *s->materials);
	if (!s->materials)
		return poro_error_set(&s->err, PORO_ENOMEM, "cannot allocate materials");
	for (int m = 0; m < c->material_count; m++)
		material_init(&s->materials[m], &c->materials[m]);
	idx_t saturated;
	idx_t n = seed_points(s, NULL, &saturated);
	if (n == 0)
		return poro_error_set(&s->err, PORO_EINVAL, "/bodies: no material point falls inside any body");
	if ((st = particles_init(&s->soil, n, 1, &s->err)))
		return st;
	seed_points(s, &s->soil, &saturated);
	s->saturated_soil = saturated;
	s->soil.support = shape_support(c->formulation.shape);
	init_soil_state(s);
	if ((st = init_water(s, saturated)) || (st = allocate_scratch(s)))
		return st;
	/* the parallel scatters' order (point_blocks.h); single-point water uses the soil's */
	if ((st = particles_add_blocks(&s->soil, &s->grid, &s->err)) ||
	    (s->double_point && (st = particles_add_blocks(&s->water, &s->grid, &s->err))))
		return st;
	if (c->formulation.velocity_update != VELOCITY_UPDATE_FLIP &&
	    ((st = particles_add_affine(&s->soil, &s->err)) || (st = particles_add_affine(&s->water, &s->err))))
		return st;
	fbar_patches_init(s);
	boundary_mark(s);
	loads_init(s);
	probes_init(s);
	s->scheme = scheme_of(c->formulation.scheme);
	return s->scheme->create(s);
}

enum poro_status sim_create(struct sim **out, const struct case_spec *c, struct poro_error *err)
{
	*out = NULL;
	struct sim *s = calloc(1, sizeof *s);
	if (!s)
		return poro_error_set(err, PORO_ENOMEM, "cannot allocate a simulation");
	s->spec = c;
	s->double_point = c->formulation.phases == PHASES_DOUBLE_POINT;
	s->dt = c->time.dt;
	s->steps_total = (long)ceil(c->time.end / c->time.dt - 1e-9);
	s->rho_w = c->fluid.density;
	stable_dt_estimate(c, &s->stable);
	enum poro_status st = build(s);
	if (st) {
		if (err)
			*err = s->err;
		sim_destroy(&s);
		return st;
	}
	*out = s;
	return PORO_OK;
}

void sim_destroy(struct sim **ps)
{
	struct sim *s = ps ? *ps : NULL;
	if (!s)
		return;
	particles_release(&s->water);
	particles_release(&s->soil);
	step_histogram_release(&s->step_cpu);
	step_histogram_release(&s->reference_cpu);
	reference_kernel_destroy(s->reference);
	if (s->scheme)
		s->scheme->destroy(s);
	grid_fields_release(&s->f);
	free(s->materials);
	free(s->soil_grad);
	free(s->soil_scalar);
	free(s->soil_coef);
	free(s->water_scalar);
	free(s->water_coef);
	free(s->patch_mass);
	free(s->patch_mass_Je);
	free(s->probe_point);
	free(s->load_bands);
	free(s);
	*ps = NULL;
}

/* The checks a finished step's state must pass; 0 when it passes. */
static enum poro_status check_finite(struct sim *s)
{
	const struct particles *p = &s->soil;
	for (idx_t q = 0; q < p->n; q++)      /* NaN anywhere in a step surfaces in these */
		if (!isfinite(p->v[2 * q] + p->v[2 * q + 1] + p->stress[4 * q] + p->stress[4 * q + 1] + p->stress[4 * q + 2]))
			return poro_error_set(&s->err, PORO_ESOLVER, "soil point %ld at (%.6g, %.6g) m has a "
					      "non-finite velocity or stress at step %ld (t = %.6g s)", (long)q,
					      p->x[2 * q], p->x[2 * q + 1], s->step, s->time);
	for (idx_t q = 0; q < s->water.n; q++)
		if (!isfinite(s->water.pressure[q] + s->water.v[2 * q] + s->water.v[2 * q + 1]))
			return poro_error_set(&s->err, PORO_ESOLVER, "water point %ld at (%.6g, %.6g) m has a "
					      "non-finite pressure or velocity at step %ld (t = %.6g s)", (long)q,
					      s->water.x[2 * q], s->water.x[2 * q + 1], s->step, s->time);
	return PORO_OK;
}

enum poro_status sim_step(struct sim *s)
{
	enum poro_status st = s->scheme->step(s);
	if (!st)
		st = check_finite(s);
	if (st == PORO_ESOLVER)   /* the symptom is named; add what it likely follows from */
		step_health_explain(s);
	if (!st)
		step_health_watch(s);
	return st;
}

double sim_clock(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

const char *sim_phase_name(enum sim_phase phase)
{
	return phase < PHASE_COUNT ? semi_implicit_scheme.phase_names[phase] : "unknown";
}

const char *sim_phase_name_of(const struct sim *s, enum sim_phase phase)
{
	return phase < PHASE_COUNT ? s->scheme->phase_names[phase] : NULL;
}

int sim_iterations(const struct sim *s, int *last, long *total, const double **energies, int *count)
{
	*last = 0, *total = 0, *count = 0;
	if (energies)
		*energies = NULL;
	return s->scheme->iterations ? s->scheme->iterations(s, last, total, energies, count) : 0;
}

int sim_linear_solver_counts(const struct sim *s, long *analyses, long *factorisations, long *solves,
			     long *factor_nonzeros)
{
	*analyses = *factorisations = *solves = *factor_nonzeros = 0;
	return s->scheme->solver_counts ? s->scheme->solver_counts(s, analyses, factorisations, solves, factor_nonzeros)
					: 0;
}

double sim_phase_seconds(const struct sim *s, enum sim_phase phase)
{
	return phase < PHASE_COUNT ? s->phase_seconds[phase] : 0.0;
}

int sim_done(const struct sim *s) { return s->step >= s->steps_total; }
double sim_time(const struct sim *s) { return s->time; }
long sim_steps_taken(const struct sim *s) { return s->step; }
long sim_steps_total(const struct sim *s) { return s->steps_total; }
const struct poro_error *sim_error(const struct sim *s) { return &s->err; }
const char *sim_warning(const struct sim *s) { return s->warning[0] ? s->warning : NULL; }
const struct particles *sim_soil(const struct sim *s) { return &s->soil; }
const struct particles *sim_water(const struct sim *s) { return &s->water; }
int sim_is_double_point(const struct sim *s) { return s->double_point; }
idx_t sim_pressure_point_count(const struct sim *s) { return s->water.n; }

void sim_pore_pressure(const struct sim *s, double *pressure, double *positions)
{
	for (idx_t q = 0; q < s->water.n; q++) {
		pressure[q] = -s->water.pressure[q];    /* physical sign: positive in compression */
		if (positions) {
			positions[2 * q] = s->water.x[2 * q];
			positions[2 * q + 1] = s->water.x[2 * q + 1];
		}
	}
}

double sim_soil_mass(const struct sim *s)
{
	const struct particles *p = &s->soil;
	double m = 0.0;
	for (idx_t q = 0; q < p->n; q++)
		m += (1.0 - p->porosity[q]) * s->materials[s->spec->bodies[p->body[q]].material].density * p->volume[q];
	return m;
}

double sim_water_mass(const struct sim *s)
{
	const struct particles *w = &s->water;
	double m = 0.0;
	for (idx_t q = 0; q < w->n; q++)
		m += w->porosity[q] * s->rho_w * w->volume[q];
	return m;
}

double sim_water_outflow_mass(const struct sim *s) { return s->water_outflow_mass; }

void sim_grid_masses(const struct sim *s, double *grid_soil, double *grid_water, double *point_soil,
		     double *point_water)
{
	double ms = 0.0, mw = 0.0;
	for (idx_t I = 0; I < s->grid.node_count; I++) {
		ms += s->f.mass_s[I];
		mw += s->f.mass_w_points[I];
	}
	*grid_soil = ms;
	*grid_water = mw;
	*point_soil = s->mapped_mass_s;
	*point_water = s->mapped_mass_w;
}
