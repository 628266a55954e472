/*
 * analytic.h - the closed forms PoroMPM is checked against, in one place: the verification tests
 * compare with them, and the solver's figures (figures.h: the metrics a run reports for the
 * benchmark nightlies) are computed from them.
 *
 * Terzaghi (000 Eqs. 84-86, with the known extraction slip of Eq. 84 corrected: the exponential
 * multiplies each term of the series): excess pore pressure at depth z below the drained face,
 * drainage length H, time factor Tv = c_v t / H^2 with c_v = k / (rho_w g m_v).
 *
 * Xie and Leo (2004) large-strain consolidation (000 Eqs. 87-90, 002 Eqs. 35-37): settlement
 * S = H (1 - exp(-m_v q)) U(Tv) and pore pressure p = ln[1 + (exp(m_v q) - 1) sum] / m_v with the
 * same series as Terzaghi. 000 writes the series with 4 M^2 Tv and sin(2 M z / H), which is the
 * same solution with H the thickness of a layer drained on both faces; for the singly drained
 * column used here the drainage length is the column height and the series is the one below
 * (002 Eq. 36 writes it this way). The solution is exact for (1 + e) = (1 + e0) exp(-m_v sigma')
 * and a conductivity k = k0 ((1 + e)/(1 + e0))^2 (tests/solver/permeability_test.c).
 */
#ifndef PORO_ANALYTIC_H
#define PORO_ANALYTIC_H

#include <math.h>

#define ANALYTIC_TERMS 400
#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* sum_m (2/M) sin(M z/H) exp(-M^2 Tv), M = (m + 1/2) pi: the normalised excess pore pressure. */
static inline double consolidation_series(double z, double H, double Tv)
{
	double sum = 0.0;
	for (int m = 0; m < ANALYTIC_TERMS; m++) {
		double M = (m + 0.5) * M_PI;
		sum += 2.0 / M * sin(M * z / H) * exp(-M * M * Tv);
	}
	return sum;
}

/* Terzaghi excess pore pressure, Pa, for load q at depth z below the drained face. */
static inline double terzaghi_pressure(double z, double H, double Tv, double q)
{
	if (z <= 0.0)
		return 0.0;
	return q * consolidation_series(z, H, Tv);
}

/* Average degree of consolidation U(Tv) = 1 - sum 2/M^2 exp(-M^2 Tv). */
static inline double consolidation_degree(double Tv)
{
	double sum = 0.0;
	for (int m = 0; m < ANALYTIC_TERMS; m++) {
		double M = (m + 0.5) * M_PI;
		sum += 2.0 / (M * M) * exp(-M * M * Tv);
	}
	return 1.0 - sum;
}

/* Terzaghi settlement, m, of the soil at reference height y0 of a column of height H on its base
 * (load q, compressibility m_v): u(y0) = m_v int_0^y0 (q - p) dy, with p the series above at depth
 * z = H - y (drained at the top, drainage length H) or z = min(H - y, y) (drained at both ends,
 * drainage length H/2). Each term integrates in closed form, since cos M = 0:
 *     top only:  int_0^y0 sin(M (H - y) / H) dy = (H / M) cos(M (H - y0) / H),
 *     both ends: the same with H/2, plus (H/2) / M for the lower half (y0 >= H/2).
 * At y0 = H it is m_v q H U(Tv). */
static inline double terzaghi_settlement(double y0, double H, double Tv, double q, double mv, int drained_both)
{
	double Hd = drained_both ? H / 2 : H, integral = 0.0;
	for (int m = 0; m < ANALYTIC_TERMS; m++) {
		double M = (m + 0.5) * M_PI, part;
		if (!drained_both)
			part = cos(M * (H - y0) / H);
		else if (y0 >= Hd)
			part = 1.0 + cos(M * (H - y0) / Hd);
		else
			part = 1.0 - cos(M * y0 / Hd);
		integral += 2.0 / M * exp(-M * M * Tv) * Hd / M * part;
	}
	return mv * q * (y0 - integral);
}

/* Tv at which the degree of consolidation is U, 0 < U < 1 (bisection on the monotone U(Tv)). */
static inline double time_factor_for_degree(double U)
{
	double lo = 1e-6, hi = 10;
	for (int i = 0; i < 200; i++) {
		double mid = 0.5 * (lo + hi);
		if (consolidation_degree(mid) < U)
			lo = mid;
		else
			hi = mid;
	}
	return 0.5 * (lo + hi);
}

/* Xie-Leo settlement (000 Eq. 87 in the single-drainage normalisation), m. */
static inline double xie_leo_settlement(double H, double mv, double q, double Tv)
{
	return H * (1.0 - exp(-mv * q)) * consolidation_degree(Tv);
}

/* Xie-Leo pore pressure at material depth z below the drained top (000 Eq. 90), Pa. */
static inline double xie_leo_pressure(double z, double H, double mv, double q, double Tv)
{
	if (z <= 0.0)
		return 0.0;
	return log(1.0 + (exp(mv * q) - 1.0) * consolidation_series(z, H, Tv)) / mv;
}

/* Time factor Tv = k t / (rho_w g m_v H^2), 000 Eq. 85. */
static inline double time_factor(double k, double t, double rho_w, double g, double mv, double H)
{
	return k * t / (rho_w * g * mv * H * H);
}

/* Time for a given Tv. */
static inline double time_for_factor(double k, double Tv, double rho_w, double g, double mv, double H)
{
	return Tv * rho_w * g * mv * H * H / k;
}

/* Mandel's problem (Mandel 1953; the series as written by Cheng and Detournay 1988, Eq. 27, and
 * Abousleiman et al. 1996, Eq. 23): a layer -a < x < a, plane strain, squeezed between rigid
 * smooth impermeable plates by a total force 2F (per metre of thickness; F on each half, a mean
 * vertical stress F / a), its sides x = +-a drained and free of stress. The excess pore pressure is
 *     p(x, t) = 2 p0 sum_n sin(alpha_n) / (alpha_n - sin(alpha_n) cos(alpha_n))
 *                          (cos(alpha_n x / a) - cos(alpha_n)) exp(-alpha_n^2 c t / a^2),
 * with alpha_n the positive roots of tan(alpha) = alpha (1 - nu) / (nu_u - nu), p0 the pressure
 * the load raises at once, p0 = B (1 + nu_u) F / (3 a) (half the mean vertical stress for
 * B = 1, nu_u = 1/2), and c the consolidation coefficient
 *     c = 2 kappa B^2 G (1 - nu) (1 + nu_u)^2 / (9 (1 - nu_u) (nu_u - nu)),   kappa = k / (rho_w g).
 * With incompressible grains and water (as in the semi-implicit scheme) B = 1 and nu_u = 1/2,
 * tan(alpha) = 2 (1 - nu) alpha / (1 - 2 nu) and c = kappa 2 G (1 - nu) / (1 - 2 nu), which is
 * Terzaghi's c_v = k / (rho_w g m_v) with m_v of 000 Eq. 86: a Tv = c t / a^2 here is the same
 * time factor as Terzaghi's with a in place of H. The derivation from the 1-D equations
 * (uniform vertical strain under the plate, sigma_xx = 0, Darcy flow to the sides) and the checks
 * against a finite-difference solution of the same equations are in tests/verify/mandel_test.c. */
#define MANDEL_ROOTS 200

/* The first count roots of tan(alpha) = r alpha, r = (1 - nu) / (nu_u - nu) > 1: the n-th
 * (n = 0, 1, ...) lies in (n pi, n pi + pi / 2), where tan(alpha) - r alpha rises from below 0
 * (n = 0: from 0 with slope 1 - r < 0) to +infinity; found by bisection. */
static inline void mandel_roots(double r, double *alpha, int count)
{
	for (int n = 0; n < count; n++) {
		double lo = n * M_PI + (n == 0 ? 1e-9 : 0.0), hi = n * M_PI + 0.5 * M_PI - 1e-15 * (n + 1);
		for (int i = 0; i < 200; i++) {
			double mid = 0.5 * (lo + hi);
			if (tan(mid) - r * mid < 0.0)
				lo = mid;
			else
				hi = mid;
		}
		alpha[n] = 0.5 * (lo + hi);
	}
}

/* p(x, Tv) / p0 for 0 <= x <= a (Tv = c t / a^2 > 0), Poisson ratios nu (drained) and nu_u
 * (undrained), nu < nu_u. */
static inline double mandel_pressure_ratio(double x, double a, double Tv, double nu, double nu_u)
{
	double alpha[MANDEL_ROOTS], sum = 0.0;
	mandel_roots((1.0 - nu) / (nu_u - nu), alpha, MANDEL_ROOTS);
	for (int n = 0; n < MANDEL_ROOTS; n++) {
		double al = alpha[n], s = sin(al), co = cos(al);
		sum += s / (al - s * co) * (cos(al * x / a) - co) * exp(-al * al * Tv);
	}
	return 2.0 * sum;
}

/* The same for a force that rises linearly from 0 to F over Tv_ramp, then stays (a "ramp" time
 * function): by superposition (Duhamel) the step response averaged over the ramp,
 * p(Tv) = (1 / Tv_ramp) int_0^min(Tv, Tv_ramp) p_step(Tv - tau) dtau, each term of the series
 * integrated in closed form. p0 is the final load's. Tv_ramp = 0 is the step load. */
static inline double mandel_pressure_ratio_ramped(double x, double a, double Tv, double Tv_ramp, double nu,
						  double nu_u)
{
	if (!(Tv_ramp > 0.0))
		return mandel_pressure_ratio(x, a, Tv, nu, nu_u);
	double alpha[MANDEL_ROOTS], sum = 0.0;
	mandel_roots((1.0 - nu) / (nu_u - nu), alpha, MANDEL_ROOTS);
	for (int n = 0; n < MANDEL_ROOTS; n++) {
		double al = alpha[n], s = sin(al), co = cos(al), a2 = al * al;
		/* int over the ramp of exp(-a2 (Tv - tau)) dtau, tau in [0, min(Tv, Tv_ramp)] */
		double in_time = Tv <= Tv_ramp ? (1.0 - exp(-a2 * Tv)) / a2
					       : (exp(-a2 * (Tv - Tv_ramp)) - exp(-a2 * Tv)) / a2;
		sum += s / (al - s * co) * (cos(al * x / a) - co) * in_time;
	}
	return 2.0 * sum / Tv_ramp;
}

/* The pressure the load raises at once, p0 = B (1 + nu_u) F / (3 a), for a force F per metre on
 * the half width a (Pa). */
static inline double mandel_initial_pressure(double F, double a, double B, double nu_u)
{
	return B * (1.0 + nu_u) * F / (3.0 * a);
}

/* Mohr-Coulomb in drained triaxial compression at cell pressure pc (Pa, compression positive):
 * the deviator at failure, q = (2 pc sin(phi) + 2 c cos(phi) / J) / (1 - sin(phi)) (sigma_1 =
 * sigma_3 (1 + sin) / (1 - sin) + 2 c cos / (1 - sin), minus sigma_3), phi in radians, c in Pa;
 * J the volume ratio at finite strain (the Kirchhoff cohesion seen as a Cauchy stress), 1 at
 * small strain. tests/solver/element_test.c checks the driver against it. */
static inline double mohr_coulomb_drained_peak_q(double pc, double c, double phi, double J)
{
	double s = sin(phi);
	return (2.0 * pc * s + 2.0 * c * cos(phi) / J) / (1.0 - s);
}

#endif
