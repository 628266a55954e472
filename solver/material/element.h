/*
 * element.h - the single-element driver of 000 App. B.2: one material point through a triaxial
 * test, undrained (Eqs. 98-106) or drained at constant cell pressure (Eqs. 107-110), for any model
 * of material.h, small or finite strain. `poro-solve element CASE.json --out DIR` is its command
 * line; docs/element.md describes the case and the output.
 *
 * Axes: x is the axial direction, y and z the lateral ones (the in-plane y and the out-of-plane z
 * of the plane-strain interface, stretched by dF_zz). The point starts at the isotropic effective
 * stress -confining_pressure (tension positive), with the model's state initialised for it.
 *   undrained: isochoric, dF = diag(exp(dE), exp(-dE/2), exp(-dE/2)) per step at finite strain
 *              (Eq. 106 with 1 + d eps_a = exp(dE), so the final logarithmic strain is exactly
 *              the case's axial_strain), d eps = diag(dE, -dE/2, -dE/2) at small strain (Eq. 99).
 *   drained:   the lateral Cauchy stresses stay at -confining_pressure, so dq = 3 dp (Eq. 107).
 *              Each step starts from the lateral strain of Eqs. 108/110 (the previous step's
 *              tangent) and corrects it by Newton's method with the consistent tangent until the
 *              lateral stresses are held to ELEMENT_STRESS_TOLERANCE (element.c).
 * dE = axial_strain / steps; axial strain negative is compression (000's sign).
 *
 * Ownership: element_case_load_* fill a caller's struct; element_run allocates the result's rows,
 * freed by element_result_release().
 */
#ifndef PORO_ELEMENT_H
#define PORO_ELEMENT_H

#include "case.h"
#include "error.h"
#include "material.h"

#define ELEMENT_SCHEMA_VERSION "poro-element/1"

enum element_test { ELEMENT_DRAINED, ELEMENT_UNDRAINED };

struct element_case {
	char title[CASE_TITLE_SIZE];      /* UTF-8, at most CASE_TITLE_MAX characters (case.h) */
	char warnings[CASE_WARNINGS_SIZE]; /* "" when none (case.h) */
	struct case_material material;    /* model and parameters (case_material.h keys) */
	enum element_test test;           /* "drained" | "undrained" */
	double confining_pressure;        /* cell pressure, Pa, >= 0 (compression positive) */
	double axial_strain;              /* final axial strain: eps_a (small, |eps_a| < 1) or ln(l / l0)
					     (finite, |ln(l / l0)| < ELEMENT_LOG_STRAIN_MAX); non-zero;
					     negative = compression */
	int steps;                        /* equal axial increments, 1 to ELEMENT_STEPS_MAX */
	unsigned metrics;                 /* figures asked for by "metrics" (case_metrics.h) */
};
#define ELEMENT_STEPS_MAX 1000000
#define ELEMENT_LOG_STRAIN_MAX 5.0

/* Loads and validates an element case; problems as "JSON-pointer: message" lines, PORO_EINVAL
 * (PORO_EIO for an unreadable file). */
enum poro_status element_case_load_file(const char *path, struct element_case *c, struct poro_error *err);
enum poro_status element_case_load_string(const char *json, struct element_case *c, struct poro_error *err);

/* 1 when the file is a JSON object whose "schema" is ELEMENT_SCHEMA_VERSION (so `poro-solve
 * validate` can tell an element case from a simulation case); 0 otherwise, errors included. */
int element_case_file_is_element(const char *path);

/* One row of the result: the state after a step (row 0: the initial state). */
struct element_row {
	double axial_strain;              /* as the case's axial_strain */
	double p;                         /* mean effective stress, Pa, compression positive */
	double q;                         /* deviator sigma'_lateral - sigma'_axial (tension positive
					     stresses), Pa: positive in triaxial compression */
	double volumetric_strain;         /* ln J (finite) or tr eps (small), negative = contraction */
	double stress[4];                 /* effective Cauchy stress (xx, yy, xy, zz), Pa */
	double J;                         /* volume ratio */
	double outputs[MATERIAL_OUTPUTS_MAX]; /* material_state_outputs() */
};

struct element_result {
	int rows;                         /* steps + 1 */
	long newton_iterations;           /* drained: Newton iterations over all steps (0 undrained) */
	struct element_row *row;
	int output_count;
	const char *output_names[MATERIAL_OUTPUTS_MAX];
};

/* Runs the test. PORO_ESOLVER when the model fails or the drained iteration does not converge. */
enum poro_status element_run(const struct element_case *c, struct element_result *r, struct poro_error *err);
void element_result_release(struct element_result *r);

/* Writes DIR/element.csv (header axial_strain,p,q,volumetric_strain then the model's outputs),
 * creating DIR if needed (element_output.c); `poro-plot DIR/element.csv` draws it. */
enum poro_status element_write(const struct element_case *c, const struct element_result *r, const char *dir,
			       struct poro_error *err);

#endif
