/*
 * explicit.h - paper 002's explicit stabilised single-point v-w scheme: its own state and the files
 * that serve it (schemes/explicit/). Not public; the rest of the solver sees the scheme through
 * scheme.h.
 *
 *   explicit.c          the step (002 §3.3 steps 1-9): maps, the nodal momentum of both phases
 *                       (Eqs. 20-23) with the drag, FLIP, the MUSL remap, the state update
 *   strain_rate.c       the points' strain rates (Eqs. 24-25) and their cell average (Eqs. 26-27)
 *   pressure_rate.c     the pore pressure of the compressible fluid (Eq. 9), node-based multi-field
 *                       projection of its rate (Eqs. 28-34)
 *
 * One set of points carries both phases (single point, particles.h): the soil set holds the
 * positions, the solid velocity v_s, the solid mass m_s = (1 - n0) rho_s V0, the effective stress,
 * volume and porosity; the water set rides on it and holds the fluid velocity v_f, the fluid mass
 * m_f = n rho_f V (recomputed every step: single point conserves no fluid per point) and the pore
 * pressure (tension positive inside the solver, as everywhere: pi = -p_f of 002).
 *
 * Everything the scheme carries between steps lives on the points, so a checkpoint of the points
 * is a checkpoint of the scheme; the arrays here are rebuilt every step.
 */
#ifndef PORO_EXPLICIT_H
#define PORO_EXPLICIT_H

#include "sim_internal.h"

struct explicit_state {
	/* nodal (node_count each) */
	double *drag;            /* C_I = sum_p S_Ip c_d,p V_p, c_d = n^2 rho_f g / k (002 Eq. 12), kg/(m s)
				    per m of thickness: the implicit nodal drag (spec-002 §5, step 3b) */
	double *rate_moments;    /* [rate_width node_count] the pressure rate's projection (Eq. 33): sum
				    S V Q pdot* and sum S V Q Q^T, see pressure_rate.c */
	double *rate_nodal;      /* [3 node_count] a_I of Eq. 33 (constant basis: a_0 only) */
	int rate_width;          /* doubles per node in rate_moments */
	/* per cell (cell_count each) */
	double *cell_sums;       /* [4 cell_count] Eq. 26: sum m_s eps_v,s, sum m_s, sum m_f eps_v,f, sum m_f */
	/* per point (n each) */
	idx_t *cell;             /* the cell holding the point at the step's start (Eq. 26's p in c) */
	double *pressure_s;      /* (1 - n) pi: the pore pressure's share on the solid (Eq. 21) */
	double *pressure_f;      /* n pi: on the fluid (Eq. 23) */
	double *drag_point;      /* c_d V of the point (Eq. 22), kg/(m s) */
	double *grad_n;          /* [2n] the porosity's gradient at the point, from the nodal porosity,
				    1/m: the buoyancy's (Eq. 13) and the fluid's advection (Eq. 7) */
	double *div_s, *div_f;   /* the points' own volumetric strain rates of the solid and fluid, 1/s */
	double *rate_s, *rate_f; /* the rates the step uses: the cell averages (Eq. 26) or div_s, div_f */
	double *pressure_rate;   /* dp_f/dt* of Eq. 9 at the points, then the projected one (Eq. 34), Pa/s
				    (physical sign: compression positive) */
};

static inline struct explicit_state *explicit_of(const struct sim *s)
{
	return s->scheme_state;
}

/* strain_rate.c: step 6. The solid's velocity gradient L_p (into s->soil_grad) and both phases'
 * volumetric strain rates at the points from the remapped nodal velocities (Eqs. 24-25), then the
 * rates the step uses: their cell averages (Eq. 26) with formulation.strain_rate_smoothing
 * "cell_average", else the points' own. Finally each soil point's dF = I + dt L~ with L~ of Eq. 27
 * (the deviatoric part of L and a third of the averaged rate on each of the three axes, zz
 * included, into p->dF_zz). Needs explicit_locate_cells at the step's start. */
void explicit_locate_cells(struct sim *s);
void explicit_strain_rates(struct sim *s);
/* With the cell average: every point of a cell takes the cell's fluid-mass-weighted mean pore
 * pressure (strain_rate.c says why). */
void explicit_cell_pressure(struct sim *s);

/* pressure_rate.c: step 7's pore pressure. pdot*_p = -(K_f / n_p) ((1 - n_p) rate_s + n_p rate_f)
 * (Eq. 9 with the smoothed rates, Eq. 30), projected node by node with the multi-field principle
 * (Eqs. 33-34, constant or linear basis) unless formulation.pressure_rate_projection is "none";
 * then p_f += dt pdot_p at every point. Uses the porosity at the step's start. */
void explicit_pressure_rate(struct sim *s);

#endif
