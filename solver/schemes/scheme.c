/*
 * scheme.c - the table of schemes (scheme.h), one entry per formulation.scheme.
 */
#include "scheme.h"

const struct scheme *scheme_of(enum case_scheme kind)
{
	switch (kind) {
	case SCHEME_EXPLICIT:
		return &explicit_scheme;
	case SCHEME_IMPLICIT_UPU:
		return &implicit_upU_scheme;
	case SCHEME_SEMI_IMPLICIT:
		break;
	}
	return &semi_implicit_scheme;
}
