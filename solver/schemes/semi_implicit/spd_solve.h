/*
 * spd_solve.h - sparse symmetric positive definite solves; the only gateway to CHOLMOD.
 *
 * The pressure Poisson system of the semi-implicit scheme (000 Eq. 60) is SPD once its Dirichlet
 * rows are removed. Between steps its pattern changes only when the set of active nodes does, so
 * the solver keeps the symbolic analysis (fill-reducing ordering), and while the pattern is
 * unchanged it first tries conjugate gradients preconditioned by the previous factor, factorising
 * again only when that does not converge to a relative residual of 1e-12 within a few iterations.
 *
 * Matrices are given as the upper triangle in compressed sparse column form (row <= col, rows
 * ascending within a column), zero-based, idx_t indices.
 */
#ifndef PORO_SPD_SOLVE_H
#define PORO_SPD_SOLVE_H

#include "error.h"
#include "particles.h"

struct spd_solver;

/* Creates a solver for systems of at most n_max unknowns and nnz_max upper-triangle entries. */
enum poro_status spd_solver_create(struct spd_solver **s, idx_t n_max, idx_t nnz_max, struct poro_error *err);

/* Solves A x = b. Returns PORO_ESOLVER if A is not positive definite (message names the column). */
enum poro_status spd_solver_solve(struct spd_solver *s, idx_t n, const idx_t *colptr, const idx_t *rowidx,
				  const double *values, const double *b, double *x, struct poro_error *err);

/* Statistics for benchmarks: symbolic analyses and numeric factorisations done so far, and the
 * solves answered by conjugate gradients on the previous factor, with their total iterations. */
void spd_solver_counts(const struct spd_solver *s, long *analyses, long *factorisations);
void spd_solver_pcg_counts(const struct spd_solver *s, long *solves, long *iterations);

void spd_solver_destroy(struct spd_solver **s);

#endif
