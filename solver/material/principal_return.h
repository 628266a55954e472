/*
 * principal_return.h - the return mapping of the Mohr-Coulomb family in principal stress space,
 * shared by material_mohr_coulomb.c, material_tresca_softening.c and
 * material_mohr_coulomb_dilation.c (private to the solver's material files).
 *
 * After de Souza Neto, Peric and Owen, Computational Methods for Plasticity (2008), §8.2.2,
 * Boxes 8.4-8.5: with the principal stresses sorted s1 >= s2 >= s3 (tension positive), the yield
 * function of the sextant is
 *     Phi = (s1 - s3) + (s1 + s3) sin(phi) - 2 c cos(phi)
 * and the plastic potential the same with the dilation angle psi (non-associated flow). A trial
 * state outside is returned to the main plane, else to one of the two edges (s1 = s2, the edge of
 * triaxial compression; s2 = s3, triaxial extension), else to the apex, each tried in that order
 * and accepted when the returned stresses keep their order (Box 8.5). Tresca is phi = psi = 0.
 *
 * Hardening: the cohesion c and the dilation angle psi may depend on one internal variable, the
 * accumulated deviatoric plastic strain eps_d (001 §4.2: softening of c, Eq. 17 for psi),
 * integrated by backward Euler as
 *     eps_d^{n+1} = eps_d^n + sqrt(2/3) |dev(d eps^p)|,  d eps^p = sum_k dgamma_k N_k(psi^{n+1}),
 * so that in triaxial compression eps_d is the usual (2/3)(eps_a - eps_r) of the plastic strains.
 * With hardening the return solves its plastic multipliers and eps_d together by Newton's method
 * (RETURN_TOLERANCE, RETURN_ITERATIONS_MAX in principal_return.c); without, the first (linear)
 * solve is exact. At the apex the whole deviatoric trial strain is plastic, so eps_d^{n+1} is
 * explicit and s = c(eps_d^{n+1}) cot(phi).
 *
 * The same code serves small strain (stresses sigma, elastic strains eps^e) and finite strain
 * (Kirchhoff stresses tau, elastic logarithmic strains 1/2 ln Be, 000 Eqs. 72-75): principal
 * stresses and principal elastic strains are related by the isotropic elastic law
 * s = lambda tr(e) 1 + 2 mu e.
 */
#ifndef PORO_PRINCIPAL_RETURN_H
#define PORO_PRINCIPAL_RETURN_H

#include "material.h"

/* State slots of the Mohr-Coulomb family. */
enum { STATE_DEVIATORIC_PLASTIC_STRAIN = 0 };

/* Cohesion and dilation of a model at a deviatoric plastic strain, with their derivatives. */
struct plastic_law {
	double c, dc;            /* cohesion, Pa, and d c / d eps_d */
	double sin_psi, dsin_psi;/* sin(psi) and d sin(psi) / d eps_d */
};
typedef void (*plastic_law_fn)(const struct material *m, double eps_d, struct plastic_law *law);

/* The laws of the three models (their files). */
void mohr_coulomb_law(const struct material *m, double eps_d, struct plastic_law *law);
void tresca_softening_law(const struct material *m, double eps_d, struct plastic_law *law);
void mohr_coulomb_dilation_law(const struct material *m, double eps_d, struct plastic_law *law);

enum principal_regime { RETURN_ELASTIC, RETURN_PLANE, RETURN_EDGE_12, RETURN_EDGE_23, RETURN_APEX };

struct principal_return {
	double s[3];             /* in: trial principal stresses, sorted s[0] >= s[1] >= s[2], Pa;
				    out: the returned ones (same order) */
	double eps_d;            /* in: eps_d^n; out: eps_d^{n+1} */
	double D[3][3];          /* out when asked: d s / d e_trial, e_trial the principal trial
				    elastic strains in the same order, Pa */
	enum principal_regime regime;   /* out: which return was taken */
	int iterations;          /* out: Newton iterations after the first solve */
	int elastic_only;        /* in: 1 accepts the trial state as it is (RETURN_ELASTIC, elastic D) */
};

/* Returns the trial state pr->s of the material m with hardening law `law` onto its yield
 * surface (or leaves it, if it is inside: RETURN_ELASTIC), and fills pr->D when want_tangent.
 * PORO_ESOLVER when the Newton iteration does not converge or no return is valid (err says why). */
enum poro_status principal_return_map(const struct material *m, plastic_law_fn law, struct principal_return *pr,
				      int want_tangent, struct poro_error *err);

/* Yield function Phi of the sorted principal stresses s with cohesion c (value in Pa). */
double principal_yield(const struct material *m, const double s[3], double c);

/* The stress update of a Mohr-Coulomb-family model with law `law`, small or finite strain by
 * m->strain (principal_update.c): trial state, spectral decomposition (in-plane by sym2_eigen,
 * z out of plane), principal_return_map, rebuilt stress and Be, and the 4x4 tangent. */
enum poro_status principal_update(const struct material *m, plastic_law_fn law, struct stress_update *u,
				  struct poro_error *err);

/* ---- Spectral kinematics for models with their own return in principal elastic strains ----
 * (material_nor_sand.c). The model sees the three principal trial elastic strains in slot order
 * (the larger and the smaller in-plane value, then z; isotropic models need no sorting) and
 * returns principal stresses, principal elastic strains and, for the tangent, d s / d e_trial.
 *   finite: Be_trial = dF Be^t dF^T (Eq. 70), e = 1/2 ln of its eigenvalues (Eq. 74);
 *   small:  Be holds exp(2 eps^e) (so one array carries the elastic strain of both kinematics),
 *           eps^e_trial = 1/2 ln Be^t + sym(dF - I) and its eigen-decomposition. */
struct spectral_trial {
	double e[3];             /* principal trial elastic strains, slot order */
	double gap;              /* e[0] - e[1], computed without cancellation */
	double c, s;             /* cosine and sine of the first in-plane eigenvector's angle */
	double Be[4];            /* Be_trial (small strain: exp(2 eps^e_trial)) */
};

/* Fills t from the point's Be and dF. PORO_ESOLVER (err names `model`) for a non-positive stretch. */
enum poro_status spectral_trial(const struct stress_update *u, int finite, struct spectral_trial *t,
				const char *model, struct poro_error *err);

/* Writes the point's results: Be (Be_trial when elastic, else rebuilt from the principal elastic
 * strains e on the trial eigenvectors), the Cauchy stress from the principal stresses s (Kirchhoff
 * at finite strain, divided by u->J), and when u->tangent and Ds are given the 4x4 tangent of
 * material.h from Ds = d s / d e_trial (slot order). */
void spectral_finish(struct stress_update *u, int finite, const struct spectral_trial *t, const double s[3],
		     const double e[3], int elastic, const double Ds[3][3]);

#endif
