/*
 * case.h - the case spec as C data: what schemas/case.schema.json describes, loaded from JSON.
 *
 * A case says everything needed to rerun an example and nothing about the machine. Field names are
 * the JSON keys (STYLE rule 9); units are SI and given with each field. Loading validates fully:
 * every problem is reported as one line "JSON-pointer: message" in the error record, and no
 * partially filled case is ever returned to the caller.
 *
 * Validation costs time and memory linear in the size of the document: names are looked up in hash
 * tables, not by scanning the lists, and every list and count a case implies (probes, grid cells,
 * time steps, ...) has a limit below, far above any real case, so that a case which asks for an
 * absurd amount of work is refused at once with the limit named (docs/case-spec.md, "Limits").
 * The list of problems is bounded too (CASE_PROBLEMS_MAX).
 *
 * Ownership: case_load_file()/case_load_string()/case_load_json() return a heap object the caller
 * frees with case_destroy(&c). The JSON text is kept in c->json (written to result files as /case).
 */
#ifndef PORO_CASE_H
#define PORO_CASE_H

#include "error.h"

#define CASE_SCHEMA_VERSION "poro-case/1"

/* Limits of a case (docs/case-spec.md, "Limits", and schemas/case.schema.json give the reasons).
 * Each sits orders of magnitude above the largest case in tests/cases/ and near or beyond what a
 * run could hold in memory, so it refuses only cases that could not run anyway. */
#define CASE_NAME_MAX 64                 /* bytes of a name with its NUL: names are 1 to 63 characters */
#define CASE_TITLE_MAX 255               /* characters (Unicode code points) of the title, as JSON
					    Schema's maxLength counts them */
#define CASE_TITLE_SIZE (4 * CASE_TITLE_MAX + 1) /* bytes that hold such a title in UTF-8, with its NUL */
#define CASE_MATERIALS_MAX 1000
#define CASE_BODIES_MAX 1000
#define CASE_LOADS_MAX 1000
#define CASE_PROBES_MAX 10000
#define CASE_POLYGON_MAX 64              /* vertices of one polygon */
#define CASE_POLYGON_VERTICES_MAX 10000  /* vertices of all the polygons of a case */
#define CASE_CELLS_MAX 100000000.0       /* grid cells; the grid holds about 300 bytes a node */
#define CASE_POINTS_MAX 100000000.0      /* material points, estimated from the bodies' areas */
#define CASE_STEPS_MAX 1000000000.0      /* time steps, end / dt */
#define CASE_FRAMES_MAX 100000.0         /* output frames, end / frame_interval (one a step at most) */
#define CASE_CHECKPOINTS_MAX 10000.0     /* checkpoints, end / checkpoint interval (one a step at most) */

/* A refused case's message lists at most CASE_PROBLEMS_MAX problems, one "JSON-pointer: message"
 * line each, in the order of the document (fewer when they would not fit in the message); when
 * there were more, a last line CASE_PROBLEMS_MORE followed by how many ("... and 900 more
 * problems"). case_problem_count() reads the total back from such a message. */
#define CASE_PROBLEMS_MAX 100
#define CASE_PROBLEMS_MORE "... and "
/* A valid case may still carry warnings: values that are allowed but most likely not what the
 * author meant (a friction angle that reads as radians), one "JSON-pointer: message" line each, in
 * case_spec.warnings (element_case.warnings), at most this many bytes with the NUL. */
#define CASE_WARNINGS_SIZE 2048

/* The time-integration schemes (solver/schemes/): paper 000's semi-implicit fractional step,
 * paper 002's explicit single-point v-w scheme with compressible pore fluid, and paper 001's fully
 * implicit u-p-U scheme (Newmark, modified Newton-Raphson). */
enum case_scheme { SCHEME_SEMI_IMPLICIT, SCHEME_EXPLICIT, SCHEME_IMPLICIT_UPU };
enum case_phases { PHASES_DOUBLE_POINT, PHASES_SINGLE_POINT };
enum case_shape { SHAPE_LINEAR, SHAPE_QUADRATIC_BSPLINE, SHAPE_CUBIC_BSPLINE, SHAPE_GIMP };
/* The matrix of the pressure solve: the Laplacian of 000 Eq. 61, or the projection G^T M^-1 G
 * consistent with the velocity correction (docs/numerics.md compares them). */
enum pressure_projection { PROJECTION_LAPLACIAN, PROJECTION_CONSISTENT };
enum pressure_stabilisation { PRESSURE_STABILISATION_NONE, PRESSURE_STABILISATION_SECOND_DIFFERENCE };
enum free_surface_condition { FREE_SURFACE_NODES, FREE_SURFACE_INTERPOLATED, FREE_SURFACE_WEAK };
/* What moves the soil points (step 7b): the grid velocity v^{t+1}, or the MUSL displacement of
 * step 8a, the field whose gradient also updates F and the volume (docs/numerics.md, "Volumes
 * that follow the motion"). */
enum position_update { POSITION_UPDATE_GRID_VELOCITY, POSITION_UPDATE_MUSL_DISPLACEMENT };
enum specific_volume { SPECIFIC_VOLUME_POINT, SPECIFIC_VOLUME_NODAL_AVERAGE };
enum velocity_update { VELOCITY_UPDATE_FLIP, VELOCITY_UPDATE_APIC, VELOCITY_UPDATE_AFLIP };
/* The explicit scheme's stabilisations (002 §3.2) and drag (spec-002 §5.1): the cell average of the
 * volumetric strain rates of both phases (Eqs. 26-27) or none; the node-based multi-field pressure
 * rate (Eqs. 28-34) with a constant or a linear basis, or each point's own rate; the drag integrated
 * at the nodes implicitly over the step (stable at any permeability) or explicitly from the step's
 * start velocities, as Eq. 22 prints it (stable below dt = 2 / lambda, stable_dt.h). */
enum strain_rate_smoothing { STRAIN_RATE_SMOOTHING_CELL_AVERAGE, STRAIN_RATE_SMOOTHING_NONE };
enum pressure_rate_projection { PRESSURE_RATE_MULTI_FIELD, PRESSURE_RATE_NONE };
enum pressure_rate_basis { PRESSURE_RATE_BASIS_CONSTANT, PRESSURE_RATE_BASIS_LINEAR };
enum drag_integration { DRAG_IMPLICIT, DRAG_EXPLICIT };
/* Soil-phase stabilisation (000 §4.4.2, docs/numerics.md): none; F-bar with the node-wise averaged
 * volume change (Eqs. 79-80); modified F-bar (Eq. 81), which also scales Be^t to the patch-wise
 * averaged elastic Jacobian (Eqs. 82-83; patch 1.5 h for B-splines, the cell for linear); and the
 * same with cell-wise patches on any shape (h_patch = h, the comparison of 000 App. A / Fig. 12). */
enum soil_stabilisation { STABILISATION_NONE, STABILISATION_FBAR, STABILISATION_MODIFIED_FBAR,
			  STABILISATION_MODIFIED_FBAR_CELLWISE, STABILISATION_BBAR };
/* The implicit u-p-U scheme's (001 §2.2, spec-001): how the pore-pressure increments reach the
 * points (the MLSA patch recovery's linear patch at the point, the recovered nodal values
 * interpolated, or Eq. 11e's direct interpolation), the mass matrices (consistent, A.1a-b as
 * printed, or lumped), and the Newton iteration's tangent (the elastic one factorised once a step,
 * 001's modified Newton-Raphson, or the materials' consistent tangent every iteration). */
enum pressure_recovery { PRESSURE_RECOVERY_MLSA_PATCH, PRESSURE_RECOVERY_MLSA_NODAL, PRESSURE_RECOVERY_NONE };
enum mass_matrix { MASS_MATRIX_CONSISTENT, MASS_MATRIX_LUMPED };
enum newton_tangent { NEWTON_TANGENT_ELASTIC, NEWTON_TANGENT_CONSISTENT };

/* Constitutive models (material.h), one file each: "linear_elastic" (small strain), "hencky" (finite
 * strain), the Mohr-Coulomb family returned in principal stress space (principal_return.h):
 * "mohr_coulomb", "tresca_softening" (001 §4.2.1), "mohr_coulomb_dilation" (001 Eq. 17), and
 * "nor_sand" (Borja and Andrade's return with 000 App. B.1's changes, material_nor_sand.c). */
enum material_model { MODEL_LINEAR_ELASTIC, MODEL_HENCKY, MODEL_MOHR_COULOMB, MODEL_TRESCA_SOFTENING,
		      MODEL_MOHR_COULOMB_DILATION, MODEL_NOR_SAND };
/* Kinematics of a plastic model: finite strain (Be, logarithmic strain, Kirchhoff stress, 000 Eqs.
 * 69-76; the default) or small strain (the symmetric part of dF - I). */
enum material_strain { STRAIN_FINITE, STRAIN_SMALL };

/* constant; Kozeny-Carman k = C1 n^3 / (1 - n)^2 (000 step 8g); volume_ratio k = k0 V / V0;
 * volume_ratio_squared k = k0 (V / V0)^2 = k0 ((1 + e)/(1 + e0))^2, the law under which Xie and Leo's
 * large-strain solution (000 Eqs. 87-90) is exact (docs/numerics.md, "Xie-Leo permeability"). */
enum permeability_law {
	PERMEABILITY_CONSTANT,
	PERMEABILITY_KOZENY_CARMAN,
	PERMEABILITY_VOLUME_RATIO,
	PERMEABILITY_VOLUME_RATIO_SQUARED
};

/* Velocity constraint of one phase on a grid face: free, slip (normal component zero: a roller),
 * fixed (both components zero), plate (a rigid smooth plate: the normal component is one velocity
 * shared by the whole face, driven by the plate's force; solver/schemes/semi_implicit/plate.c). */
enum face_constraint { CONSTRAINT_FREE, CONSTRAINT_SLIP, CONSTRAINT_FIXED, CONSTRAINT_PLATE };
/* Drainage of a grid face, independent of its velocity constraint: impermeable (no flux: the
 * natural condition of the pressure equation) or drained (pore pressure zero on the face). */
enum face_drainage { DRAINAGE_IMPERMEABLE, DRAINAGE_DRAINED };
enum grid_face { FACE_LEFT, FACE_RIGHT, FACE_BOTTOM, FACE_TOP, FACE_COUNT };

enum time_function_kind { TIME_CONSTANT, TIME_RAMP, TIME_SINUSOID };

enum probe_kind { PROBE_PORE_PRESSURE, PROBE_DISPLACEMENT, PROBE_AVERAGE };
enum probe_field { FIELD_PORE_PRESSURE, FIELD_STRESS_XX, FIELD_STRESS_YY, FIELD_STRESS_XY,
		   FIELD_DISPLACEMENT_X, FIELD_DISPLACEMENT_Y };

struct case_formulation {
	enum case_scheme scheme;          /* "semi_implicit" or "explicit" (single point only) */
	enum case_phases phases;          /* "double_point" (default) or "single_point" */
	enum case_shape shape;            /* "linear", "quadratic_bspline" (default), "cubic_bspline" or
					     "gimp" (uGIMP; the explicit scheme only, shape.h) */
	int pore_pressure_smoothing;      /* node-wise smoothing, 000 Eq. 77; default true */
	enum velocity_update velocity_update; /* point velocities: "flip" (default, blended with PIC by
						 flip_fraction), "apic" (affine PIC, transfer.h) or
						 "aflip" (FLIP blended by flip_fraction, with
						 APIC's affine part) */
	double flip_fraction;             /* 1 = pure FLIP (default), 0 = PIC; velocity update blend */
	enum pressure_projection pressure_projection; /* "laplacian" (default) or "consistent" */
	enum soil_stabilisation soil_stabilisation;   /* "none" (default), "fbar", "modified_fbar" or
							 "modified_fbar_cellwise" */
	int drag_in_correction;           /* drag also in the velocity correction (phase_coupling.h); default false */
	enum pressure_stabilisation pressure_stabilisation; /* "none" (default) or "second_difference"
							       (pressure_stabilisation.c; consistent projection only) */
	double pressure_stabilisation_factor; /* > 0, weight of the second-difference penalty; default 10 */
	enum free_surface_condition free_surface; /* "nodes" (default), "interpolated" or "weak"
						     (free_surface.c; the last two: consistent projection only) */
	double free_surface_penalty_factor;   /* > 0, weight of the interpolated condition; default 1e4 */
	enum position_update position_update; /* soil points: "grid_velocity" (default) or "musl_displacement" */
	enum specific_volume specific_volume; /* the J of Nor-Sand's v = J v0: "point" (default, 000 Eq. 95)
						 or "nodal_average" (Eqs. 96-97) */
	/* the explicit scheme's (002 §3.2, spec-002 §5.1) */
	enum strain_rate_smoothing strain_rate_smoothing;   /* "cell_average" (default) or "none" */
	enum pressure_rate_projection pressure_rate_projection; /* "multi_field" (default) or "none" */
	enum pressure_rate_basis pressure_rate_basis;       /* "constant" (default) or "linear" */
	enum drag_integration drag;                         /* "implicit" (default) or "explicit" */
	/* the implicit u-p-U scheme's (001, spec-001 §4); soil_stabilisation "bbar" (default) or "none" */
	double newmark_beta, newmark_gamma;                 /* 0.25, 0.5 (001 §2.2) */
	enum newton_tangent tangent;                        /* "elastic" (default) or "consistent" */
	double newton_tolerance;                            /* energy criterion, default 1e-10 */
	int newton_max_iterations;                          /* default 100 */
	enum pressure_recovery pressure_recovery;           /* "mlsa_patch" (default), "mlsa_nodal", "none" */
	enum mass_matrix mass_matrix;                       /* "consistent" (default) or "lumped" */
};

struct case_grid {
	double origin[2];                 /* lower-left corner, m */
	double extent[2];                 /* width and height, m; multiples of cell_size */
	double cell_size;                 /* h, m (square cells) */
};

struct case_material {
	char name[CASE_NAME_MAX];
	enum material_model model;        /* "linear_elastic" (small strain), "hencky" (finite strain) or a
					     plastic model (below) */
	double density;                   /* soil grain density rho_s, kg/m^3 */
	double youngs_modulus;            /* E, Pa, > 0 */
	double poisson_ratio;             /* nu, -1 < nu < 0.5 */
	/* Plastic models only (case_material.c says which model takes which key). Angles in degrees
	 * as given; material_init() converts and applies the strength reduction. */
	enum material_strain strain;      /* "finite" (default) or "small" */
	double cohesion;                  /* c, Pa, >= 0 (mohr_coulomb, mohr_coulomb_dilation) */
	double friction_angle;            /* phi, degrees, 0 < phi < 90 (Mohr-Coulomb models) */
	double dilation_angle;            /* psi, degrees, 0 <= psi <= phi (mohr_coulomb) */
	double peak_cohesion;             /* c_p, Pa, > 0 (tresca_softening) */
	double residual_cohesion;         /* c_r, Pa, 0 <= c_r <= c_p (tresca_softening) */
	double residual_plastic_strain;   /* eps_p^r: deviatoric plastic strain at which c_r is reached, > 0 */
	double initial_dilation_angle;    /* psi_ini, degrees, -phi <= psi_ini <= phi (mohr_coulomb_dilation) */
	double critical_dilation_angle;   /* psi_crit, degrees, -phi <= psi_crit <= phi */
	double dilation_evolution_parameter; /* eta >= 0 of 001 Eq. 17, per unit deviatoric plastic strain */
	double strength_reduction_factor; /* SRF >= 1, default 1 (000 Eq. 91) */
	/* nor_sand (000 Table 6 and App. B; youngs_modulus and poisson_ratio are not taken). */
	double shear_modulus;             /* G, Pa, > 0 (constant) */
	double swelling_index;            /* kappa > 0: p = p0 exp(-(eps_v^e - eps_v0^e) / kappa) */
	double compression_index;         /* lambda > 0: slope of the critical state line in v - ln p */
	double reference_specific_volume; /* v_c0 > 1: v on the critical state line at p = critical_state_reference_pressure */
	double critical_state_reference_pressure; /* Pa, > 0, default 1000 (v_c0 quoted with p in kPa) */
	double critical_stress_ratio;     /* M > 0 */
	double yield_function_constant;   /* N, 0 <= N < 1 */
	double plastic_potential_constant;/* Nbar, 0 <= Nbar < 1 */
	double hardening_coefficient;     /* h >= 0 */
	double dilatancy_multiplier;      /* alpha <= 0: maximum plastic dilatancy D* = alpha psi_i */
	double initial_specific_volume;   /* v0 > 1 */
	double overconsolidation_ratio;   /* OCR >= 1, default 1 (000 Eq. 113) */
	int yield_surface_through_stress; /* 1: the initial image pressure is at least the one whose surface
					     passes through the point's stress ("initial_yield_surface":
					     "through_stress"); 0: Eq. 113 alone ("tip", default) */
	double initial_reference_pressure;/* Pa, > 0, default 2000: p0 of a stress-free point (000 App. B.4) */
	double dilatancy_cutoff_start;    /* E_d^p,start >= 0, default 1 (000 Eq. 92) */
	double dilatancy_cutoff_end;      /* E_d^p,end > start, default 1.5 */
	double gas_volume_ratio;          /* v_crit / v0 > 1, default 1.6 (000 Eqs. 93-94) */
};

struct case_body {
	char name[CASE_NAME_MAX];
	int material;                     /* index into case.materials */
	int is_polygon;                   /* 0: rectangle [min, max]; 1: polygon */
	double min[2], max[2];            /* rectangle corners, m (for a polygon: its bounding box) */
	int polygon_count;
	double polygon[CASE_POLYGON_MAX][2]; /* vertices, m, counter-clockwise or clockwise */
	int particles_per_cell;           /* points per cell per direction (2 means 2x2) */
	double porosity;                  /* initial porosity n0, 0 < n0 < 1 */
	double hydraulic_conductivity;    /* k0, m/s, > 0 */
	enum permeability_law permeability_law; /* "constant" (default), "kozeny_carman" (000 step 8g),
						   "volume_ratio" (k = k0 V/V0) or "volume_ratio_squared"
						   (k = k0 (V/V0)^2, Xie and Leo 2004) */
	double initial_pore_pressure;     /* Pa, compression positive, default 0: the points' pore
					     pressure at t = 0 (002 §4.1 starts at p0 = q with sigma' = 0) */
	int saturated;                    /* 1 (default): the pores are full of water; 0: a dry body, whose
					     points carry no water (sim.c, docs/numerics.md "Dry bodies") */
};

struct case_time_function {
	enum time_function_kind kind;     /* "constant" | "ramp" | "sinusoid" */
	double ramp_time;                 /* ramp: s, value rises linearly from 0 to 1 over [0, ramp_time] */
	double frequency;                 /* sinusoid: Hz */
	double amplitude;                 /* sinusoid: dimensionless; value = mean + amplitude sin(2 pi f t + phase) */
	double mean;                      /* sinusoid: dimensionless, default 0 */
	double phase;                     /* sinusoid: rad */
	double start;                     /* sinusoid: s, default 0; value 0 before it and t counted
					     from it (002 §4.3's load begins when gravity has ramped up) */
};

struct case_boundary {
	enum face_constraint soil;        /* soil velocity constraint on the face */
	enum face_constraint water;       /* water velocity constraint on the face */
	enum face_drainage drainage;
	struct {                          /* soil "plate" only: the rigid plate on the face */
		double force;             /* N per metre of thickness, pushing into the grid along the
					     face's inward normal (compression positive) */
		struct case_time_function time_function;   /* scales the force over time */
	} plate;
};

struct case_load {
	int body;                         /* index into case.bodies */
	enum grid_face face;              /* which face of the body's bounding box: left/right/bottom/top */
	double from, to;                  /* extent along the face, m (x for top/bottom, y for left/right);
					     default the whole face */
	double traction[2];               /* Pa, applied to the soil skeleton (000 Eq. 54) */
	struct case_time_function time_function;
};

struct case_probe {
	char name[CASE_NAME_MAX];
	enum probe_kind kind;             /* "pore_pressure" at point, "displacement" of the soil point
					     nearest to point, "average" of field over box */
	double point[2];                  /* m */
	int component;                    /* displacement: 0 = x, 1 = y */
	enum probe_field field;           /* average: which field */
	double box_min[2], box_max[2];    /* average: box, m */
};

struct case_spec {
	char title[CASE_TITLE_SIZE];      /* UTF-8, at most CASE_TITLE_MAX characters */
	char warnings[CASE_WARNINGS_SIZE]; /* "" when none (CASE_WARNINGS_SIZE) */
	struct case_formulation formulation;
	struct case_grid grid;
	int material_count;
	struct case_material *materials;
	int body_count;
	struct case_body *bodies;
	struct {
		double density;           /* rho_w, kg/m^3 */
		double bulk_modulus;      /* K_w, Pa (the explicit scheme's compressible pore fluid, 002 Eq. 9;
					     unused by the semi-implicit scheme) */
		double cavitation_pressure; /* p_cav, the pressure at which the pore water boils, Pa, gauge
					       (compression positive, as in case files), < 0; 0: no limit,
					       the water takes any tension as in 000 (cavitation.c) */
		double grain_bulk_modulus; /* K_s of 001 Eq. 3, Pa: the grains' compressibility in 1/Q =
					      n / K_w + (1 - n) / K_s; 0 (default): incompressible grains */
		double cavitated_bulk_modulus; /* K_c, Pa: the stiffness of the water once it has cavitated,
						  the spring on its vapour (cavitation.c) */
	} fluid;
	struct {
		double acceleration[2];   /* body force b, m/s^2, e.g. [0, -9.81] */
		double ramp_time;         /* s; 0 = applied at once */
		int elastic_loading;      /* 000 App. B.4: plastic models stay elastic during the ramp, and at
					     its end every soil point's state becomes its reference */
		double loading_conductivity; /* m/s; > 0: every soil point's conductivity while gravity ramps
					     up (000 §5.4 uses 1 m/s so the loading leaves no excess pore
					     pressure); 0 (default): the bodies' own */
		int water_attached;       /* while gravity ramps up the water moves with the soil (000 §5.4:
					     no seepage during the initialisation); default false */
	} gravity;
	struct case_boundary boundaries[FACE_COUNT];
	int load_count;
	struct case_load *loads;
	struct {
		double dt;                /* time step, s, > 0; "auto": the scheme's recommended step
					     (stable_dt.h), written here by the loader */
		int dt_auto;              /* 1 when the case asked for "auto" */
		double end;               /* end time, s, > 0 */
	} time;
	struct {
		double frame_interval;    /* s; 0 = first and last frame only */
		double progress_interval; /* s of wall time between progress lines, default 1 */
	} output;
	int probe_count;
	struct case_probe *probes;
	struct {
		double interval;          /* s of simulated time between checkpoints; 0 = none (key absent) */
	} checkpoint;
	unsigned metrics;                 /* bit (1u << k) per figure k (figures.h) the optional "metrics"
					     object asks the run to report (case_metrics.h) */
	char *json;                       /* the case as given, NUL-terminated */
};

typedef struct json_t json_t;

/* Loads and validates a case. On failure returns PORO_EINVAL (or PORO_EIO for an unreadable file,
 * PORO_ENOMEM) with the problems listed in err->message as described at CASE_PROBLEMS_MAX, and
 * *out NULL. case_load_string() keeps json as c->json. */
enum poro_status case_load_file(const char *path, struct case_spec **out, struct poro_error *err);
enum poro_status case_load_string(const char *json, struct case_spec **out, struct poro_error *err);
/* The same on a document jansson has already parsed (the server's request body), so that one tree
 * is built, not two. root is only read and not kept. c->json is root in canonical form: compact,
 * keys sorted (json_dumps with JSON_COMPACT | JSON_SORT_KEYS), the text the server stores. */
enum poro_status case_load_json(const json_t *root, struct case_spec **out, struct poro_error *err);
void case_destroy(struct case_spec **c);

/* How many problems a refused case's message stands for: its lines, with a last line
 * CASE_PROBLEMS_MORE "N more problems" counted as N. 0 for NULL or "". */
long case_problem_count(const char *message);

/* Compares two case texts as JSON values: key order, white space and the spelling of numbers
 * (2, 2.0, 2e0) do not matter. Returns 0 when equal; 1 when they differ, with the JSON pointer
 * of the first difference in where[size] ("/" for the whole document); -1 when either text is
 * not JSON (where names which: "first" or "second"). Implemented with the case loader's JSON
 * reader (case_json.c). */
int case_json_difference(const char *a, const char *b, char *where, size_t size);

/* Value of a time function at time t (dimensionless factor). */
double case_time_function_value(const struct case_time_function *f, double t);

#endif
