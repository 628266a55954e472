/*
 * strain_rate.c - step 6 of paper 002's explicit scheme: the points' strain rates from the
 * remapped nodal velocities (Eqs. 24-25) and the cell-average smoothing of both phases' volumetric
 * rates (Eqs. 26-27, after Mast et al. 2012), which relieves the volumetric locking of the nearly
 * incompressible undrained mixture and the pressure checkerboard that comes with it (002 §3.2.1).
 *
 * Eq. 26 writes alpha_p on both sides; its left side is the cell's mass-weighted average, which
 * every point of the cell takes (spec-002 §12 E4):
 *     rate_s(c) = sum_{p in c} m_s,p div v_s,p / sum m_s,p,   rate_f(c) likewise with m_f and div v_f.
 * Eq. 27 rebuilds the solid's rate as dev(L) + rate_s(c) I / 3 with the 3-D identity (plane
 * strain: L_zz = 0, so the smoothed rate has a zz part (rate_s(c) - div v_s,p) / 3, as in Hughes'
 * plane-strain B-bar; E9). The stress update receives it as dF = I + dt L~ and dF_zz = 1 + dt L~_zz.
 * "p in c" is the cell that held the point's centre at the step's start, where the shape
 * functions were evaluated.
 *
 * One volumetric rate per cell makes one pressure increment per cell, so the pore pressure is
 * cell-wise constant while the points keep their cells (002 Fig. 7 shows it so). A point that
 * crosses into another cell would carry its old cell's pressure into the new one, and the points
 * of a cell then hold pressures no rate of theirs accounts for and that the internal forces barely
 * resist; in a large deformation that part grows until a point inverts (002 §4.1.2's column at
 * 39 s, §4.4's block at 0.3 s; docs/numerics.md, "The explicit scheme of paper 002", one pressure per cell). So with the cell average
 * the points of a cell also share its fluid-mass-weighted mean pressure after each update
 * (explicit_cell_pressure), which a point entering a cell mixes into by its mass.
 */
#include <string.h>

#include "explicit.h"
#include "transfer.h"

void explicit_locate_cells(struct sim *s)
{
	struct explicit_state *e = explicit_of(s);
	const struct particles *p = &s->soil;
#pragma omp parallel for schedule(static)
	for (idx_t q = 0; q < p->n; q++)
		e->cell[q] = grid_cell_of(&s->grid, p->x + 2 * q);   /* inside: step 1 checked it */
}

/* Eqs. 24-25: L_p = sum_I v_s,I (x) grad S_Ip (row-major, dv_x/dx, dv_x/dy, dv_y/dx, dv_y/dy) and
 * div v_f,p = sum_I v_f,I . grad S_Ip, in one visit of each point. The fluid's rate also takes the
 * advection of porosity Eq. 7 writes, (v_f - v_s) . grad n / n, so that (1 - n) div v_s + n div_f
 * is the fluid's whole volume balance: Eq. 9 drops it ("neglecting spatial variations in density
 * and porosity"), and where consolidation has graded the porosity the dropped term compacted the
 * soil faster than its water can leave (docs/numerics.md, "The explicit scheme of paper 002"). */
static void point_rates(struct sim *s)
{
	struct explicit_state *e = explicit_of(s);
	const struct grid *g = &s->grid;
	const struct particles *p = &s->soil;
	const double *vs = s->f.v_s, *vf = s->f.v_w;
	double *L = s->soil_grad;
#pragma omp parallel for schedule(static)
	for (idx_t q = 0; q < p->n; q++) {
		double l[4] = {0, 0, 0, 0}, div_f = 0.0, w[2] = {0, 0};
		FOR_SUPPORT(g, p, q, {
			l[0] += vs[2 * I] * gx, l[1] += vs[2 * I] * gy;
			l[2] += vs[2 * I + 1] * gx, l[3] += vs[2 * I + 1] * gy;
			div_f += vf[2 * I] * gx + vf[2 * I + 1] * gy;
			w[0] += wk * (vf[2 * I] - vs[2 * I]), w[1] += wk * (vf[2 * I + 1] - vs[2 * I + 1]);
		});
		memcpy(L + 4 * q, l, sizeof l);
		e->div_s[q] = l[0] + l[3];
		const double *grad_n = e->grad_n + 2 * q;
		e->div_f[q] = div_f + (w[0] * grad_n[0] + w[1] * grad_n[1]) / p->porosity[q];
	}
}

/* Eq. 26: each cell's mass-weighted mean rates, given to its points. */
static void cell_averages(struct sim *s)
{
	struct explicit_state *e = explicit_of(s);
	const struct particles *p = &s->soil, *w = &s->water;
	double *sums = e->cell_sums;
	memset(sums, 0, 4 * sizeof(double) * (size_t)s->grid.cell_count);
	FOR_POINTS_BY_BLOCK(p, q, {   /* q's cell is in q's block: in parallel (point_blocks.h) */
		double *c = sums + 4 * (size_t)e->cell[q];
		c[0] += p->mass[q] * e->div_s[q], c[1] += p->mass[q];
		c[2] += w->mass[q] * e->div_f[q], c[3] += w->mass[q];
	});
#pragma omp parallel for schedule(static)
	for (idx_t q = 0; q < p->n; q++) {
		const double *c = sums + 4 * (size_t)e->cell[q];   /* the point's own mass is in it: > 0 */
		e->rate_s[q] = c[0] / c[1];
		e->rate_f[q] = c[3] > 0.0 ? c[2] / c[3] : e->div_f[q];
	}
}

void explicit_strain_rates(struct sim *s)
{
	struct explicit_state *e = explicit_of(s);
	struct particles *p = &s->soil;
	const double dt = s->dt;
	const size_t n = (size_t)p->n;
	point_rates(s);
	if (s->spec->formulation.strain_rate_smoothing == STRAIN_RATE_SMOOTHING_CELL_AVERAGE) {
		cell_averages(s);
	} else {
		memcpy(e->rate_s, e->div_s, n * sizeof(double));
		memcpy(e->rate_f, e->div_f, n * sizeof(double));
	}
	/* Eq. 27: L~ = L + (rate_s - div v_s) I / 3 on xx, yy and zz; without smoothing L~ = L */
	const double *L = s->soil_grad;
#pragma omp parallel for schedule(static)
	for (idx_t q = 0; q < p->n; q++) {
		const double shift = (e->rate_s[q] - e->div_s[q]) / 3.0;
		double *dF = p->dF + 4 * q;
		dF[0] = 1.0 + dt * (L[4 * q] + shift);
		dF[1] = dt * L[4 * q + 1];
		dF[2] = dt * L[4 * q + 2];
		dF[3] = 1.0 + dt * (L[4 * q + 3] + shift);
		p->dF_zz[q] = 1.0 + dt * shift;
	}
}

void explicit_cell_pressure(struct sim *s)
{
	struct explicit_state *e = explicit_of(s);
	struct particles *w = &s->water;
	double *sums = e->cell_sums;
	memset(sums, 0, 4 * sizeof(double) * (size_t)s->grid.cell_count);
	FOR_POINTS_BY_BLOCK(w, q, {   /* q's cell is in q's block: in parallel (point_blocks.h) */
		double *c = sums + 4 * (size_t)e->cell[q];
		c[0] += w->mass[q] * w->pressure[q], c[1] += w->mass[q];
	});
#pragma omp parallel for schedule(static)
	for (idx_t q = 0; q < w->n; q++) {
		const double *c = sums + 4 * (size_t)e->cell[q];   /* the point's own mass is in it: > 0 */
		w->pressure[q] = c[0] / c[1];
	}
}
