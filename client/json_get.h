/*
 * json_get.h - tolerant readers for JSON answers from the server: a missing member or one of
 * another type yields the given default, so callers check only what they rely on.
 */
#ifndef PORO_JSON_GET_H
#define PORO_JSON_GET_H

#include <jansson.h>

/* obj[key] as an integer (a real is truncated), or def. obj may be NULL. */
long long json_get_int(const json_t *obj, const char *key, long long def);
/* obj[key] as a number, or def. */
double json_get_real(const json_t *obj, const char *key, double def);
/* obj[key] as a string (owned by obj), or def. */
const char *json_get_str(const json_t *obj, const char *key, const char *def);
/* obj[key] as a boolean (true/false, non-zero number), or def. */
int json_get_bool(const json_t *obj, const char *key, int def);

#endif
