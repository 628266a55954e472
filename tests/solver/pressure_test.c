/*
 * pressure_test.c - the consistent projection's matrix and right-hand side (solver/schemes/semi_implicit/pressure.c)
 * against a brute-force assembly.
 *
 * pressure.c assembles A = sum_I,c [G_s; G_w]_I^T K_I^-1 [G_s; G_w]_I row by row from banded
 * per-node stencils, with bounds tests skipped away from the grid edge. The oracle here builds
 * G_s and G_w as dense matrices straight from their definition (G_IJ = f_I sum_p V_p S_Ip
 * grad S_Jp, f_I = 1 - n_I for soil and n_I for water, Eqs. 67-68), takes K_I^-1 from the same
 * phase coupling, multiplies out, and compares every entry of A within the stencil's reach, and
 * b = -sum (G_s^T v_s* + G_w^T v_w*) / dt, to 1e-12 of the largest entry. The state is the one a
 * real step leaves: after some steps of the Terzaghi column (grid edges on all sides of a
 * 4-cell-wide column) and of the Xie-Leo column (porosity varying from node to node, water
 * points moved away from the soil points), double and single point, with drag in the correction
 * and without the pressure stabilisation (which adds its own penalty to A).
 *
 * Why the consistent projection leaves a pressure pattern of period two cells (docs/numerics.md,
 * "A pressure pattern of period two cells"): on a block seeded 2x2, 3x3 and 4x4 per cell, at rest
 * (points on their lattice), G_s and G_w of a nodal pressure alternating from node to node along
 * x, along y or both vanish at every node whose support lies inside the block, to round-off
 * against G of a linear pressure (the gradient of the interpolated alternation is odd about each
 * node, the weights S_I even, the points symmetric); so A, built from G, cannot see it. And the
 * Eq. 77 mapping of the interpolated alternation back to the nodes keeps 9/64 of it with 2x2
 * points (3/8 at the points, then 3/8 of that at the nodes), so a pattern that lasts is made
 * again by every solve.
 */
#include "../harness.h"
#include "case.h"
#include "phase_coupling.h"
#include "poro.h"
#include "semi_implicit.h"
#include "transfer.h"

#define CASES "tests/cases/"
#define ASSEMBLY_TOLERANCE 1e-12   /* relative to the largest |A| or |b| */
#define ALTERNATION_TOLERANCE 1e-12  /* round-off, relative to the natural scale of the quantity */

/* Adds one set's G (dense, [nodes][nodes][2]) for point volumes V; the caller applies f_I. */
static void dense_gradient(const struct sim *s, const struct particles *p, const double *V, double *G)
{
	const idx_t N = s->grid.node_count, nx = s->grid.nodes[0];
	const int S = p->support, nn = S * S;
	for (idx_t q = 0; q < p->n; q++) {
		const struct shape_factors f = particle_shape(p, q);
		for (int k = 0; k < nn; k++) {
			const idx_t I = p->node0[q] + k % S + (k / S) * nx;
			const double S_I = f.wx[k % S] * f.wy[k / S];
			for (int l = 0; l < nn; l++) {
				const idx_t J = p->node0[q] + l % S + (l / S) * nx;
				const double grad_S_J[2] = { f.dx[l % S] * f.wy[l / S], f.wx[l % S] * f.dy[l / S] };
				for (int c = 0; c < 2; c++)
					G[((size_t)I * N + J) * 2 + c] += V[q] * S_I * grad_S_J[c];
			}
		}
	}
}

/* Largest differences of A and b from the brute-force assembly, relative to their largest entries. */
static void compare(const struct sim *s, double *a_err, double *b_err)
{
	struct semi_implicit *si = semi_implicit_of(s);
	const struct grid_fields *f = &s->f;
	const struct pressure_system *ps = &si->ps;
	const idx_t N = s->grid.node_count, nx = s->grid.nodes[0];
	const int W = ps->width, R = ps->radius;
	double *Gs = calloc((size_t)N * N * 2, sizeof(double)), *Gw = calloc((size_t)N * N * 2, sizeof(double));
	double *A = calloc((size_t)N * N, sizeof(double)), *b = calloc((size_t)N, sizeof(double));
	/* the step's last phases already scaled the soil volumes by this step's dJ (step 8); the
	 * pressure matrix was built with the volumes before, V / dJ (single-point water shares them) */
	const struct particles *soil = &s->soil;
	double *V = malloc(sizeof(double) * (size_t)soil->n);
	for (idx_t q = 0; q < soil->n; q++) {
		const double *dF = soil->dF + 4 * q;
		V[q] = soil->volume[q] / (dF[0] * dF[3] - dF[1] * dF[2]);
	}
	dense_gradient(s, soil, V, Gs);
	dense_gradient(s, &s->water, s->double_point ? s->water.volume : V, Gw);
	free(V);
	for (idx_t I = 0; I < N; I++)
		for (idx_t J = 0; J < N; J++)
			for (int c = 0; c < 2; c++) {
				Gs[((size_t)I * N + J) * 2 + c] *= 1.0 - f->porosity[I];
				Gw[((size_t)I * N + J) * 2 + c] *= f->porosity[I];
			}
	const int drag = s->spec->formulation.drag_in_correction;
	for (idx_t I = 0; I < N; I++)
		for (int c = 0; c < 2; c++) {
			const struct phase_coupling K = phase_coupling_inverse(f->mass_s[I], f->mass_w[I],
									       drag ? si->drag_dt[I] : 0.0,
									       f->fix_s[I] & (1 << c), f->fix_w[I] & (1 << c));
			const double vs = K.ss > 0.0 ? si->v_s_star[2 * I + c] : 0.0;
			const double vw = K.ww > 0.0 ? si->v_w_star[2 * I + c] : 0.0;
			for (idx_t P = 0; P < N; P++) {
				const double gsP = Gs[((size_t)I * N + P) * 2 + c], gwP = Gw[((size_t)I * N + P) * 2 + c];
				if (gsP == 0.0 && gwP == 0.0)
					continue;
				b[P] -= (gsP * vs + gwP * vw) / s->dt;
				for (idx_t Q = 0; Q < N; Q++) {
					const double gsQ = Gs[((size_t)I * N + Q) * 2 + c], gwQ = Gw[((size_t)I * N + Q) * 2 + c];
					A[(size_t)P * N + Q] += gsP * (K.ss * gsQ + K.sw * gwQ) + gwP * (K.sw * gsQ + K.ww * gwQ);
				}
			}
		}
	double a_max = 0, a_diff = 0, b_max = 0, b_diff = 0;
	for (idx_t P = 0; P < N; P++) {
		const idx_t pi = P % nx, pj = P / nx;
		b_max = fmax(b_max, fabs(b[P]));
		b_diff = fmax(b_diff, fabs(b[P] - si->rhs[P]));
		for (idx_t Q = 0; Q < N; Q++) {
			const idx_t dx = Q % nx - pi, dy = Q / nx - pj;
			const double ref = A[(size_t)P * N + Q];
			a_max = fmax(a_max, fabs(ref));
			if (labs((long)dx) > R || labs((long)dy) > R) {
				a_diff = fmax(a_diff, fabs(ref));   /* beyond the stencil A must vanish */
				continue;
			}
			a_diff = fmax(a_diff, fabs(ref - ps->stencil[(size_t)P * W * W + (dx + R) + (dy + R) * W]));
		}
	}
	*a_err = a_max > 0 ? a_diff / a_max : 1.0;
	*b_err = b_max > 0 ? b_diff / b_max : 1.0;
	free(Gs), free(Gw), free(A), free(b);
}

static void check_case(const char *label, const char *file, enum case_phases phases, long steps)
{
	struct case_spec *c = NULL;
	struct sim *s = NULL;
	struct poro_error err = {0};
	int ok = !case_load_file(file, &c, &err);
	if (ok) {
		c->formulation.phases = phases;
		c->formulation.pressure_projection = PROJECTION_CONSISTENT;
		c->formulation.drag_in_correction = 1;
		c->formulation.pressure_stabilisation = PRESSURE_STABILISATION_NONE;
		ok = !sim_create(&s, c, &err);
	}
	for (long k = 0; ok && k < steps; k++)
		ok = !sim_step(s);
	double a_err = 1, b_err = 1;
	if (ok)
		compare(s, &a_err, &b_err);
	else
		printf("INFO %s: %s\n", label, s ? sim_error(s)->message : err.message);
	printf("INFO %s after %ld steps: A differs from the brute-force assembly by %.2e, b by %.2e (relative)\n",
	       label, steps, a_err, b_err);
	char name[128];
	snprintf(name, sizeof name, "consistent_projection_matrix_matches_brute_force_%s", label);
	CHECK(ok && a_err <= ASSEMBLY_TOLERANCE, name, "relative difference %.2e", a_err);
	snprintf(name, sizeof name, "consistent_projection_rhs_matches_brute_force_%s", label);
	CHECK(ok && b_err <= ASSEMBLY_TOLERANCE, name, "relative difference %.2e", b_err);
	sim_destroy(&s);
	case_destroy(&c);
}

/* A block filling an 8 x 8 cell grid, ppc^2 points per cell, nothing to move it (no gravity, no
 * load), drained at the top so that the pressure system is regular. */
static const char block_case[] =
	"{\"schema\": \"poro-case/1\", \"title\": \"block at rest\","
	" \"formulation\": {\"scheme\": \"semi_implicit\", \"phases\": \"double_point\","
	"   \"shape\": \"quadratic_bspline\", \"pressure_projection\": \"consistent\", \"drag_in_correction\": true},"
	" \"grid\": {\"origin\": [0.0, 0.0], \"extent\": [1.096, 1.096], \"cell_size\": 0.137},"
	" \"materials\": [{\"name\": \"soil\", \"model\": \"linear_elastic\", \"density\": 2650,"
	"   \"youngs_modulus\": 1e7, \"poisson_ratio\": 0.3}],"
	" \"bodies\": [{\"name\": \"block\", \"material\": \"soil\","
	"   \"rectangle\": {\"min\": [0, 0], \"max\": [1.096, 1.096]}, \"particles_per_cell\": %d,"
	"   \"porosity\": 0.37, \"hydraulic_conductivity\": 1e-3}],"
	" \"fluid\": {\"density\": 1000}, \"gravity\": {\"acceleration\": [0.0, 0.0]},"
	" \"boundaries\": {\"left\": {\"soil\": \"slip\", \"water\": \"slip\"},"
	"   \"right\": {\"soil\": \"slip\", \"water\": \"slip\"}, \"bottom\": {\"soil\": \"fixed\", \"water\": \"fixed\"},"
	"   \"top\": {\"drainage\": \"drained\"}},"
	" \"time\": {\"dt\": 1e-4, \"end\": 1e-3}}";

/* Nodal fields: the alternation along x (kind 0), along y (1), along both (2), and x itself (3). */
static void nodal_field(const struct grid *g, int kind, double *p)
{
	for (idx_t I = 0; I < g->node_count; I++) {
		const idx_t i = I % g->nodes[0], j = I / g->nodes[0];
		const double sx = i % 2 ? -1.0 : 1.0, sy = j % 2 ? -1.0 : 1.0;
		p[I] = kind == 0 ? sx : kind == 1 ? sy : kind == 2 ? sx * sy : (double)i * g->h;
	}
}

/* Largest |G p| over the nodes whose support lies inside the grid, for G = G_s + G_w. */
static double interior_gradient(const struct sim *s, const double *p, double *out)
{
	struct semi_implicit *si = semi_implicit_of(s);
	const struct grid *g = &s->grid;
	const idx_t R = si->ps.g_radius;
	memset(out, 0, sizeof(double) * 2 * (size_t)g->node_count);
	pressure_apply_gradient(s, si->ps.grad_s, p, out);
	pressure_apply_gradient(s, si->ps.grad_w, p, out);
	double largest = 0.0;
	for (idx_t I = 0; I < g->node_count; I++) {
		const idx_t i = I % g->nodes[0], j = I / g->nodes[0];
		if (i >= R && i < g->nodes[0] - R && j >= R && j < g->nodes[1] - R)
			largest = fmax(largest, fmax(fabs(out[2 * I]), fabs(out[2 * I + 1])));
	}
	return largest;
}

/* Eq. 77's round trip of the alternation along x: interpolated to the water points, then their
 * mean at the nodes (uniform masses); the ratio to the alternation at the interior nodes, and how
 * far it strays from one value there. */
static double smoothing_ratio(const struct sim *s, const double *m, double *scratch, double *spread)
{
	const struct grid *g = &s->grid;
	const idx_t R = semi_implicit_of(s)->ps.g_radius, N = g->node_count;
	double *at_points = malloc(sizeof(double) * ((size_t)s->water.n + 1)), *den = scratch + N;
	g2p_scalar(g, &s->water, m, at_points);
	memset(scratch, 0, sizeof(double) * 2 * (size_t)N);
	p2g_scalar(g, &s->water, NULL, at_points, scratch);
	p2g_scalar(g, &s->water, NULL, NULL, den);
	double lo = INFINITY, hi = -INFINITY;
	for (idx_t I = 0; I < N; I++) {
		const idx_t i = I % g->nodes[0], j = I / g->nodes[0];
		if (i >= R && i < g->nodes[0] - R && j >= R && j < g->nodes[1] - R) {
			const double r = scratch[I] / den[I] / m[I];
			lo = fmin(lo, r), hi = fmax(hi, r);
		}
	}
	free(at_points);
	*spread = hi - lo;
	return 0.5 * (lo + hi);
}

static void check_alternation(int ppc)
{
	char json[4096], name[128];
	snprintf(json, sizeof json, block_case, ppc);
	struct case_spec *c = NULL;
	struct sim *s = NULL;
	struct poro_error err = {0};
	int ok = !case_load_string(json, &c, &err) && !sim_create(&s, c, &err) && !sim_step(s);
	if (!ok) {
		CHECK(0, "block_at_rest_runs", "%s", s ? sim_error(s)->message : err.message);
		sim_destroy(&s);
		case_destroy(&c);
		return;
	}
	const size_t N = (size_t)s->grid.node_count;
	double *p = malloc(sizeof(double) * N), *out = malloc(sizeof(double) * 2 * N);
	nodal_field(&s->grid, 3, p);
	const double linear = interior_gradient(s, p, out);   /* V_I per unit gradient */
	double worst = 0.0;
	for (int kind = 0; kind < 3; kind++) {
		nodal_field(&s->grid, kind, p);
		worst = fmax(worst, interior_gradient(s, p, out) * s->grid.h / linear);
	}
	printf("INFO block %dx%d per cell at rest: |G m| of the node-to-node alternation (along x, y, both) at "
	       "interior nodes %.1e of |G x| h\n", ppc, ppc, worst);
	snprintf(name, sizeof name, "node_alternation_in_null_space_of_G_%dx%d", ppc, ppc);
	CHECK(worst <= ALTERNATION_TOLERANCE, name, "|G m| %.2e of |G x| h", worst);
	nodal_field(&s->grid, 0, p);
	double spread = 0.0;
	const double kept = smoothing_ratio(s, p, out, &spread);
	printf("INFO block %dx%d: Eq. 77 keeps %.4f of the interpolated alternation at the nodes (spread %.1e)\n",
	       ppc, ppc, kept, spread);
	if (ppc == 2) {
		CHECK(fabs(kept - 9.0 / 64.0) <= ALTERNATION_TOLERANCE && spread <= ALTERNATION_TOLERANCE,
		      "eq77_keeps_9_64_of_the_alternation_2x2", "%.17g (spread %.1e), want 9/64", kept, spread);
	}
	free(p), free(out);
	sim_destroy(&s);
	case_destroy(&c);
}

int main(void)
{
	for (int ppc = 2; ppc <= 4; ppc++)
		check_alternation(ppc);
	check_case("terzaghi_double_point", CASES "terzaghi.json", PHASES_DOUBLE_POINT, 7);
	check_case("terzaghi_single_point", CASES "terzaghi.json", PHASES_SINGLE_POINT, 7);
	check_case("xie_leo_double_point", CASES "xie_leo.json", PHASES_DOUBLE_POINT, 600);
	check_case("xie_leo_single_point", CASES "xie_leo.json", PHASES_SINGLE_POINT, 600);
	HARNESS_EXIT();
}
