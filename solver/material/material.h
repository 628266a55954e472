/*
 * material.h - the one constitutive interface every scheme calls (DESIGN §2.2).
 *
 * A model has one file (material_<model>.c) with an init_state and an update. The update receives
 * the deformation-gradient increment dF of the step (plane strain: dF_zz = 1; the single-element
 * driver also stretches z) and the total Jacobian J = V / V0 after the step, and returns the
 * effective Cauchy stress sigma' (tension positive) with the updated internal state and, when
 * asked, the consistent tangent. Finite-strain models work with the elastic left Cauchy-Green
 * tensor Be and Kirchhoff stress tau = J sigma' (000 Eqs. 69-76); small-strain models use the
 * symmetric part of dF - I as the strain increment.
 *
 * Models: linear_elastic (small strain), hencky (finite strain), the Mohr-Coulomb family
 * (mohr_coulomb, tresca_softening, mohr_coulomb_dilation; finite or small strain by the case's
 * "strain" key), which share the principal-space return mapping of principal_return.h, and
 * nor_sand (material_nor_sand.c; finite or small strain), whose stress is nonlinear in the elastic
 * strain: at small strain its Be holds exp(2 eps^e) rather than I.
 *
 * J and the specific volume: nor_sand's specific volume is v = J v0 with the J given here (000 Eq.
 * 95), or v = J_v v0 when the scheme passes the node-wise averaged Jacobian of Eq. 97 in J_v (Eq.
 * 96). J alone divides tau to give sigma: it is the point's volume ratio, the one its forces use.
 *
 * Internal variables live in the point's state array (STATE_MAX doubles, zero at the start unless
 * init_state says otherwise); a model documents its slots in its file and names the ones worth
 * writing out through material_state_outputs(). A model with its own nonlinear return (nor_sand)
 * has an enum value, a file with its update, and a case in the dispatch of material.c.
 *
 * Consistent tangent (for implicit schemes and the drained element driver). Layout: a 4x4
 * row-major matrix over the components (xx, yy, xy, zz) of stress and strain, with TENSOR shear:
 * the xy column is the response to a change of eps_xy = eps_yx (both off-diagonal entries), so the
 * elastic xy diagonal entry is 2 mu, not mu.
 *   small strain:  d sigma / d eps, eps the total small strain of the step (dF - I, symmetrised).
 *   finite strain: d tau / d eps_trial, with eps_trial = 1/2 ln Be_trial the elastic trial
 *                  logarithmic strain (Be_trial = dF Be^t dF^T, Eq. 70), so
 *                  d tau / d ln(Be_trial) is half of it. The spatial tangent of an implicit
 *                  scheme follows as (de Souza Neto, Peric and Owen, Ch. 14)
 *                      a_ijkl = 1/(2J) [T : L : B]_ijkl - sigma_il delta_jk,
 *                  with T this tangent (as a fourth-order tensor), L = d ln(Be_trial) / d Be_trial
 *                  (spectral formula from the eigen-decomposition of Be_trial) and
 *                  B_ijkl = delta_ik Be_trial_jl + delta_jk Be_trial_il.
 */
#ifndef PORO_MATERIAL_H
#define PORO_MATERIAL_H

#include "case.h"
#include "error.h"
#include "particles.h"

struct material {
	enum material_model model;
	enum material_strain strain;   /* plastic models: finite or small; elastic models: fixed by model */
	double density;          /* rho_s, kg/m^3 */
	double E, nu;            /* Young's modulus (Pa) and Poisson's ratio */
	double lambda, mu;       /* Lame constants, Pa */
	double bulk;             /* K = lambda + 2 mu / 3, Pa */
	double constrained;      /* 1 / m_v = lambda + 2 mu (000 Eq. 86), Pa */
	/* Plastic models, after the strength reduction of 000 Eq. 91 (c / SRF, tan phi / SRF; the
	 * dilation angle is kept but never exceeds the reduced friction angle). */
	double srf;              /* strength reduction factor SRF */
	double cohesion;         /* c, Pa (tresca_softening: peak c_p) */
	double residual_cohesion;/* tresca_softening: c_r, Pa */
	double residual_plastic_strain; /* tresca_softening: eps_p^r, deviatoric plastic strain at c_r */
	double phi, psi;         /* friction and dilation angle, rad (mohr_coulomb_dilation: psi unused) */
	double sin_phi, cos_phi, sin_psi; /* of phi and psi */
	double psi_ini, psi_crit;/* mohr_coulomb_dilation: initial and critical dilation angle, rad */
	double eta;              /* mohr_coulomb_dilation: decay of 001 Eq. 17 */
	struct nor_sand_parameters { /* nor_sand (material_nor_sand.c; mu above is G) */
		double kappa, lambda;    /* swelling and compression index */
		double v_c0, p_ref;      /* critical state line v_c = v_c0 - lambda ln(p / p_ref); p_ref Pa */
		double M, N, N_bar, h, alpha;
		double v0, ocr, p_start; /* initial specific volume, OCR, p0 of a stress-free point (Pa) */
		int through_stress;      /* initial surface through the stress, not only Eq. 113 (case.h) */
		double cutoff_start, cutoff_end;   /* 000 Eq. 92 */
		double gas_ratio;        /* v_crit / v0, 000 Eq. 93 */
	} ns;
};

/* One point's stress update. Arrays belong to the particle set. */
struct stress_update {
	const double *dF;        /* [4] row-major (xx, xy, yx, yy) */
	double dF_zz;            /* out-of-plane stretch increment; 0 (what an initializer that does not
				    name it leaves) means plane strain, dF_zz = 1 */
	double J;                /* total Jacobian V/V0 after the step */
	double J_v;              /* the Jacobian of nor_sand's specific volume v = J_v v0 (000 Eq. 96: the
				    node-wise average of Eq. 97); 0 (what an initializer that does not
				    name it leaves) means J (Eq. 95) */
	double *stress;          /* [4] in: sigma'^t, out: sigma'^{t+1} (xx, yy, xy, zz), Pa */
	double *Be;              /* [4] elastic left Cauchy-Green (xx, yy, xy, zz) */
	double *state;           /* [STATE_MAX] internal variables */
	double *plastic_strain;  /* [1] accumulated plastic strain (plastic models: the deviatoric
				    plastic strain, principal_return.h) */
	double *tangent;         /* [16] out: consistent tangent (layout above), Pa; NULL when not wanted */
	int elastic_only;        /* 1: plastic models accept the elastic trial state (the elastic
				    gravity loading of 000 App. B.4); 0 for a normal update */
};

void material_init(struct material *m, const struct case_material *spec);

/* Sets the internal state for a point whose initial effective stress is `stress` (zero for a
 * stress-free start): Be consistent with it for finite-strain models. */
void material_init_state(const struct material *m, const double *stress, double *Be, double *state);

/* Updates one point. Returns PORO_OK, or PORO_ESOLVER if the update has no valid result (for
 * example a non-positive stretch, or a return mapping that does not converge); err gets the
 * reason. On failure the point's arrays may hold partial results. */
enum poro_status material_update(const struct material *m, struct stress_update *u, struct poro_error *err);

/* 1 for finite-strain kinematics (hencky, plastic models with strain "finite"). */
int material_is_finite_strain(const struct material *m);

/* Named quantities derived from a point's state for output (the element driver's CSV columns):
 * writes up to MATERIAL_OUTPUTS_MAX names and values, returns how many. names may be NULL. */
#define MATERIAL_OUTPUTS_MAX 4
int material_state_outputs(const struct material *m, const double *state, const char **names, double *values);

/* Per-model entry points (one file each). */
void linear_elastic_update(const struct material *m, struct stress_update *u);
enum poro_status hencky_update(const struct material *m, struct stress_update *u, struct poro_error *err);
void hencky_init_state(const struct material *m, const double *stress, double *Be);
enum poro_status mohr_coulomb_update(const struct material *m, struct stress_update *u, struct poro_error *err);
enum poro_status tresca_softening_update(const struct material *m, struct stress_update *u,
					 struct poro_error *err);
enum poro_status mohr_coulomb_dilation_update(const struct material *m, struct stress_update *u,
					      struct poro_error *err);
/* State slots of nor_sand (slot 0 is the deviatoric plastic strain, as for the Mohr-Coulomb family). */
enum nor_sand_slot {
	NOR_SAND_DEVIATORIC_PLASTIC_STRAIN = 0, /* E_d^p = sum of plastic multipliers (d eps_s^p) */
	NOR_SAND_IMAGE_PRESSURE,         /* pi_i, Pa, compression positive */
	NOR_SAND_INITIAL_SPECIFIC_VOLUME,/* v0 of the point: v = J v0 */
	NOR_SAND_REFERENCE_PRESSURE,     /* p0, Pa, compression positive */
	NOR_SAND_REFERENCE_STRAIN,       /* eps_v0^e, elastic volumetric strain at p0 (tension positive) */
	NOR_SAND_CUTOFF_STATE,           /* psi_i when E_d^p last stood at or below the cut-off start */
	NOR_SAND_SPECIFIC_VOLUME,        /* v after the last update */
	NOR_SAND_STATE_PARAMETER,        /* psi = v - v_c(p) after the last update */
};
enum poro_status nor_sand_update(const struct material *m, struct stress_update *u, struct poro_error *err);
void nor_sand_init_state(const struct material *m, const double *stress, double *Be, double *state);
int nor_sand_state_outputs(const struct material *m, const double *state, const char **names, double *values);

/* 000 App. B.4, the end of the elastic gravity loading: takes the point's present elastic state as
 * the Nor-Sand reference, p0 = the Kirchhoff mean pressure J p (Eq. 111) and eps_v0^e = tr eps^e =
 * 1/2 ln det Be (Eq. 112), and sets the image pressure from the overconsolidation ratio (Eq. 113),
 * or with initial_yield_surface "through_stress" at least the one whose surface passes through the
 * present stress; the deviatoric plastic strain restarts at 0. The specific volume keeps v = J v0 with J counted
 * from the start, which is Eq. 114. Does nothing for other models. */
void material_reset_reference(const struct material *m, const double *stress, const double *Be, double J,
			      double *state);

/* Isotropic elastic tangent lambda 1 x 1 + 2 mu I in the layout above (tensor shear). */
void material_elastic_tangent(const struct material *m, double *tangent);

/* Eigen-decomposition of a symmetric 2x2 tensor (xx, yy, xy): eigenvalues l[2] and the rotation
 * angle theta of the first eigenvector from the x axis. Closed form, used by finite-strain models. */
void sym2_eigen(double xx, double yy, double xy, double l[2], double *theta);

#endif
