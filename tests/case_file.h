/*
 * case_file.h - loading a shipped case in a test: the case, or NULL after an INFO line naming the
 * file and every problem (the test's checks then fail on the NULL).
 */
#ifndef PORO_TEST_CASE_FILE_H
#define PORO_TEST_CASE_FILE_H

#include <stdio.h>

#include "case.h"

static inline struct case_spec *test_case_load(const char *file)
{
	struct case_spec *c = NULL;
	struct poro_error err = {0};
	if (case_load_file(file, &c, &err))
		printf("INFO cannot load %s: %s\n", file, err.message);
	return c;
}

#endif
