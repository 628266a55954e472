/*
 * spd_solve.c - CHOLMOD behind spd_solve.h.
 *
 * The matrix, right-hand side and solution workspaces are CHOLMOD objects allocated once at
 * create with the largest size a run can need; a solve only resets their dimensions. The symbolic
 * factor is kept while the pattern (n, colptr, rowidx) is unchanged, checked by comparing against
 * a saved copy, which costs O(nnz) against the O(nnz(L)) numeric factorisation it precedes.
 *
 * Between steps the pressure matrix changes little (the points move a fraction of a cell), so
 * while the pattern is unchanged the last numeric factor is used as the preconditioner of a
 * conjugate-gradient solve: a few triangular solves instead of a factorisation. The solve is
 * accepted at a relative residual of SPD_PCG_TOLERANCE; if it takes more than SPD_PCG_MAX_ITER
 * iterations the matrix is factorised afresh and solved directly, so every answer is a direct
 * solve or one converged to that tolerance.
 */
#include "spd_solve.h"

#include <cholmod.h>
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#define SPD_PCG_TOLERANCE 1e-12   /* relative residual ||b - A x|| / ||b|| accepted from PCG */
#define SPD_PCG_MAX_ITER 12       /* beyond this the factor is stale: refactorise */

struct spd_solver {
	cholmod_common cm;
	cholmod_sparse *A;        /* upper triangle, capacity n_max x n_max, nnz_max */
	cholmod_factor *L;        /* symbolic + numeric factor, NULL until the first solve */
	cholmod_dense *B, *X, *Y, *E; /* right-hand side and cholmod_solve2 workspaces */
	idx_t n_max, nnz_max;
	idx_t pattern_n;          /* pattern of the current symbolic factor */
	idx_t *pattern_colptr, *pattern_rowidx;
	long analyses, factorisations, pcg_solves, pcg_iterations;
	double *r, *z, *p, *Ap;   /* [n_max] conjugate-gradient workspaces */
};

enum poro_status spd_solver_create(struct spd_solver **out, idx_t n_max, idx_t nnz_max, struct poro_error *err)
{
	*out = NULL;
	struct spd_solver *s = calloc(1, sizeof *s);
	if (!s)
		return poro_error_set(err, PORO_ENOMEM, "cannot allocate the pressure solver");
	cholmod_start(&s->cm);
	s->cm.print = 0;
	s->cm.error_handler = NULL;
	if (n_max < 1)
		n_max = 1;
	if (nnz_max < 1)
		nnz_max = 1;
	s->n_max = n_max;
	s->nnz_max = nnz_max;
	s->A = cholmod_allocate_sparse(n_max, n_max, nnz_max, 1, 1, 1, CHOLMOD_REAL, &s->cm);
	s->B = cholmod_zeros(n_max, 1, CHOLMOD_REAL, &s->cm);
	s->r = malloc(sizeof(double) * (size_t)n_max);
	s->z = malloc(sizeof(double) * (size_t)n_max);
	s->p = malloc(sizeof(double) * (size_t)n_max);
	s->Ap = malloc(sizeof(double) * (size_t)n_max);
	s->pattern_colptr = malloc(sizeof(idx_t) * ((size_t)n_max + 1));
	s->pattern_rowidx = malloc(sizeof(idx_t) * (size_t)nnz_max);
	if (!s->A || !s->B || !s->pattern_colptr || !s->pattern_rowidx || !s->r || !s->z || !s->p || !s->Ap) {
		spd_solver_destroy(&s);
		return poro_error_set(err, PORO_ENOMEM, "cannot allocate a pressure system of %ld unknowns",
				      (long)n_max);
	}
	s->pattern_n = -1;
	*out = s;
	return PORO_OK;
}

static int same_pattern(const struct spd_solver *s, idx_t n, const idx_t *colptr, const idx_t *rowidx)
{
	if (!s->L || n != s->pattern_n)
		return 0;
	if (memcmp(colptr, s->pattern_colptr, sizeof(idx_t) * ((size_t)n + 1)))
		return 0;
	return !memcmp(rowidx, s->pattern_rowidx, sizeof(idx_t) * (size_t)colptr[n]);
}

/* First column whose LDL' pivot is not positive, or -1. D_jj is the first entry of column j. */
static idx_t first_non_positive_pivot(const cholmod_factor *L)
{
	const int *p = L->p;
	const double *x = L->x;
	for (size_t j = 0; j < L->n; j++)
		if (!(x[p[j]] > 0.0))
			return (idx_t)j;
	return -1;
}

/* y = A x for the symmetric matrix stored as its upper triangle in CSC. */
static void symmetric_multiply(idx_t n, const idx_t *colptr, const idx_t *rowidx, const double *values,
			       const double *x, double *y)
{
	memset(y, 0, sizeof(double) * (size_t)n);
	for (idx_t j = 0; j < n; j++)
		for (idx_t k = colptr[j]; k < colptr[j + 1]; k++) {
			idx_t i = rowidx[k];
			y[i] += values[k] * x[j];
			if (i != j)
				y[j] += values[k] * x[i];
		}
}

/* out = L^-T L^-1 in with the current factor (the preconditioner, or the direct solve). */
static int factor_solve(struct spd_solver *s, idx_t n, const double *in, double *out)
{
	cholmod_dense *B = s->B;
	B->nrow = (size_t)n;
	B->d = (size_t)n;
	memcpy(B->x, in, sizeof(double) * (size_t)n);
	if (!cholmod_solve2(CHOLMOD_A, s->L, B, NULL, &s->X, NULL, &s->Y, &s->E, &s->cm))
		return 0;
	memcpy(out, s->X->x, sizeof(double) * (size_t)n);
	return 1;
}

static double dot(idx_t n, const double *a, const double *b)
{
	double sum = 0.0;
	for (idx_t i = 0; i < n; i++)
		sum += a[i] * b[i];
	return sum;
}

/* Conjugate gradients preconditioned by the existing factor. Returns 1 when converged. */
static int preconditioned_cg(struct spd_solver *s, idx_t n, const idx_t *colptr, const idx_t *rowidx,
			     const double *values, const double *b, double *x)
{
	double *r = s->r, *z = s->z, *p = s->p, *Ap = s->Ap;
	const double bnorm = sqrt(dot(n, b, b));
	if (bnorm == 0.0) {
		memset(x, 0, sizeof(double) * (size_t)n);
		return 1;
	}
	if (!factor_solve(s, n, b, x))
		return 0;
	symmetric_multiply(n, colptr, rowidx, values, x, Ap);
	for (idx_t i = 0; i < n; i++)
		r[i] = b[i] - Ap[i];
	if (!factor_solve(s, n, r, z))
		return 0;
	memcpy(p, z, sizeof(double) * (size_t)n);
	double rz = dot(n, r, z);
	for (int it = 0; it < SPD_PCG_MAX_ITER; it++) {
		if (sqrt(dot(n, r, r)) <= SPD_PCG_TOLERANCE * bnorm) {
			s->pcg_iterations += it;
			return 1;
		}
		symmetric_multiply(n, colptr, rowidx, values, p, Ap);
		const double pAp = dot(n, p, Ap);
		if (!(pAp > 0.0))
			return 0;
		const double alpha = rz / pAp;
		for (idx_t i = 0; i < n; i++) {
			x[i] += alpha * p[i];
			r[i] -= alpha * Ap[i];
		}
		if (!factor_solve(s, n, r, z))
			return 0;
		const double rz_new = dot(n, r, z);
		for (idx_t i = 0; i < n; i++)
			p[i] = z[i] + rz_new / rz * p[i];
		rz = rz_new;
	}
	return sqrt(dot(n, r, r)) <= SPD_PCG_TOLERANCE * bnorm;
}

/* A failed LL' pivot is a warning that leaves L->minor at the failing column; a simplicial LDL'
 * factorisation succeeds on indefinite matrices, so its pivots D_jj are checked. */
static enum poro_status factorise(struct spd_solver *s, idx_t n, struct poro_error *err)
{
	idx_t bad = -1;
	if (!cholmod_factorize(s->A, s->L, &s->cm) || s->cm.status == CHOLMOD_NOT_POSDEF || s->L->minor < (size_t)n)
		bad = (idx_t)s->L->minor;
	else if (!s->L->is_ll && !s->L->is_super)
		bad = first_non_positive_pivot(s->L);
	if (bad >= 0) {
		s->pattern_n = -1;   /* force a fresh analysis next time */
		return poro_error_set(err, PORO_ESOLVER, "pressure matrix is not positive definite (column %ld of %ld)",
				      (long)bad, (long)n);
	}
	s->factorisations++;
	return PORO_OK;
}

static enum poro_status solve(struct spd_solver *s, idx_t n, const idx_t *colptr, const idx_t *rowidx,
			      const double *values, const double *b, double *x, struct poro_error *err)
{
	if (n == 0)
		return PORO_OK;
	idx_t nnz = colptr[n];
	if (n > s->n_max || nnz > s->nnz_max)
		return poro_error_set(err, PORO_ESOLVER, "pressure system of %ld unknowns, %ld entries exceeds "
				      "its capacity (%ld, %ld)", (long)n, (long)nnz, (long)s->n_max, (long)s->nnz_max);
	const int same = same_pattern(s, n, colptr, rowidx);
	if (same) {
		if (preconditioned_cg(s, n, colptr, rowidx, values, b, x)) {
			s->pcg_solves++;
			return PORO_OK;
		}
	}
	cholmod_sparse *A = s->A;
	A->nrow = A->ncol = (size_t)n;
	memcpy(A->p, colptr, sizeof(idx_t) * ((size_t)n + 1));
	memcpy(A->i, rowidx, sizeof(idx_t) * (size_t)nnz);
	memcpy(A->x, values, sizeof(double) * (size_t)nnz);
	A->sorted = 1;
	A->packed = 1;
	if (!same) {
		cholmod_free_factor(&s->L, &s->cm);
		s->L = cholmod_analyze(A, &s->cm);
		if (!s->L)
			return poro_error_set(err, PORO_ENOMEM, "cholmod_analyze failed (status %d)", s->cm.status);
		s->pattern_n = n;
		memcpy(s->pattern_colptr, colptr, sizeof(idx_t) * ((size_t)n + 1));
		memcpy(s->pattern_rowidx, rowidx, sizeof(idx_t) * (size_t)nnz);
		s->analyses++;
	}
	enum poro_status st = factorise(s, n, err);
	if (st)
		return st;
	if (!factor_solve(s, n, b, x))
		return poro_error_set(err, PORO_ESOLVER, "cholmod_solve2 failed (status %d)", s->cm.status);
	return PORO_OK;
}

/* CHOLMOD's supernodal factor and solves run on the BLAS, whose OpenMP build splits its work by the
 * calling thread's thread count: the sums then differ in the last bits between one and two
 * threads, and the runs part. On one BLAS thread a run is bit for bit the same at any thread
 * count of the solver; on the landslides' pressure systems the factor-and-solve took about as long
 * on one BLAS thread as on two, within the machine's timing noise (docs/performance.md, "Threads"). */
enum poro_status spd_solver_solve(struct spd_solver *s, idx_t n, const idx_t *colptr, const idx_t *rowidx,
				  const double *values, const double *b, double *x, struct poro_error *err)
{
	const int threads = omp_get_max_threads();
	omp_set_num_threads(1);
	enum poro_status st = solve(s, n, colptr, rowidx, values, b, x, err);
	omp_set_num_threads(threads);
	return st;
}

void spd_solver_counts(const struct spd_solver *s, long *analyses, long *factorisations)
{
	*analyses = s->analyses;
	*factorisations = s->factorisations;
}

void spd_solver_pcg_counts(const struct spd_solver *s, long *solves, long *iterations)
{
	*solves = s->pcg_solves;
	*iterations = s->pcg_iterations;
}

void spd_solver_destroy(struct spd_solver **ps)
{
	struct spd_solver *s = ps ? *ps : NULL;
	if (!s)
		return;
	cholmod_free_factor(&s->L, &s->cm);
	cholmod_free_sparse(&s->A, &s->cm);
	cholmod_free_dense(&s->B, &s->cm);
	cholmod_free_dense(&s->X, &s->cm);
	cholmod_free_dense(&s->Y, &s->cm);
	cholmod_free_dense(&s->E, &s->cm);
	cholmod_finish(&s->cm);
	free(s->pattern_colptr);
	free(s->pattern_rowidx);
	free(s->r);
	free(s->z);
	free(s->p);
	free(s->Ap);
	free(s);
	*ps = NULL;
}
