/*
 * json_text.h - writing small JSON documents as text (the probes document of `poro-solve probes`,
 * a run's metrics.json), without building a tree: strings escaped, numbers in the fewest of 15,
 * 16 or 17 significant digits that read back to the same double, null for a number that is not
 * finite (JSON has no NaN).
 */
#ifndef PORO_JSON_TEXT_H
#define PORO_JSON_TEXT_H

#include <stdio.h>

/* text as a JSON string. With ascii_only, bytes >= 0x7f are written as '?' (text that came from a
 * file that may be damaged: the document stays valid UTF-8 whatever it holds); otherwise text
 * must be valid UTF-8 (what jansson read). */
void json_text_string(FILE *f, const char *text, int ascii_only);
void json_text_number(FILE *f, double x);
/* [x0,x1,...] */
void json_text_numbers(FILE *f, const double *x, long n);

#endif
