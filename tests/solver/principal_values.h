/*
 * principal_values.h - the principal values of a plane-strain tensor for the constitutive tests
 * (objectivity checks compare them before and after a rigid rotation).
 */
#ifndef PORO_TEST_PRINCIPAL_VALUES_H
#define PORO_TEST_PRINCIPAL_VALUES_H

#include "material.h"

/* Principal values of a (xx, yy, xy, zz) tensor, sorted descending. */
static inline void sorted_principal(const double t[4], double s[3])
{
	double l[2], th;
	sym2_eigen(t[0], t[1], t[2], l, &th);
	s[0] = l[0], s[1] = l[1], s[2] = t[3];
	for (int a = 0; a < 3; a++)
		for (int b = a + 1; b < 3; b++)
			if (s[b] > s[a]) {
				double x = s[a];
				s[a] = s[b];
				s[b] = x;
			}
}

#endif
