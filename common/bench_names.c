/*
 * bench_names.c - names of the benchmark nightlies, see bench_names.h.
 */
#include "bench_names.h"

#include <string.h>

static int alnum(char c)
{
	return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9');
}

/* 1 when s is 1..max characters, each alphanumeric or in extra. */
static int made_of(const char *s, size_t max, const char *extra)
{
	size_t n = s ? strlen(s) : 0;
	int ok = n >= 1 && n <= max;
	for (size_t i = 0; ok && i < n; i++)
		ok = alnum(s[i]) || strchr(extra, s[i]);
	return ok;
}

int bench_name_valid(const char *name)
{
	return made_of(name, BENCH_NAME_MAX, "_.-") && name[0] != '.';
}

int bench_label_valid(const char *label)
{
	return made_of(label, BENCH_LABEL_MAX, "._:-");
}

const char *bench_unknown_key(const json_t *obj, const char *const *allowed)
{
	const char *key;
	json_t *v;
	json_object_foreach((json_t *)obj, key, v) {
		int ok = 0;
		for (const char *const *a = allowed; *a && !ok; a++)
			ok = !strcmp(*a, key);
		if (!ok)
			return key;
	}
	return NULL;
}
