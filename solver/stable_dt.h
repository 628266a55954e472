/*
 * stable_dt.h - the largest time step a scheme can take on a case, known before the run.
 *
 * Paper 000's step is semi-implicit: the pressure (and in PoroMPM the drag, docs/numerics.md
 * "Predictors solved together") is implicit, so water's compressibility and the permeability do
 * not bound dt, but the soil skeleton's stress is explicit, so dt is bounded by the time a P-wave
 * of the skeleton takes to cross a cell (000 §1 and §6: "the critical time step is governed by the
 * CFL condition of the soil phase"). Each scheme adds its own estimate here; case_load.c refuses a
 * case whose dt exceeds STABLE_DT_MAX_FACTOR times it, and sim.c quotes it when a step fails.
 */
#ifndef PORO_STABLE_DT_H
#define PORO_STABLE_DT_H

#include "case.h"

/* Refused above this many CFL steps h / c_p. The Terzaghi column's own limit, found by bisection
 * on dt with the default formulation, lies between 1.23 and 2.46 h / c_p over E = 1e6-1e8 Pa and
 * k = 1e-9-1 m/s, double and single point (0.87 with drag_in_correction at k = 1e-9 m/s;
 * docs/numerics.md "Stable time step"); the shipped case nearest its bound, the Mohr-Coulomb
 * slope, runs at 1.198 (000 §5.3's "about 0.92 CFL"). */
#define STABLE_DT_MAX_FACTOR 1.25

/* The CFL step of the stiffest body and what it follows from. */
struct stable_dt {
	double cfl;          /* h / c_p, s */
	double wave_speed;   /* c_p = sqrt(modulus / density), m/s */
	double modulus;      /* constrained (P-wave) modulus K + 4G/3, Pa */
	double density;      /* (1 - n0) rho_s, kg/m^3: the soil mass per volume the skeleton stress moves */
	int body;            /* index of the body that sets it, -1 when there is none */
};

/* The semi-implicit scheme's estimate for case c (its bodies, materials and grid must have been
 * read); out->body = -1 and cfl = INFINITY when the case has no body. */
void stable_dt_estimate(const struct case_spec *c, struct stable_dt *out);

/* The elastic constrained modulus K + 4G/3 of body i's material, Pa (Nor-Sand's at the pressure
 * estimated in stable_dt.c). */
double stable_dt_modulus(const struct case_spec *c, int i);

/* The mass per volume of body i whose weight its skeleton carries, kg/m^3: the buoyant
 * (1 - n0)(rho_s - rho_w) of a saturated body, the dry (1 - n0) rho_s of a dry one
 * ("saturated": false). */
double stable_dt_effective_density(const struct case_spec *c, int i);

/* The largest dt the loader accepts: STABLE_DT_MAX_FACTOR times out->cfl. */
double stable_dt_max(const struct stable_dt *e);

#endif
