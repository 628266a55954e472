/*
 * json_text.c - JSON as text, see json_text.h.
 */
#include "json_text.h"

#include <math.h>
#include <stdlib.h>

void json_text_string(FILE *f, const char *text, int ascii_only)
{
	fputc('"', f);
	for (const unsigned char *p = (const unsigned char *)text; *p; p++) {
		if (*p == '"' || *p == '\\')
			fprintf(f, "\\%c", *p);
		else if (*p < 0x20)
			fprintf(f, "\\u%04x", *p);
		else
			fputc(ascii_only && *p >= 0x7f ? '?' : *p, f);
	}
	fputc('"', f);
}

void json_text_number(FILE *f, double x)
{
	if (!isfinite(x)) {
		fputs("null", f);
		return;
	}
	char text[32];   /* the shortest of 15, 16, 17 digits that reads back to x */
	for (int digits = 15; digits <= 17; digits++) {
		snprintf(text, sizeof text, "%.*g", digits, x);
		if (strtod(text, NULL) == x)
			break;
	}
	fputs(text, f);
}

void json_text_numbers(FILE *f, const double *x, long n)
{
	fputc('[', f);
	for (long k = 0; k < n; k++) {
		if (k)
			fputc(',', f);
		json_text_number(f, x[k]);
	}
	fputc(']', f);
}
