/* error.c - status table lookups and the error record (see error.h). */
#include "error.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

enum poro_status poro_error_record(struct poro_error *err, enum poro_status code, const char *file,
				   int line, const char *fmt, ...)
{
	if (!err)
		return code;
	err->code = code;
	err->file = file;
	err->line = line;
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(err->message, sizeof err->message, fmt, ap);
	va_end(ap);
	return code;
}

void poro_error_append(struct poro_error *err, const char *fmt, ...)
{
	if (!err)
		return;
	size_t used = strlen(err->message);
	if (used + 2 >= sizeof err->message)
		return;
	if (used)
		err->message[used++] = '\n';
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(err->message + used, sizeof err->message - used, fmt, ap);
	va_end(ap);
}

const char *poro_status_name(enum poro_status code)
{
	switch (code) {
#define PORO_STATUS_NAME(c, exit_code, meaning) case c: return #c;
		PORO_STATUS_MAP(PORO_STATUS_NAME)
#undef PORO_STATUS_NAME
	}
	return "PORO_UNKNOWN";
}

const char *poro_status_meaning(enum poro_status code)
{
	switch (code) {
#define PORO_STATUS_MEANING(c, exit_code, meaning) case c: return meaning;
		PORO_STATUS_MAP(PORO_STATUS_MEANING)
#undef PORO_STATUS_MEANING
	}
	return "unknown error";
}

int poro_status_exit_code(enum poro_status code)
{
	switch (code) {
#define PORO_STATUS_EXIT(c, exit_code, meaning) case c: return exit_code;
		PORO_STATUS_MAP(PORO_STATUS_EXIT)
#undef PORO_STATUS_EXIT
	}
	return 1;
}
