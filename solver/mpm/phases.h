/*
 * phases.h - the phases of a step that every scheme shares, over struct sim (sim_internal.h).
 *
 * A scheme's step (schemes/<name>/) reads as its paper's algorithm: it calls these for what the
 * schemes have in common and keeps only its own equations. In 000 §4.5's numbering:
 *   point_map.c      step 1 (shape functions) and step 2 (the two phases' point-to-grid maps)
 *   point_motion.c   step 7a-b (the points' velocities and positions; water leaving the domain)
 *   deformation.c    step 8b-g (dF from a nodal displacement increment; F, V, n, k from dF)
 *   fbar.c           step 9b-g (the soil-phase stabilisations of 000 §4.4.2)
 *   stress_update.c  step 10 (the materials)
 * with loads.c (tractions, gravity and its ramp) and boundary.c (the faces' velocity constraints)
 * beside them.
 */
#ifndef PORO_PHASES_H
#define PORO_PHASES_H

#include "sim_internal.h"

/* ---- point_map.c ----------------------------------------------------------------------------- */

/* Step 1: shape functions and gradients of the soil and (double point) water points at their
 * current positions; fails when a point has left the grid. */
enum poro_status point_map_shapes(struct sim *s);

/* Divides a nodal field (width 1 or DIM) by a nodal weight where the weight is positive, else 0. */
void point_map_normalise(idx_t nodes, double *field, int width, const double *weight);

/* The point velocities' two transfers, with APIC's affine part when the points carry one
 * (formulation.velocity_update "apic" or "aflip"): point_map_momentum adds
 * out_I += sum_p S_Ip m_p v_p; point_gather_velocity sets v_p = sum_I S_Ip node_I (PIC) and, with
 * the affine part, the points' affine velocities C_p. */
void point_map_momentum(const struct sim *s, const struct particles *p, double *out);
void point_gather_velocity(const struct sim *s, struct particles *p, const double *node, double *v);

/* Step 2a-d: the soil's nodal mass M_s (Eq. 44), velocity v_s and its copy v_s_old (Eq. 45),
 * porosity (Eq. 46; 1 where there is no soil), point volume and conductivity (Eq. 47; the
 * gravity ramp's loading_conductivity, 000 §5.4, while it lasts) into s->f, which the scheme has
 * zeroed. */
void point_map_soil(struct sim *s);

/* How the water's nodal pressure p^t is formed from the point pressures (step 2f): Eq. 77's
 * water-mass-weighted mean, or its local linear fit (transfer.h, p2g_scalar_linear_fit), which
 * equals the mean inside a regular lattice and passes a linear field (the hydrostatic pressure)
 * through unchanged where the points lie to one side of the node. */
enum nodal_pressure { NODAL_PRESSURE_MEAN, NODAL_PRESSURE_LINEAR_FIT };

/* Step 2e-f, after point_map_soil: the water's nodal mass M_w (Eq. 50), velocity v_w and v_w_old
 * (Eq. 51) and pressure p^t. Double point first updates each water point's porosity (Eq. 48) and
 * volume (Eq. 36) from the nodal porosity just mapped. */
void point_map_water(struct sim *s, enum nodal_pressure nodal);

/* Node-wise mapping and remapping of a soil-point scalar (000 Eq. 80): avg_p =
 * sum_I S_Ip (sum_q S_Iq m_q value_q / M_sI). Overwrites s->f.pressure. */
void point_map_average_nodewise(struct sim *s, const double *value, double *avg);

/* ---- point_motion.c -------------------------------------------------------------------------- */

/* Step 7a-b for one point set: velocities by the case's velocity_update (FLIP blended with PIC by
 * flip_fraction, APIC or AFLIP) from the nodal v_new and the step's start v_old (overwritten with
 * the increment), positions x += dt sum S v_new when move_positions. Returns how many moved points
 * lie beyond a grid face. */
idx_t point_motion_update(struct sim *s, struct particles *p, const double *v_new, double *v_old, int move_positions);

/* 000 §5.4, gravity.water_attached during the ramp: the water points take the soil's nodal
 * velocity (PIC) and move with it. Returns how many lie beyond a grid face. */
idx_t point_motion_attach_water(struct sim *s);

/* Double point: water points beyond a face where water moves freely have left the domain; they
 * are removed and their mass booked as outflow (beyond: the count the motion returned). */
void point_motion_remove_outflow(struct sim *s, idx_t beyond);

/* ---- deformation.c --------------------------------------------------------------------------- */

/* Step 8b-c: each soil point's dF = I + sum_I du_I (x) grad S_Ip from a nodal displacement
 * increment du (DIM per node, constraints applied); with position_update "musl_displacement" the
 * points also move by sum_I S_Ip du_I, so that volume and motion follow one field. */
void deformation_increment(struct sim *s, const double *du);

/* Step 8d-g from the points' dF: F <- dF F, V <- det(dF) V, J = V / V0, porosity
 * n = 1 - (1 - n0) / J, conductivity by the body's permeability law. Fails, naming the point,
 * when a point inverts or its porosity leaves (0, 1). */
enum poro_status deformation_apply(struct sim *s);

/* The same with each point's volume following a volumetric strain rate of its own instead of
 * det(dF): V <- V (1 + dt rate_p), the volume update of 002 §3.3 step 8 with the cell-averaged rate
 * of Eqs. 26-27, so that volume, porosity and pore pressure see one rate; F still takes dF. */
enum poro_status deformation_apply_volumetric(struct sim *s, const double *rate);

/* ---- fbar.c ---------------------------------------------------------------------------------- */

/* Lays out the modified F-bar's fixed patches (000 §4.4.2, Eq. 83) once, at create. */
void fbar_patches_init(struct sim *s);

/* Step 9b-g: the case's soil_stabilisation applied to the points' dF (F-bar, Eqs. 79-80) and,
 * for the modified F-bar, to their Be (Eqs. 82-83); between deformation_increment and
 * deformation_apply. */
void fbar_stabilise(struct sim *s);

/* ---- stress_update.c ------------------------------------------------------------------------- */

/* Step 10: every soil point's stress from its dF and J through its material (Eqs. 69-76), in
 * parallel; the failure reported is the lowest-numbered failing point's at any thread count. */
enum poro_status stress_update(struct sim *s);

#endif
