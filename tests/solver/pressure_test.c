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
 */
#include "../harness.h"
#include "case.h"
#include "phase_coupling.h"
#include "poro.h"
#include "semi_implicit.h"

#define CASES "tests/cases/"
#define ASSEMBLY_TOLERANCE 1e-12   /* relative to the largest |A| or |b| */

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

int main(void)
{
	check_case("terzaghi_double_point", CASES "terzaghi.json", PHASES_DOUBLE_POINT, 7);
	check_case("terzaghi_single_point", CASES "terzaghi.json", PHASES_SINGLE_POINT, 7);
	check_case("xie_leo_double_point", CASES "xie_leo.json", PHASES_DOUBLE_POINT, 600);
	check_case("xie_leo_single_point", CASES "xie_leo.json", PHASES_SINGLE_POINT, 600);
	HARNESS_EXIT();
}
