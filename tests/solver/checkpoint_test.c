/*
 * checkpoint_test.c - tests of checkpoints and resume (solver/output/checkpoint.c, the resume path of
 * solver/run.c and output.c).
 *
 * Oracle: the uninterrupted run. A small loaded column under gravity (Hencky skeleton, so Be and
 * F carry state frames do not hold; a drained top; three kinds of probe) runs N steps, is
 * checkpointed, and runs M more. A second simulation created from the same case and loaded from
 * the checkpoint must hold exactly the state of the first at step N (every saved array, bit for
 * bit) and, after M steps, agree with the first in every per-point field to RESUME_TOLERANCE,
 * relative to the field's largest magnitude. Not bit for bit: the first pressure solve after a
 * resume factorises afresh where the uninterrupted run uses conjugate gradients on its previous
 * factor (spd_solve.h), converged to a relative residual of 1e-12; the measured differences are
 * printed as INFO lines. Both double point and single point, each also with APIC point velocities
 * (whose affine velocities C the checkpoint must carry), and the dry embankment of
 * tests/cases/dry_embankment.json, whose dry fill's points carry no water: the single-point
 * water set is then the clay's points only, which the resume must accept (it required one water
 * value per soil point).
 *
 * The sim_run test kills a run in a child process (_exit, like kill -9) right after its first
 * checkpoint is announced, resumes it in the same directory, and requires result.h5 to hold the
 * frames and probe samples of an uninterrupted run at the same times, with no duplicate and no gap
 * at the resume point. Refusals: a checkpoint of another case (the message names the first
 * difference), a truncated file, a file that is not HDF5, a result file, a missing file, and a
 * checkpoint whose body indices were damaged: each is an error with a message, never a crash.
 */
#include "checkpoint.h"

#include <hdf5.h>
#include <jansson.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "../harness.h"
#include "results_read.h"

#define DT 1.0e-4
#define STEPS_BEFORE 17           /* N: steps before the checkpoint */
#define STEPS_AFTER 23            /* M: steps after it */
#define RESUME_TOLERANCE 1e-10    /* relative to a field's largest magnitude */
#define FIELD_FLOOR 1e-300        /* a field that is zero everywhere compares absolutely */

/* A 0.1 m x 0.3 m column of 0.25 m, 160 soil points, Hencky skeleton, loaded on a ramp, drained
 * on top. %s: phases; %s: the velocity update; %s: an extra top-level member (the checkpoint
 * interval for sim_run). */
static const char case_format[] =
	"{\"schema\": \"poro-case/1\", \"title\": \"checkpoint test column\","
	" \"formulation\": {\"scheme\": \"semi_implicit\", \"phases\": \"%s\", \"velocity_update\": \"%s\","
	"   \"shape\": \"quadratic_bspline\"},"
	" \"grid\": {\"origin\": [0.0, 0.0], \"extent\": [0.1, 0.3], \"cell_size\": 0.025},"
	" \"materials\": [{\"name\": \"silt\", \"model\": \"hencky\", \"density\": 2683,"
	"   \"youngs_modulus\": 1.37e6, \"poisson_ratio\": 0.23}],"
	" \"bodies\": [{\"name\": \"column\", \"material\": \"silt\", \"rectangle\": {\"min\": [0.0, 0.0],"
	"   \"max\": [0.1, 0.25]}, \"particles_per_cell\": 2, \"porosity\": 0.347, \"hydraulic_conductivity\": 2.3e-3,"
	"   \"permeability_law\": \"kozeny_carman\"}],"
	" \"fluid\": {\"density\": 1000},"
	" \"gravity\": {\"acceleration\": [0.0, -9.81], \"ramp_time\": 0.0013},"
	" \"boundaries\": {\"left\": {\"soil\": \"slip\", \"water\": \"slip\"},"
	"   \"right\": {\"soil\": \"slip\", \"water\": \"slip\"}, \"bottom\": {\"soil\": \"fixed\", \"water\": \"slip\"},"
	"   \"top\": {\"drainage\": \"drained\"}},"
	" \"loads\": [{\"body\": \"column\", \"face\": \"top\", \"traction\": [0.0, -2.345e4],"
	"   \"time_function\": {\"kind\": \"ramp\", \"ramp_time\": 0.0021}}],"
	" \"time\": {\"dt\": %g, \"end\": %.17g}, \"output\": {\"frame_interval\": 0.0007},"
	" \"probes\": [{\"name\": \"p_base\", \"kind\": \"pore_pressure\", \"point\": [0.05, 0.01]},"
	"   {\"name\": \"settlement\", \"kind\": \"displacement\", \"point\": [0.05, 0.25], \"component\": \"y\"},"
	"   {\"name\": \"syy_mid\", \"kind\": \"average\", \"field\": \"stress_yy\","
	"    \"box\": {\"min\": [0.0, 0.1], \"max\": [0.1, 0.15]}}]%s}";

/* The same column under a rigid plate on the grid's top face (solver/schemes/semi_implicit/plate.c) instead of the
 * traction, drained at the bottom: the plate's velocity is rebuilt each step from the nodes'
 * momentum, so a resumed run needs nothing more in the checkpoint. %s: phases. */
static const char plate_case_format[] =
	"{\"schema\": \"poro-case/1\", \"title\": \"checkpoint test column under a plate\","
	" \"formulation\": {\"scheme\": \"semi_implicit\", \"phases\": \"%s\", \"shape\": \"quadratic_bspline\"},"
	" \"grid\": {\"origin\": [0.0, 0.0], \"extent\": [0.1, 0.25], \"cell_size\": 0.025},"
	" \"materials\": [{\"name\": \"silt\", \"model\": \"hencky\", \"density\": 2683,"
	"   \"youngs_modulus\": 1.37e6, \"poisson_ratio\": 0.23}],"
	" \"bodies\": [{\"name\": \"column\", \"material\": \"silt\", \"rectangle\": {\"min\": [0.0, 0.0],"
	"   \"max\": [0.1, 0.25]}, \"particles_per_cell\": 2, \"porosity\": 0.347, \"hydraulic_conductivity\": 2.3e-3}],"
	" \"fluid\": {\"density\": 1000},"
	" \"gravity\": {\"acceleration\": [0.0, 0.0]},"
	" \"boundaries\": {\"left\": {\"soil\": \"slip\", \"water\": \"slip\"},"
	"   \"right\": {\"soil\": \"slip\", \"water\": \"slip\"},"
	"   \"bottom\": {\"soil\": \"slip\", \"water\": \"free\", \"drainage\": \"drained\"},"
	"   \"top\": {\"soil\": \"plate\", \"water\": \"plate\", \"plate\": {\"force\": 2345,"
	"     \"time_function\": {\"kind\": \"ramp\", \"ramp_time\": 0.0021}}}},"
	" \"time\": {\"dt\": %g, \"end\": %.17g}, \"output\": {\"frame_interval\": 0.0007},"
	" \"probes\": [{\"name\": \"p_base\", \"kind\": \"pore_pressure\", \"point\": [0.05, 0.01]},"
	"   {\"name\": \"settlement\", \"kind\": \"displacement\", \"point\": [0.05, 0.25], \"component\": \"y\"},"
	"   {\"name\": \"syy_mid\", \"kind\": \"average\", \"field\": \"stress_yy\","
	"    \"box\": {\"min\": [0.0, 0.1], \"max\": [0.1, 0.15]}}]}";

static char *plate_case_json(const char *phases)
{
	static char buf[4096];
	snprintf(buf, sizeof buf, plate_case_format, phases, DT, (STEPS_BEFORE + STEPS_AFTER) * DT);
	return buf;
}

static char *case_json_with(const char *phases, const char *velocity_update, const char *extra)
{
	static char buf[4][4096];
	static int next;
	char *b = buf[next++ % 4];
	snprintf(b, sizeof buf[0], case_format, phases, velocity_update, DT, (STEPS_BEFORE + STEPS_AFTER) * DT, extra);
	return b;
}

static char *case_json(const char *phases, const char *extra)
{
	return case_json_with(phases, "flip", extra);
}

/* A shipped case (with phases, when not NULL), cut to the steps of a resume test; a heap string
 * the caller frees, NULL if the file cannot be read. */
static char *shipped_case_json(const char *file, const char *phases)
{
	json_t *c = json_load_file(file, 0, NULL);
	if (!c)
		return NULL;
	json_t *time = json_object_get(c, "time");
	if (phases)
		json_object_set_new(json_object_get(c, "formulation"), "phases", json_string(phases));
	json_object_set_new(time, "end", json_real((STEPS_BEFORE + STEPS_AFTER) * json_real_value(json_object_get(time, "dt"))));
	char *text = json_dumps(c, 0);
	json_decref(c);
	return text;
}

/* ---- fixtures ---------------------------------------------------------------------------------- */

static struct sim *new_sim(const char *json, struct case_spec **c)
{
	struct poro_error err = {0};
	struct sim *s = NULL;
	if (case_load_string(json, c, &err) || sim_create(&s, *c, &err)) {
		printf("INFO cannot build the test case: %s\n", err.message);
		case_destroy(c);
		return NULL;
	}
	return s;
}

static int steps(struct sim *s, int n)
{
	for (int i = 0; i < n; i++)
		if (sim_step(s)) {
			printf("INFO step failed: %s\n", sim_error(s)->message);
			return -1;
		}
	return 0;
}

/* ---- comparing two simulations --------------------------------------------------------------- */

struct compared {
	const char *name;
	size_t member;
	int width;
};

#define FIELD(m, w) {#m, offsetof(struct particles, m), w}
static const struct compared soil_fields[] = {
	FIELD(x, 2), FIELD(x0, 2), FIELD(v, 2), FIELD(mass, 1), FIELD(volume, 1), FIELD(volume0, 1),
	FIELD(porosity, 1), FIELD(porosity0, 1), FIELD(conductivity, 1), FIELD(pressure, 1), FIELD(stress, 4),
	FIELD(F, 4), FIELD(Be, 4), FIELD(state, STATE_MAX), FIELD(plastic_strain, 1), FIELD(surface, 2),
	FIELD(acceleration, 2),
};
static const struct compared water_fields[] = {
	FIELD(x, 2), FIELD(x0, 2), FIELD(v, 2), FIELD(mass, 1), FIELD(volume, 1), FIELD(volume0, 1),
	FIELD(porosity, 1), FIELD(porosity0, 1), FIELD(pressure, 1), FIELD(acceleration, 2),
};

static const double *field_of(const struct particles *p, const struct compared *f)
{
	return *(double *const *)((const char *)p + f->member);
}

/* Largest |a - b| over max |b| for each field of a set; the worst of them goes to *worst and its
 * name to worst_name. -1 when the sets differ in size or one lacks an array the other has. */
static int compare_sets(const struct particles *a, const struct particles *b, const struct compared *fields,
			size_t count, double *worst, const char **worst_name)
{
	if (a->n != b->n)
		return -1;
	for (size_t k = 0; k < count; k++) {
		const double *x = field_of(a, &fields[k]), *y = field_of(b, &fields[k]);
		if (!x || !y) {   /* a scheme's own arrays (the implicit scheme's) exist in its runs only */
			if (x != y)
				return -1;
			continue;
		}
		double diff = 0.0, scale = FIELD_FLOOR;
		for (long i = 0; i < (long)b->n * fields[k].width; i++) {
			diff = fmax(diff, fabs(x[i] - y[i]));
			scale = fmax(scale, fabs(y[i]));
		}
		if (!(diff / scale <= *worst)) {
			*worst = diff / scale;
			*worst_name = fields[k].name;
		}
	}
	return 0;
}

/* 1 when every saved array and counter of a and b is bit for bit the same. */
static int identical(const struct sim *a, const struct sim *b)
{
	double worst = 0.0;
	const char *name = "";
	int ok = compare_sets(sim_soil(a), sim_soil(b), soil_fields, sizeof soil_fields / sizeof soil_fields[0],
			      &worst, &name) == 0 && worst == 0.0;
	ok = ok && compare_sets(sim_water(a), sim_water(b), water_fields, sizeof water_fields / sizeof water_fields[0],
				&worst, &name) == 0 && worst == 0.0;
	for (int set = 0; ok && set < 2; set++) {   /* APIC's affine velocities, where the run has them */
		const struct particles *pa = set ? sim_water(a) : sim_soil(a), *pb = set ? sim_water(b) : sim_soil(b);
		ok = !pa->C == !pb->C && (!pa->C || memcmp(pa->C, pb->C, sizeof(double) * 4 * (size_t)pa->n) == 0);
	}
	ok = ok && memcmp(sim_soil(a)->body, sim_soil(b)->body, sizeof(int) * (size_t)sim_soil(a)->n) == 0 &&
	     memcmp(sim_soil(a)->surface_load, sim_soil(b)->surface_load, sizeof(int) * (size_t)sim_soil(a)->n) == 0;
	ok = ok && sim_steps_taken(a) == sim_steps_taken(b) && sim_time(a) == sim_time(b) &&
	     sim_water_outflow_mass(a) == sim_water_outflow_mass(b);
	for (int i = 0; ok && i < 3; i++) {
		double pa = sim_probe_value(a, i), pb = sim_probe_value(b, i);
		ok = pa == pb || (isnan(pa) && isnan(pb));
	}
	return ok;
}

/* ---- step-level resume ------------------------------------------------------------------------- */

static void test_resume_case(const char *label, const char *json)
{
	char name[128], path[128];
	struct case_spec *ca = NULL, *cb = NULL;
	char *dir = harness_temp_dir("checkpoint_test");
	struct sim *a = new_sim(json, &ca), *b = new_sim(json, &cb);
	snprintf(name, sizeof name, "%s_builds", label);
	CHECK(dir && a && b, name, "no directory or simulation");
	if (!dir || !a || !b)
		goto out;

	int ok = steps(a, STEPS_BEFORE) == 0 && checkpoint_write(a, dir) == PORO_OK;
	snprintf(name, sizeof name, "%s_checkpoint_written", label);
	struct stat sb;
	CHECK(ok && stat(harness_join(path, sizeof path, dir, CHECKPOINT_NAME), &sb) == 0 &&
	      stat(harness_join(path, sizeof path, dir, CHECKPOINT_TMP_NAME), &sb) != 0, name, "%s",
	      ok ? "checkpoint.h5 missing or checkpoint.h5.tmp left" : sim_error(a)->message);

	enum poro_status st = checkpoint_load(b, harness_join(path, sizeof path, dir, CHECKPOINT_NAME));
	snprintf(name, sizeof name, "%s_load_restores_exact_state", label);
	CHECK(!st && checkpoint_resumed(b) && identical(a, b), name, "status %d: %s", st, sim_error(b)->message);

	ok = steps(a, STEPS_AFTER) == 0 && steps(b, STEPS_AFTER) == 0 && sim_done(a) && sim_done(b);
	double worst = 0.0;
	const char *worst_name = "none";
	int sizes = compare_sets(sim_soil(b), sim_soil(a), soil_fields, sizeof soil_fields / sizeof soil_fields[0],
				 &worst, &worst_name);
	sizes |= compare_sets(sim_water(b), sim_water(a), water_fields, sizeof water_fields / sizeof water_fields[0],
			      &worst, &worst_name);
	printf("INFO %s: after %d steps from the checkpoint, largest relative difference %.3g (%s)\n", label,
	       STEPS_AFTER, worst, worst_name);
	snprintf(name, sizeof name, "%s_resumed_run_matches_uninterrupted", label);
	CHECK(ok && sizes == 0 && worst <= RESUME_TOLERANCE && sim_time(a) == sim_time(b), name,
	      "steps ok %d, sizes %d, worst %.3g in %s", ok, sizes, worst, worst_name);
out:
	sim_destroy(&a);
	sim_destroy(&b);
	case_destroy(&ca);
	case_destroy(&cb);
	if (dir)
		harness_remove_dir(dir);
}

static void test_resume(const char *label, const char *phases, const char *velocity_update)
{
	test_resume_case(label, case_json_with(phases, velocity_update, ""));
}

/* ---- refusals ---------------------------------------------------------------------------------- */

/* Loads path into a fresh sim of json; returns the status and copies the message. */
static enum poro_status try_load(const char *json, const char *path, char *message, size_t size)
{
	struct case_spec *c = NULL;
	struct sim *s = new_sim(json, &c);
	if (!s)
		return PORO_ENOMEM;
	enum poro_status st = checkpoint_load(s, path);
	snprintf(message, size, "%s", sim_error(s)->message);
	sim_destroy(&s);
	case_destroy(&c);
	return st;
}

static int copy_prefix(const char *from, const char *to, long bytes)
{
	FILE *in = fopen(from, "rb"), *out = fopen(to, "wb");
	int rc = in && out ? 0 : -1;
	for (long i = 0; !rc && i < bytes; i++) {
		int ch = fgetc(in);
		if (ch == EOF)
			break;
		fputc(ch, out);
	}
	if (in)
		fclose(in);
	if (out && fclose(out))
		rc = -1;
	return rc;
}

/* Overwrites /soil/body[0] with an index no case body has. */
static int damage_body(const char *path)
{
	hid_t f = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT);
	hid_t ds = f < 0 ? -1 : H5Dopen2(f, "/soil/body", H5P_DEFAULT);
	hid_t space = ds < 0 ? -1 : H5Dget_space(ds);
	hsize_t start = 0, count = 1;
	int bad = 7919;
	hid_t mem = H5Screate_simple(1, &count, NULL);
	int rc = space < 0 || H5Sselect_hyperslab(space, H5S_SELECT_SET, &start, NULL, &count, NULL) < 0 ||
		 H5Dwrite(ds, H5T_NATIVE_INT, mem, space, H5P_DEFAULT, &bad) < 0 ? -1 : 0;
	H5Sclose(mem);
	if (space >= 0)
		H5Sclose(space);
	if (ds >= 0)
		H5Dclose(ds);
	if (f >= 0)
		H5Fclose(f);
	return rc;
}

static void test_refusals(void)
{
	char path[128], other[128], message[PORO_ERROR_MESSAGE_MAX];
	const char *json = case_json("double_point", "");
	struct case_spec *c = NULL;
	char *dir = harness_temp_dir("checkpoint_test");
	struct sim *s = new_sim(json, &c);
	int ok = dir && s && steps(s, 3) == 0 && checkpoint_write(s, dir) == PORO_OK;
	CHECK(ok, "refusal_fixture", "cannot write a checkpoint: %s", s ? sim_error(s)->message : "no sim");
	if (!ok)
		goto out;
	harness_join(path, sizeof path, dir, CHECKPOINT_NAME);

	/* another case: one value changed */
	char changed[4096];
	snprintf(changed, sizeof changed, "%s", json);
	char *e = strstr(changed, "1.37e6");
	memcpy(e, "1.38e6", 6);
	enum poro_status st = try_load(changed, path, message, sizeof message);
	CHECK(st == PORO_EINVAL && strstr(message, "different case") && strstr(message, "/materials/0/youngs_modulus"),
	      "other_case_refused_naming_difference", "status %d: %s", st, message);

	/* the same case written differently: key order, spacing, 1.37e6 as 1370000.0 */
	snprintf(changed, sizeof changed, "%s", json);
	e = strstr(changed, "\"youngs_modulus\": 1.37e6");
	char rest[4096];
	snprintf(rest, sizeof rest, "%s", e + strlen("\"youngs_modulus\": 1.37e6"));
	snprintf(e, sizeof changed - (size_t)(e - changed), "\"youngs_modulus\":1370000.0%s", rest);
	st = try_load(changed, path, message, sizeof message);
	CHECK(st == PORO_OK, "same_case_other_spelling_accepted", "status %d: %s", st, message);

	/* truncated at half its length */
	struct stat sb;
	stat(path, &sb);
	harness_join(other, sizeof other, dir, "truncated.h5");
	copy_prefix(path, other, (long)sb.st_size / 2);
	st = try_load(json, other, message, sizeof message);
	CHECK(st == PORO_EIO && strstr(message, other), "truncated_checkpoint_refused", "status %d: %s", st, message);

	/* not HDF5 at all */
	harness_join(other, sizeof other, dir, "garbage.h5");
	FILE *f = fopen(other, "wb");
	for (int i = 0; f && i < 4096; i++)
		fputc((int)rnd(0, 256), f);
	if (f)
		fclose(f);
	st = try_load(json, other, message, sizeof message);
	CHECK(st == PORO_EIO && strstr(message, other), "garbage_checkpoint_refused", "status %d: %s", st, message);

	/* a missing file */
	harness_join(other, sizeof other, dir, "no_such_checkpoint.h5");
	st = try_load(json, other, message, sizeof message);
	CHECK(st == PORO_EIO && strstr(message, other), "missing_checkpoint_refused", "status %d: %s", st, message);

	/* a damaged index: a body no case has */
	harness_join(other, sizeof other, dir, "damaged.h5");
	copy_prefix(path, other, (long)sb.st_size);
	ok = damage_body(other) == 0;
	st = try_load(json, other, message, sizeof message);
	CHECK(ok && st == PORO_EINVAL && strstr(message, "/soil/body"), "damaged_body_index_refused",
	      "damaged %d, status %d: %s", ok, st, message);

	/* a result file is not a checkpoint */
	if (sim_run(s, dir, "checkpoint_test", NULL, NULL, NULL) == PORO_OK) {
		harness_join(other, sizeof other, dir, "result.h5");
		st = try_load(json, other, message, sizeof message);
		CHECK(st == PORO_EINVAL && strstr(message, "not a checkpoint"), "result_file_refused", "status %d: %s",
		      st, message);
	}
out:
	sim_destroy(&s);
	case_destroy(&c);
	if (dir)
		harness_remove_dir(dir);
}

/* ---- sim_run: killed after a checkpoint, resumed into the same directory ----------------------- */

static void die_after_checkpoint(const struct sim_progress *p, void *user)
{
	(void)user;
	if (p->checkpoint)
		_exit(0);   /* like kill -9: nothing closed, nothing flushed beyond what the run did */
}

/* A 1-D dataset of doubles, malloc'ed, *n its length; NULL on failure. */
static double *read_series(const char *file, const char *path, long *n)
{
	hid_t f = H5Fopen(file, H5F_ACC_RDONLY, H5P_DEFAULT);
	hid_t ds = f < 0 ? -1 : H5Dopen2(f, path, H5P_DEFAULT);
	hid_t space = ds < 0 ? -1 : H5Dget_space(ds);
	*n = space < 0 ? -1 : (long)H5Sget_simple_extent_npoints(space);
	double *v = *n >= 0 ? malloc(((size_t)*n + 1) * sizeof *v) : NULL;
	if (v && *n > 0 && H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v) < 0) {
		free(v);
		v = NULL;
	}
	if (space >= 0)
		H5Sclose(space);
	if (ds >= 0)
		H5Dclose(ds);
	if (f >= 0)
		H5Fclose(f);
	return v;
}

static void compare_results(const char *ref_dir, const char *dir, const char *phases)
{
	char name[128], ref_path[128], path[128];
	struct results *ra = NULL, *rb = NULL;
	struct poro_error err = {0};
	results_open(&ra, harness_join(ref_path, sizeof ref_path, ref_dir, "result.h5"), &err);
	results_open(&rb, harness_join(path, sizeof path, dir, "result.h5"), &err);
	long fa = ra ? results_frame_count(ra) : -1, fb = rb ? results_frame_count(rb) : -2;
	int same_times = fa == fb && fa > 0;
	for (long k = 0; same_times && k < fa; k++) {
		double ta = -1, tb = -2;
		results_frame_time(ra, k, &ta, &err);
		results_frame_time(rb, k, &tb, &err);
		same_times = ta == tb;
	}
	snprintf(name, sizeof name, "%s_run_resumed_keeps_frame_schedule", phases);
	CHECK(same_times, name, "frames %ld vs %ld uninterrupted, or their times differ: %s", fb, fa, err.message);
	double *xa = NULL, *xb = NULL;
	long na = 0, nb = -1;
	if (same_times) {
		results_frame_read(ra, fa - 1, "soil", "stress", &xa, &na, NULL, &err);
		results_frame_read(rb, fb - 1, "soil", "stress", &xb, &nb, NULL, &err);
	}
	double diff = INFINITY, scale = FIELD_FLOOR;
	if (xa && xb && na == nb) {
		diff = 0.0;
		for (long i = 0; i < 4 * na; i++) {
			diff = fmax(diff, fabs(xa[i] - xb[i]));
			scale = fmax(scale, fabs(xa[i]));
		}
	}
	snprintf(name, sizeof name, "%s_run_resumed_last_frame_matches", phases);
	CHECK(diff / scale <= RESUME_TOLERANCE, name, "stress differs by %.3g relative", diff / scale);
	free(xa);
	free(xb);
	results_close(&ra);
	results_close(&rb);

	const char *probes[] = {"p_base", "settlement", "syy_mid"};
	for (int j = 0; j < 3; j++) {
		char series[96];
		long n_ref = 0, n = -1, v_ref = 0, v_n = -1;
		snprintf(series, sizeof series, "/probes/%s/time", probes[j]);
		double *t_ref = read_series(ref_path, series, &n_ref), *t = read_series(path, series, &n);
		snprintf(series, sizeof series, "/probes/%s/value", probes[j]);
		double *val_ref = read_series(ref_path, series, &v_ref), *val = read_series(path, series, &v_n);
		int ok = t_ref && t && val_ref && val && n == n_ref && v_n == n && v_ref == n_ref;
		double worst = 0.0, scale_v = FIELD_FLOOR;
		for (long i = 0; ok && i < n; i++) {
			ok = t[i] == t_ref[i] && (i == 0 || t[i] > t[i - 1]);
			worst = fmax(worst, fabs(val[i] - val_ref[i]));
			scale_v = fmax(scale_v, fabs(val_ref[i]));
		}
		snprintf(name, sizeof name, "%s_run_resumed_probe_%s_same_samples", phases, probes[j]);
		CHECK(ok && worst / scale_v <= RESUME_TOLERANCE, name,
		      "%ld samples vs %ld uninterrupted, times equal and increasing %d, values differ by %.3g", n,
		      n_ref, ok, worst / scale_v);
		free(t_ref), free(t), free(val_ref), free(val);
	}
}

#define CHILD_FLAG "--run-until-checkpoint"
#define CHECKPOINT_MEMBER ", \"checkpoint\": {\"interval\": 0.0011}"

static void test_run_killed_and_resumed(const char *phases)
{
	char name[128], path[128];
	/* checkpoints every 0.0011 s: at steps 11, 22 and 33; the child dies after the first */
	const char *json = case_json(phases, CHECKPOINT_MEMBER);
	char *ref_dir = harness_temp_dir("checkpoint_test"), *dir = harness_temp_dir("checkpoint_test");
	struct case_spec *c = NULL;
	struct sim *s = new_sim(json, &c);
	int ok = ref_dir && dir && s && sim_run(s, ref_dir, "checkpoint_test", NULL, NULL, NULL) == PORO_OK;
	sim_destroy(&s);
	case_destroy(&c);
	snprintf(name, sizeof name, "%s_run_uninterrupted", phases);
	CHECK(ok, name, "the uninterrupted run failed");
	if (!ok)
		goto out;

	/* a fresh process (fork and exec): the solver's thread pools do not survive a bare fork */
	fflush(stdout);
	pid_t child = fork();
	if (child == 0) {
		execl("/proc/self/exe", "checkpoint_test", CHILD_FLAG, phases, dir, (char *)NULL);
		_exit(4);
	}
	int status = -1;
	waitpid(child, &status, 0);
	snprintf(name, sizeof name, "%s_run_killed_after_checkpoint", phases);
	CHECK(WIFEXITED(status) && WEXITSTATUS(status) == 0, name, "child status %d", status);

	s = new_sim(json, &c);
	enum poro_status st = s ? checkpoint_load(s, harness_join(path, sizeof path, dir, CHECKPOINT_NAME)) : PORO_ENOMEM;
	long resumed_at = s ? sim_steps_taken(s) : -1;
	if (!st)
		st = sim_run(s, dir, "checkpoint_test", NULL, NULL, NULL);
	snprintf(name, sizeof name, "%s_run_resumed_completes", phases);
	CHECK(!st && resumed_at == 11, name, "status %d at step %ld: %s", st, resumed_at,
	      s ? sim_error(s)->message : "");
	if (!st)
		compare_results(ref_dir, dir, phases);
out:
	sim_destroy(&s);
	case_destroy(&c);
	if (ref_dir)
		harness_remove_dir(ref_dir);
	if (dir)
		harness_remove_dir(dir);
}

/* The child of test_run_killed_and_resumed: runs the case into dir until its first checkpoint. */
static int run_until_checkpoint(const char *phases, const char *dir)
{
	struct case_spec *c = NULL;
	struct sim *s = new_sim(case_json(phases, CHECKPOINT_MEMBER), &c);
	if (s)
		sim_run(s, dir, "checkpoint_test", die_after_checkpoint, NULL, NULL);
	return 3;   /* no checkpoint was announced */
}

int main(int argc, char **argv)
{
	if (argc == 4 && !strcmp(argv[1], CHILD_FLAG))
		return run_until_checkpoint(argv[2], argv[3]);
	test_resume("double_point", "double_point", "flip");
	test_resume("single_point", "single_point", "flip");
	test_resume("double_point_apic", "double_point", "apic");
	test_resume("single_point_apic", "single_point", "apic");
	test_resume("double_point_aflip", "double_point", "aflip");
	test_resume("single_point_aflip", "single_point", "aflip");
	test_resume_case("double_point_plate", plate_case_json("double_point"));
	test_resume_case("single_point_plate", plate_case_json("single_point"));
	for (int single = 0; single < 2; single++) {
		char *json = shipped_case_json("tests/cases/dry_embankment.json", single ? "single_point" : "double_point");
		test_resume_case(single ? "single_point_dry_fill" : "double_point_dry_fill", json ? json : "{}");
		free(json);
	}
	/* the other schemes: the explicit one's state is the points' own; the implicit one's adds the
	 * points' accelerations, volumetric strains and reference pressures */
	static const char *const schemes[][2] = {{"explicit", "tests/cases/terzaghi_002.json"},
						  {"implicit_upU", "tests/cases/terzaghi_001.json"}};
	for (int k = 0; k < 2; k++) {
		char *json = shipped_case_json(schemes[k][1], NULL);
		test_resume_case(schemes[k][0], json ? json : "{}");
		free(json);
	}
	test_refusals();
	test_run_killed_and_resumed("double_point");
	test_run_killed_and_resumed("single_point");
	HARNESS_EXIT();
}
