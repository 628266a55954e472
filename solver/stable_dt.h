/*
 * stable_dt.h - the largest time step a scheme can take on a case, known before the run.
 *
 * Semi-implicit (paper 000): the pressure (and in PoroMPM the drag, docs/numerics.md "Predictors
 * solved together") is implicit, so water's compressibility and the permeability do not bound dt,
 * but the soil skeleton's stress is explicit, so dt is bounded by the time a P-wave of the
 * skeleton takes to cross a cell (000 §1 and §6: "the critical time step is governed by the CFL
 * condition of the soil phase").
 *
 * Explicit (paper 002, spec-002 §5.1): everything is explicit, the pore pressure included, so dt is
 * bounded by the fast compressional wave of the coupled soil and compressible pore fluid crossing a
 * cell, h / c_fast, and, when the drag is integrated explicitly (formulation.drag "explicit", 002
 * Eq. 22 as printed), by the decay of the phases' relative velocity, 2 / lambda: forward Euler on
 * d(v_s - v_f)/dt = -lambda (v_s - v_f) is stable for lambda dt < 2, lambda = c_d (1 / rhō_s +
 * 1 / rhō_f), c_d = n^2 rho_f g / k (Eq. 12). The implicit nodal drag (the default) has no such bound.
 *
 * Implicit u-p-U (paper 001): Newmark's average acceleration (beta = 1/4, gamma = 1/2, or any pair
 * the loader accepts) is unconditionally stable for linear problems: no bound (body -1), dt is the
 * user's choice by accuracy, and "auto" is refused.
 *
 * case_load.c refuses a case whose dt exceeds stable_dt_max, names the bound with
 * stable_dt_describe, and takes stable_dt_recommended for "dt": "auto"; sim.c keeps the estimate
 * to quote it when a step fails (step_health.c).
 */
#ifndef PORO_STABLE_DT_H
#define PORO_STABLE_DT_H

#include "case.h"

/* Semi-implicit: refused above this many CFL steps h / c_p. The Terzaghi column's own limit, found
 * by bisection on dt with the default formulation, lies between 1.23 and 2.46 h / c_p over
 * E = 1e6-1e8 Pa and k = 1e-9-1 m/s, double and single point (0.87 with drag_in_correction at
 * k = 1e-9 m/s; docs/numerics.md "Stable time step"); the shipped case nearest its bound, the
 * Mohr-Coulomb slope, runs at 1.198 (000 §5.3's "about 0.92 CFL"). "auto" takes one CFL step. */
#define STABLE_DT_MAX_FACTOR 1.25
#define STABLE_DT_RECOMMENDED_FACTOR 1.0

/* Explicit: refused above the critical step itself, about half the limit measured on 002's
 * examples (2.0-2.1 h / c_fast; docs/numerics.md, "The explicit scheme of paper 002"); "auto"
 * takes 0.9 of it (spec-002 §5.1). */
#define STABLE_DT_EXPLICIT_MAX_FACTOR 1.0
#define STABLE_DT_EXPLICIT_RECOMMENDED_FACTOR 0.9

/* The bound of the most restrictive body and what it follows from. */
struct stable_dt {
	enum case_scheme scheme;
	double cfl;          /* the critical step, s: semi-implicit h / c_p; explicit the smaller of
				wave_step and drag_step */
	double wave_speed;   /* semi-implicit c_p = sqrt(modulus / density); explicit c_fast, m/s */
	double modulus;      /* constrained (P-wave) modulus K + 4G/3 of the skeleton, Pa */
	double density;      /* (1 - n0) rho_s, kg/m^3: the soil mass per volume the skeleton stress moves */
	int body;            /* index of the body whose wave sets it, -1 when there is none */
	double wave_step;    /* h / wave_speed, s */
	double drag_step;    /* explicit drag: 2 / lambda of drag_body, s; INFINITY otherwise */
	int drag_body;       /* -1 when no drag bound applies */
};

/* The estimate of the case's scheme for case c (its bodies, materials, fluid and grid must have
 * been read); out->body = -1 and cfl = INFINITY when the case has no body. */
void stable_dt_estimate(const struct case_spec *c, struct stable_dt *out);

/* The elastic constrained modulus K + 4G/3 of body i's material, Pa (Nor-Sand's at the pressure
 * estimated in stable_dt.c). */
double stable_dt_modulus(const struct case_spec *c, int i);

/* The explicit scheme's fast wave speed c_fast, m/s, in a soil of constrained modulus M (Pa),
 * grain density rho_s, porosity n, with pore fluid of density rho_f and bulk modulus K_f: the
 * larger root of the no-drag plane-wave problem of 002 Eqs. 9, 16-17 (spec-002 §5.1). */
double stable_dt_fast_wave_speed(double M, double rho_s, double n, double rho_f, double K_f);

/* The mass per volume of body i whose weight its skeleton carries, kg/m^3: the buoyant
 * (1 - n0)(rho_s - rho_w) of a saturated body, the dry (1 - n0) rho_s of a dry one
 * ("saturated": false). */
double stable_dt_effective_density(const struct case_spec *c, int i);

/* The largest dt the loader accepts, and the dt that "auto" takes. */
double stable_dt_max(const struct stable_dt *e);
double stable_dt_recommended(const struct stable_dt *e);

/* The bound in words for a message: "1.25 times the soil skeleton's CFL step h / c_p = ... (c_p =
 * ... in body 'B')" or the explicit scheme's critical step and its two parts. */
#define STABLE_DT_DESCRIPTION_SIZE 400
void stable_dt_describe(const struct stable_dt *e, const struct case_spec *c, char *text, size_t size);

#endif
