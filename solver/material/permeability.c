/*
 * permeability.c - the conductivity laws of permeability.h (000 step 8g; Xie and Leo 2004).
 */
#include "permeability.h"

double permeability_conductivity(enum permeability_law law, double k0, double n0, double n, double J)
{
	switch (law) {
	case PERMEABILITY_KOZENY_CARMAN: {
		double C1 = k0 * (1.0 - n0) * (1.0 - n0) / (n0 * n0 * n0);
		return C1 * n * n * n / ((1.0 - n) * (1.0 - n));
	}
	case PERMEABILITY_VOLUME_RATIO:
		return k0 * J;
	case PERMEABILITY_VOLUME_RATIO_SQUARED:
		return k0 * J * J;
	case PERMEABILITY_CONSTANT:
		break;
	}
	return k0;
}
