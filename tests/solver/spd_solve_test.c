/*
 * spd_solve_test.c - the CHOLMOD gateway: solves of SPD systems checked by the
 * scaled residual ||A x - b|| / (||A|| ||x|| + ||b||) for direct solves and the relative residual
 * for solves answered by conjugate gradients on the previous factor; the factor reused while the
 * values change little, a refactorisation when they change a lot, a fresh analysis when the
 * pattern changes, and an indefinite matrix reported.
 */
#include "../harness.h"
#include "spd_solve.h"

/* A 2-D 9-point stencil matrix on an m x m grid, SPD by diagonal dominance, random weights. */
static idx_t build(idx_t m, double shift, idx_t *colptr, idx_t *rowidx, double *val, double *dense)
{
	idx_t n = m * m, nnz = 0;
	for (idx_t J = 0; J < n; J++) {
		colptr[J] = nnz;
		idx_t jx = J % m, jy = J / m;
		for (int dy = -1; dy <= 1; dy++)
			for (int dx = -1; dx <= 1; dx++) {
				idx_t ix = jx + dx, iy = jy + dy;
				if (ix < 0 || iy < 0 || ix >= m || iy >= m)
					continue;
				idx_t I = ix + iy * m;
				if (I > J)
					continue;
				double v = I == J ? 8.0 + shift : -rnd(0.1, 0.95);
				rowidx[nnz] = I;
				val[nnz++] = v;
				dense[I * n + J] = dense[J * n + I] = v;
			}
	}
	colptr[n] = nnz;
	return n;
}

static double scaled_residual(idx_t n, const double *A, const double *x, const double *b)
{
	double r2 = 0, x2 = 0, b2 = 0, anorm = 0;
	for (idx_t i = 0; i < n; i++) {
		double r = -b[i], row = 0;
		for (idx_t j = 0; j < n; j++) {
			r += A[i * n + j] * x[j];
			row += fabs(A[i * n + j]);
		}
		r2 += r * r, x2 += x[i] * x[i], b2 += b[i] * b[i];
		anorm = fmax(anorm, row);
	}
	return sqrt(r2) / (anorm * sqrt(x2) + sqrt(b2));
}

static double relative_residual(idx_t n, const double *A, const double *x, const double *b)
{
	double r2 = 0, b2 = 0;
	for (idx_t i = 0; i < n; i++) {
		double r = -b[i];
		for (idx_t j = 0; j < n; j++)
			r += A[i * n + j] * x[j];
		r2 += r * r, b2 += b[i] * b[i];
	}
	return sqrt(r2 / b2);
}

int main(void)
{
	const idx_t m = 23, n = m * m, nnz_max = 5 * n;
	idx_t *colptr = malloc(sizeof(idx_t) * (n + 1)), *rowidx = malloc(sizeof(idx_t) * nnz_max);
	double *val = malloc(sizeof(double) * nnz_max), *A = calloc((size_t)n * n, sizeof(double));
	double *b = malloc(sizeof(double) * n), *x = malloc(sizeof(double) * n);
	struct spd_solver *s = NULL;
	struct poro_error err = {0};
	CHECK(spd_solver_create(&s, n, nnz_max, &err) == PORO_OK, "spd_create", "%s", err.message);

	long analyses, factorisations, pcg_solves, pcg_iterations;
	build(m, 0.0, colptr, rowidx, val, A);
	for (int round = 0; round < 3; round++) {
		if (round > 0)   /* the same pattern, values changed by up to 1%: as between two steps */
			for (idx_t J = 0; J < n; J++)
				for (idx_t k = colptr[J]; k < colptr[J + 1]; k++) {
					val[k] *= 1.0 + rnd(-0.01, 0.01);
					A[rowidx[k] * n + J] = A[J * n + rowidx[k]] = val[k];
				}
		for (idx_t i = 0; i < n; i++)
			b[i] = rnd(-3.7, 5.1);
		enum poro_status st = spd_solver_solve(s, n, colptr, rowidx, val, b, x, &err);
		double res = scaled_residual(n, A, x, b), rel = relative_residual(n, A, x, b);
		printf("INFO round %d scaled residual %.3e, relative residual %.3e\n", round, res, rel);
		if (round == 0)   /* a direct solve */
			CHECK(st == PORO_OK && res < 1e-14, "spd_direct_scaled_residual", "status %d residual %.3e", st, res);
		else              /* answered by PCG: its documented tolerance ||b - A x|| <= 1e-12 ||b|| */
			CHECK(st == PORO_OK && rel <= 1e-12, "spd_pcg_relative_residual", "status %d residual %.3e", st, rel);
	}
	spd_solver_counts(s, &analyses, &factorisations);
	spd_solver_pcg_counts(s, &pcg_solves, &pcg_iterations);
	printf("INFO %ld analyses, %ld factorisations, %ld PCG solves in %ld iterations\n", analyses, factorisations,
	       pcg_solves, pcg_iterations);
	CHECK(analyses == 1 && factorisations == 1 && pcg_solves == 2, "spd_factor_reused_as_preconditioner",
	      "%ld analyses, %ld factorisations, %ld PCG solves", analyses, factorisations, pcg_solves);

	/* values far from the factored ones: PCG gives up and the matrix is factorised again */
	memset(A, 0, sizeof(double) * (size_t)n * n);
	build(m, 40.0, colptr, rowidx, val, A);
	for (idx_t J = 0; J < n; J++)
		for (idx_t k = colptr[J]; k < colptr[J + 1]; k++)
			if (rowidx[k] != J) {
				val[k] *= 9.0;
				A[rowidx[k] * n + J] = A[J * n + rowidx[k]] = val[k];
			}
	enum poro_status st0 = spd_solver_solve(s, n, colptr, rowidx, val, b, x, &err);
	double res0 = scaled_residual(n, A, x, b);
	spd_solver_counts(s, &analyses, &factorisations);
	CHECK(st0 == PORO_OK && res0 < 1e-14, "spd_changed_matrix_solved_accurately", "status %d residual %.3e", st0, res0);
	printf("INFO changed matrix: %ld factorisations so far, residual %.3e\n", factorisations, res0);

	/* a smaller system: new pattern, new analysis */
	memset(A, 0, sizeof(double) * (size_t)n * n);
	idx_t n2 = build(m - 4, 0.0, colptr, rowidx, val, A);
	enum poro_status st = spd_solver_solve(s, n2, colptr, rowidx, val, b, x, &err);
	spd_solver_counts(s, &analyses, &factorisations);
	CHECK(st == PORO_OK && analyses == 2 && scaled_residual(n2, A, x, b) < 1e-14, "spd_new_pattern_reanalysed",
	      "status %d, %ld analyses", st, analyses);

	/* an indefinite matrix: diagonal far below the off-diagonal sum */
	memset(A, 0, sizeof(double) * (size_t)n * n);
	build(m, -10.0, colptr, rowidx, val, A);
	st = spd_solver_solve(s, n, colptr, rowidx, val, b, x, &err);
	CHECK(st == PORO_ESOLVER && strstr(err.message, "not positive definite"), "spd_indefinite_reported",
	      "status %d '%s'", st, err.message);

	spd_solver_destroy(&s);
	CHECK(s == NULL, "spd_destroy_clears_pointer", "pointer not cleared");
	spd_solver_destroy(&s);   /* accepts NULL */
	free(colptr), free(rowidx), free(val), free(A), free(b), free(x);
	HARNESS_EXIT();
}
