/*
 * json_get.c - tolerant JSON member readers, see json_get.h.
 */
#include "json_get.h"

long long json_get_int(const json_t *obj, const char *key, long long def)
{
	json_t *v = obj ? json_object_get(obj, key) : NULL;
	if (json_is_integer(v))
		return (long long)json_integer_value(v);
	if (json_is_real(v))
		return (long long)json_real_value(v);
	return def;
}

double json_get_real(const json_t *obj, const char *key, double def)
{
	json_t *v = obj ? json_object_get(obj, key) : NULL;
	return json_is_number(v) ? json_number_value(v) : def;
}

const char *json_get_str(const json_t *obj, const char *key, const char *def)
{
	json_t *v = obj ? json_object_get(obj, key) : NULL;
	return json_is_string(v) ? json_string_value(v) : def;
}

int json_get_bool(const json_t *obj, const char *key, int def)
{
	json_t *v = obj ? json_object_get(obj, key) : NULL;
	if (json_is_boolean(v))
		return json_is_true(v);
	if (json_is_number(v))
		return json_number_value(v) != 0;
	return def;
}
