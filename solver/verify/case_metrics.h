/*
 * case_metrics.h - the optional "metrics" object of a case: the figures (figures.h) it asks a run
 * to report beyond those every run reports, {"terzaghi_rms": true, "runout": true}. Read by the
 * case loader (case_load.c) and the element case loader (element_case.c) with the loader's own
 * typed reads (case_json.h), so a problem is one "JSON-pointer: message" line like any other:
 * an unknown figure is "/metrics/NAME: unknown key", one the case cannot yield
 * "/metrics/NAME: needs ..." (figure_check).
 */
#ifndef PORO_CASE_METRICS_H
#define PORO_CASE_METRICS_H

#include "case_json.h"

struct case_spec;
struct element_case;

/* Reads root's "metrics" (optional) into *bits, bit (1u << k) per figure k set to true. */
void case_read_metrics(struct case_reader *r, const json_t *root, unsigned *bits);

/* After the whole case is read: a problem for each figure asked for that the case cannot yield. */
void case_check_metrics(struct case_reader *r, const struct case_spec *c);
void case_check_element_metrics(struct case_reader *r, const struct element_case *c);

#endif
