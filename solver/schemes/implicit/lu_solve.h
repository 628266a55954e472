/*
 * lu_solve.h - sparse unsymmetric (or symmetric indefinite) LU solves; the only gateway to UMFPACK.
 *
 * The implicit u-p-U scheme's Newmark matrix K = 4/dt^2 M + 2/dt C + K (001 Eq. 9) is symmetric
 * but indefinite, its pore-pressure block near zero, so CHOLMOD (spd_solve.h) cannot factorise it;
 * UMFPACK's LU with threshold partial pivoting can (spec-001 §4.3). The matrix's pattern is the
 * whole grid's, fixed for the run (a node's 5 unknowns coupled to every node within two cells,
 * inactive unknowns held by unit diagonals), so the symbolic analysis (the fill-reducing ordering)
 * is done once per run, and only the numeric factorisation is redone, once per step (the modified
 * Newton-Raphson of 001 §2.2) or once per iteration (full Newton).
 *
 * Matrices are in compressed sparse column form, zero-based, idx_t indices, rows ascending within
 * a column; the pattern passed at create must stay valid (it is borrowed) until destroy.
 */
#ifndef PORO_LU_SOLVE_H
#define PORO_LU_SOLVE_H

#include "error.h"
#include "particles.h"

struct lu_solver;

/* A solver for n x n matrices of the pattern colptr[n + 1], rowidx[colptr[n]]. */
enum poro_status lu_solver_create(struct lu_solver **s, idx_t n, const idx_t *colptr, const idx_t *rowidx,
				  struct poro_error *err);

/* Factorises the matrix with these values (the create's pattern): the symbolic analysis on the
 * first call, the numeric factorisation every call. PORO_ESOLVER when the matrix is singular or
 * UMFPACK fails, the message naming why; PORO_ENOMEM when it runs out of memory. */
enum poro_status lu_solver_factorise(struct lu_solver *s, const double *values, struct poro_error *err);

/* Solves A x = b with the last factorisation. No iterative refinement: the Newton loop that calls
 * it recomputes the true residual after every correction, which is refinement already, and
 * UMFPACK's two default steps tripled the cost of a solve (each a product with A and a solve with
 * the factors). *backward_error gets UMFPACK's relative backward error of the answer (may be NULL). */
#define LU_REFINEMENT_STEPS 0
enum poro_status lu_solver_solve(struct lu_solver *s, const double *b, double *x, double *backward_error,
				 struct poro_error *err);

/* For benchmarks and tests: symbolic analyses, numeric factorisations and solves done so far, and
 * the nonzeros of the last factorisation's L and U. */
void lu_solver_counts(const struct lu_solver *s, long *analyses, long *factorisations, long *solves,
		      long *factor_nonzeros);

void lu_solver_destroy(struct lu_solver **s);

#endif
