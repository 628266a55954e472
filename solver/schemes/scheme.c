/*
 * scheme.c - the table of schemes (scheme.h), one entry per formulation.scheme.
 */
#include "scheme.h"

#include "semi_implicit.h"

const struct scheme *scheme_of(enum case_scheme kind)
{
	switch (kind) {
	case SCHEME_SEMI_IMPLICIT:
		return &semi_implicit_scheme;
	}
	return &semi_implicit_scheme;
}
