/*
 * case_formulation.h - private to the case loader: reads "formulation" (the scheme and its
 * options) and checks what the chosen scheme asks of the rest of the case.
 *
 * Each scheme has options of its own (schemas/case.schema.json names the scheme of each key). A
 * key written for another scheme than the case's is refused rather than ignored, since a user
 * who writes it expects it to act.
 */
#ifndef PORO_CASE_FORMULATION_H
#define PORO_CASE_FORMULATION_H

#include "case.h"
#include "case_json.h"

/* Every formulation default (docs/case-spec.md), stored before the case is read. */
void case_formulation_defaults(struct case_formulation *f);

/* Reads root's required "formulation" object into f. */
void case_read_formulation(struct case_reader *r, const json_t *root, struct case_formulation *f);

/* After fluid, gravity and boundaries are read: what the scheme cannot take there (the explicit
 * scheme has no rigid plate, no cavitation model, no attached water during the gravity ramp, and
 * drains a face exactly where its water moves freely: a "drained" face must let its water move). */
void case_check_scheme(struct case_reader *r, const struct case_spec *c);

#endif
