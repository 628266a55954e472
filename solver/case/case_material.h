/*
 * case_material.h - private to the case loaders: reads the constitutive part of a material object.
 *
 * The simulation case (case_load.c, a named material in "materials") and the single-element case
 * (element_case.c, one anonymous "material") describe a soil model with the same keys, read here
 * once: "model" and the parameters of that model, with the same checks and the same
 * "JSON-pointer: message" problems (case_json.h).
 */
#ifndef PORO_CASE_MATERIAL_H
#define PORO_CASE_MATERIAL_H

#include "case.h"
#include "case_json.h"

/* Reads "model" and its parameters from the object o at pointer p into m, and records an
 * "unknown key" problem for every key that is neither a parameter of the model nor in
 * extra_keys (the caller's own keys, NULL-terminated). Defaults (strain "finite",
 * strength_reduction_factor 1) are stored first. */
void case_read_material_model(struct case_reader *r, const json_t *o, const char *p,
			      const char *const *extra_keys, struct case_material *m);

#endif
