/*
 * lu_solve.c - UMFPACK behind lu_solve.h.
 *
 * UMFPACK's defaults suit the system: its automatic strategy chooses the symmetric one for a
 * matrix with a symmetric pattern and a mostly nonzero diagonal, ordering A + A' by AMD and
 * preferring diagonal pivots while they are not below the symmetric pivot tolerance, and taking
 * off-diagonal pivots (the pore-pressure block's tiny diagonal) where they are; rows are scaled
 * by their sums. The caller scales the pressure unknowns to the stiffness's order beforehand
 * (implicit.c), which the pivot choice needs most.
 */
#include "lu_solve.h"

#include <omp.h>
#include <stdlib.h>
#include <umfpack.h>

struct lu_solver {
	idx_t n;
	const idx_t *colptr, *rowidx;   /* borrowed pattern */
	const double *values;           /* the last factorised values, borrowed until the next call */
	void *symbolic, *numeric;
	double control[UMFPACK_CONTROL], info[UMFPACK_INFO];
	long analyses, factorisations, solves, factor_nonzeros;
};

/* The message for a non-OK UMFPACK status. */
static const char *status_text(double status)
{
	switch ((int)status) {
	case UMFPACK_WARNING_singular_matrix: return "the matrix is singular";
	case UMFPACK_ERROR_out_of_memory: return "out of memory";
	case UMFPACK_ERROR_invalid_matrix: return "the matrix pattern is invalid";
	case UMFPACK_ERROR_different_pattern: return "the pattern changed since the analysis";
	default: return "UMFPACK failed";
	}
}

static enum poro_status fail(struct lu_solver *s, const char *what, struct poro_error *err)
{
	const double status = s->info[UMFPACK_STATUS];
	return poro_error_set(err, status == UMFPACK_ERROR_out_of_memory ? PORO_ENOMEM : PORO_ESOLVER,
			      "%s of the %ld-unknown implicit system: %s (UMFPACK status %d)", what, (long)s->n,
			      status_text(status), (int)status);
}

enum poro_status lu_solver_create(struct lu_solver **out, idx_t n, const idx_t *colptr, const idx_t *rowidx,
				  struct poro_error *err)
{
	struct lu_solver *s = calloc(1, sizeof *s);
	*out = NULL;
	if (!s)
		return poro_error_set(err, PORO_ENOMEM, "cannot allocate the implicit system's solver");
	s->n = n, s->colptr = colptr, s->rowidx = rowidx;
	umfpack_di_defaults(s->control);
	s->control[UMFPACK_PRL] = 0;   /* the library never prints */
	s->control[UMFPACK_IRSTEP] = LU_REFINEMENT_STEPS;
	*out = s;
	return PORO_OK;
}

static enum poro_status factorise(struct lu_solver *s, const double *values, struct poro_error *err)
{
	if (!s->symbolic) {
		if (umfpack_di_symbolic(s->n, s->n, s->colptr, s->rowidx, values, &s->symbolic, s->control, s->info) !=
		    UMFPACK_OK)
			return fail(s, "the symbolic analysis", err);
		s->analyses++;
	}
	if (s->numeric)
		umfpack_di_free_numeric(&s->numeric);
	const int status = umfpack_di_numeric(s->colptr, s->rowidx, values, s->symbolic, &s->numeric, s->control,
					      s->info);
	if (status != UMFPACK_OK) {
		if (s->numeric)
			umfpack_di_free_numeric(&s->numeric);
		return fail(s, "the factorisation", err);
	}
	s->values = values;
	s->factorisations++;
	s->factor_nonzeros = (long)(s->info[UMFPACK_LNZ] + s->info[UMFPACK_UNZ]);
	return PORO_OK;
}

static enum poro_status solve(struct lu_solver *s, const double *b, double *x, double *backward_error,
			      struct poro_error *err)
{
	if (!s->numeric)
		return poro_error_set(err, PORO_ESOLVER, "the implicit system was solved before it was factorised");
	if (umfpack_di_solve(UMFPACK_A, s->colptr, s->rowidx, s->values, x, b, s->numeric, s->control, s->info) !=
	    UMFPACK_OK)
		return fail(s, "the solve", err);
	s->solves++;
	if (backward_error)
		*backward_error = s->info[UMFPACK_OMEGA1];
	return PORO_OK;
}

/* UMFPACK's dense kernels run on the BLAS, whose OpenMP build splits its work by the calling
 * thread's thread count, so the factors and solutions differed in the last bits between one and
 * two threads and the runs parted from the first step (tests/solver/thread_count_test.c). On one
 * BLAS thread a run is the same bit for bit at any thread count of the solver, as the
 * semi-implicit scheme's CHOLMOD solves are kept (spd_solve.c); the cost is in docs/performance.md,
 * "Threads on every scheme". */
enum poro_status lu_solver_factorise(struct lu_solver *s, const double *values, struct poro_error *err)
{
	const int threads = omp_get_max_threads();
	omp_set_num_threads(1);
	const enum poro_status st = factorise(s, values, err);
	omp_set_num_threads(threads);
	return st;
}

enum poro_status lu_solver_solve(struct lu_solver *s, const double *b, double *x, double *backward_error,
				 struct poro_error *err)
{
	const int threads = omp_get_max_threads();
	omp_set_num_threads(1);
	const enum poro_status st = solve(s, b, x, backward_error, err);
	omp_set_num_threads(threads);
	return st;
}

void lu_solver_counts(const struct lu_solver *s, long *analyses, long *factorisations, long *solves,
		      long *factor_nonzeros)
{
	*analyses = s->analyses, *factorisations = s->factorisations, *solves = s->solves;
	*factor_nonzeros = s->factor_nonzeros;
}

void lu_solver_destroy(struct lu_solver **ps)
{
	struct lu_solver *s = ps ? *ps : NULL;
	if (!s)
		return;
	if (s->numeric)
		umfpack_di_free_numeric(&s->numeric);
	if (s->symbolic)
		umfpack_di_free_symbolic(&s->symbolic);
	free(s);
	*ps = NULL;
}
