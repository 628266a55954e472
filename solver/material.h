/*
 * material.h - the one constitutive interface every scheme calls (DESIGN §2.2).
 *
 * A model has one file (material_<model>.c) with an init_state and an update. The update receives
 * the deformation-gradient increment dF of the step (plane strain: dF_zz = 1) and the total
 * Jacobian J = V / V0 after the step, and returns the effective Cauchy stress sigma' (tension
 * positive) with the updated internal state. Finite-strain models work with the elastic left
 * Cauchy-Green tensor Be and Kirchhoff stress tau = J sigma' (000 Eqs. 69-76); small-strain
 * models use the symmetric part of dF - I as the strain increment.
 */
#ifndef PORO_MATERIAL_H
#define PORO_MATERIAL_H

#include "case.h"
#include "error.h"
#include "particles.h"

struct material {
	enum material_model model;
	double density;          /* rho_s, kg/m^3 */
	double E, nu;            /* Young's modulus (Pa) and Poisson's ratio */
	double lambda, mu;       /* Lame constants, Pa */
	double bulk;             /* K = lambda + 2 mu / 3, Pa */
	double constrained;      /* 1 / m_v = lambda + 2 mu (000 Eq. 86), Pa */
};

/* One point's stress update. Arrays belong to the particle set. */
struct stress_update {
	const double *dF;        /* [4] row-major (xx, xy, yx, yy) */
	double J;                /* total Jacobian V/V0 after the step */
	double *stress;          /* [4] in: sigma'^t, out: sigma'^{t+1} (xx, yy, xy, zz), Pa */
	double *Be;              /* [4] elastic left Cauchy-Green (xx, yy, xy, zz) */
	double *state;           /* [STATE_MAX] internal variables */
	double *plastic_strain;  /* [1] */
};

void material_init(struct material *m, const struct case_material *spec);

/* Sets the internal state for a point whose initial effective stress is `stress` (zero for a
 * stress-free start): Be consistent with it for finite-strain models. */
void material_init_state(const struct material *m, const double *stress, double *Be, double *state);

/* Updates one point. Returns PORO_OK, or PORO_ESOLVER if the update has no valid result (for
 * example a non-positive stretch); err gets the reason. */
enum poro_status material_update(const struct material *m, struct stress_update *u, struct poro_error *err);

/* Per-model entry points (one file each). */
void linear_elastic_update(const struct material *m, struct stress_update *u);
enum poro_status hencky_update(const struct material *m, struct stress_update *u, struct poro_error *err);
void hencky_init_state(const struct material *m, const double *stress, double *Be);

/* Eigen-decomposition of a symmetric 2x2 tensor (xx, yy, xy): eigenvalues l[2] and the rotation
 * angle theta of the first eigenvector from the x axis. Closed form, used by finite-strain models. */
void sym2_eigen(double xx, double yy, double xy, double l[2], double *theta);

#endif
