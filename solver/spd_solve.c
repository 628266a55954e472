/*
 * spd_solve.c - CHOLMOD behind spd_solve.h.
 *
 * The matrix, right-hand side and solution workspaces are CHOLMOD objects allocated once at
 * create with the largest size a run can need; a solve only resets their dimensions. The symbolic
 * factor is kept while the pattern (n, colptr, rowidx) is unchanged, checked by comparing against
 * a saved copy, which costs O(nnz) against the O(nnz(L)) numeric factorisation it precedes.
 */
#include "spd_solve.h"

#include <cholmod.h>
#include <stdlib.h>
#include <string.h>

struct spd_solver {
	cholmod_common cm;
	cholmod_sparse *A;        /* upper triangle, capacity n_max x n_max, nnz_max */
	cholmod_factor *L;        /* symbolic + numeric factor, NULL until the first solve */
	cholmod_dense *B, *X, *Y, *E; /* right-hand side and cholmod_solve2 workspaces */
	idx_t n_max, nnz_max;
	idx_t pattern_n;          /* pattern of the current symbolic factor */
	idx_t *pattern_colptr, *pattern_rowidx;
	long analyses, factorisations;
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
	s->pattern_colptr = malloc(sizeof(idx_t) * ((size_t)n_max + 1));
	s->pattern_rowidx = malloc(sizeof(idx_t) * (size_t)nnz_max);
	if (!s->A || !s->B || !s->pattern_colptr || !s->pattern_rowidx) {
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

enum poro_status spd_solver_solve(struct spd_solver *s, idx_t n, const idx_t *colptr, const idx_t *rowidx,
				  const double *values, const double *b, double *x, struct poro_error *err)
{
	if (n == 0)
		return PORO_OK;
	idx_t nnz = colptr[n];
	if (n > s->n_max || nnz > s->nnz_max)
		return poro_error_set(err, PORO_ESOLVER, "pressure system of %ld unknowns, %ld entries exceeds "
				      "its capacity (%ld, %ld)", (long)n, (long)nnz, (long)s->n_max, (long)s->nnz_max);
	cholmod_sparse *A = s->A;
	A->nrow = A->ncol = (size_t)n;
	memcpy(A->p, colptr, sizeof(idx_t) * ((size_t)n + 1));
	memcpy(A->i, rowidx, sizeof(idx_t) * (size_t)nnz);
	memcpy(A->x, values, sizeof(double) * (size_t)nnz);
	A->sorted = 1;
	A->packed = 1;

	if (!same_pattern(s, n, colptr, rowidx)) {
		cholmod_free_factor(&s->L, &s->cm);
		s->L = cholmod_analyze(A, &s->cm);
		if (!s->L)
			return poro_error_set(err, PORO_ENOMEM, "cholmod_analyze failed (status %d)", s->cm.status);
		s->pattern_n = n;
		memcpy(s->pattern_colptr, colptr, sizeof(idx_t) * ((size_t)n + 1));
		memcpy(s->pattern_rowidx, rowidx, sizeof(idx_t) * (size_t)nnz);
		s->analyses++;
	}
	/* A failed LL' pivot is a warning that leaves L->minor at the failing column; a simplicial
	 * LDL' factorisation succeeds on indefinite matrices, so its pivots D_jj are checked. */
	idx_t bad = -1;
	if (!cholmod_factorize(A, s->L, &s->cm) || s->cm.status == CHOLMOD_NOT_POSDEF || s->L->minor < (size_t)n)
		bad = (idx_t)s->L->minor;
	else if (!s->L->is_ll && !s->L->is_super)
		bad = first_non_positive_pivot(s->L);
	if (bad >= 0) {
		s->pattern_n = -1;   /* force a fresh analysis next time */
		return poro_error_set(err, PORO_ESOLVER, "pressure matrix is not positive definite (column %ld of %ld)",
				      (long)bad, (long)n);
	}
	s->factorisations++;
	cholmod_dense *B = s->B;
	B->nrow = (size_t)n;
	B->d = (size_t)n;
	memcpy(B->x, b, sizeof(double) * (size_t)n);
	if (!cholmod_solve2(CHOLMOD_A, s->L, B, NULL, &s->X, NULL, &s->Y, &s->E, &s->cm))
		return poro_error_set(err, PORO_ESOLVER, "cholmod_solve2 failed (status %d)", s->cm.status);
	memcpy(x, s->X->x, sizeof(double) * (size_t)n);
	return PORO_OK;
}

void spd_solver_counts(const struct spd_solver *s, long *analyses, long *factorisations)
{
	*analyses = s->analyses;
	*factorisations = s->factorisations;
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
	free(s);
	*ps = NULL;
}
