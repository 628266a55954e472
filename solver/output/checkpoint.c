/*
 * checkpoint.c - checkpoint.h5, the state a run continues from (checkpoint.h). This file owns the
 * checkpoint layout; schemas/results.md documents it for users:
 *   /                      attributes format ("poro-checkpoint/1"), step, time (s), dt (s),
 *                          water_outflow_mass (kg/m)
 *   /case                  attribute "json": the case as given
 *   /soil/<array>          every saved array of the soil set, N rows x width (1-D for width 1)
 *   /water/<array>         the water set's own arrays: all of them in double point (N_w rows, fewer
 *                          than at the start once water has drained out), only v, mass and pressure
 *                          in single point, where the water rides on the soil points
 *   /probe_point           int32 [probe_count]: the point a point probe follows, -1 for none
 *
 * HDF5 conventions as in output.c: HDF5's default (earliest) format bounds, variable-length UTF-8
 * strings, no file locking, HDF5's error reports caught by hdf5_record_reason and put into the
 * message instead of printed. Values are stored bit for bit (IEEE little-endian doubles), so a
 * resumed run starts from exactly the state the checkpointed run had.
 *
 * Durability: the file is written under a temporary name, flushed and fsync'ed, closed, renamed
 * over checkpoint.h5, and the directory is fsync'ed, so after a crash at any moment checkpoint.h5
 * is the previous complete checkpoint or the new one, never a torn one.
 *
 * Loading trusts nothing in the file: sizes must fit the simulation the case builds, and every
 * index used to address an array (body, load, probe point) is range checked, so a damaged or
 * foreign file gives an error message, not a crash.
 */
#include "checkpoint.h"

#include <errno.h>
#include <fcntl.h>
#include <hdf5.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "hdf5_attr.h"
#include "hdf5_reason.h"
#include "sim_internal.h"

#define CHECKPOINT_PATH_MAX 1024   /* file system paths of the checkpoint and its temporary */
#define OBJECT_PATH_MAX 64         /* object paths inside the file */
#define WHERE_MAX 256              /* JSON pointer of a case difference, for the message */

/* One saved per-point array: a member of struct particles, its per-point width, whether it holds
 * ints (body and load indices) or doubles, and whether a single-point water set owns it (the
 * others alias the soil set's and are saved there). A member that is NULL in a set (the skeleton
 * arrays of a water set) is not saved for that set. */
struct saved_array {
	const char *name;
	size_t member;          /* offsetof(struct particles, member) */
	int width;
	int is_int;
	int owned_by_alias;
};

#define MEMBER(m) offsetof(struct particles, m)

static const struct saved_array saved_arrays[] = {
	{"x", MEMBER(x), 2, 0, 0},
	{"x0", MEMBER(x0), 2, 0, 0},
	{"v", MEMBER(v), 2, 0, 1},
	{"C", MEMBER(C), 4, 0, 1},      /* APIC and AFLIP runs only (NULL, not saved, otherwise) */
	{"mass", MEMBER(mass), 1, 0, 1},
	{"volume", MEMBER(volume), 1, 0, 0},
	{"volume0", MEMBER(volume0), 1, 0, 0},
	{"porosity", MEMBER(porosity), 1, 0, 0},
	{"porosity0", MEMBER(porosity0), 1, 0, 0},
	{"conductivity", MEMBER(conductivity), 1, 0, 0},
	{"pressure", MEMBER(pressure), 1, 0, 1},
	{"body", MEMBER(body), 1, 1, 0},
	{"stress", MEMBER(stress), 4, 0, 0},
	{"F", MEMBER(F), 4, 0, 0},
	{"Be", MEMBER(Be), 4, 0, 0},
	{"state", MEMBER(state), STATE_MAX, 0, 0},
	{"plastic_strain", MEMBER(plastic_strain), 1, 0, 0},
	{"surface", MEMBER(surface), 2, 0, 0},
	{"surface_load", MEMBER(surface_load), 1, 1, 0},
	/* the implicit u-p-U scheme's (NULL, not saved, otherwise); each set owns its own */
	{"acceleration", MEMBER(acceleration), 2, 0, 1},
};

#define SAVED_COUNT (sizeof saved_arrays / sizeof saved_arrays[0])

static void *array_of(const struct particles *p, const struct saved_array *a)
{
	return *(void *const *)((const char *)p + a->member);
}

static int is_saved(const struct particles *p, const struct saved_array *a)
{
	return array_of(p, a) && (!p->alias_of || a->owned_by_alias);
}

/* ---- errors ------------------------------------------------------------------------------------ */

static void reason_clear(void)
{
	hdf5_reason[0] = '\0';
	H5Eclear2(H5E_DEFAULT);
}

/* Records "cannot VERB 'OBJECT' in 'FILE': REASON" (or "cannot VERB 'FILE': REASON" when object
 * is NULL) as code. */
static enum poro_status h5_fail(struct sim *s, enum poro_status code, const char *verb, const char *object,
				const char *file)
{
	char what[OBJECT_PATH_MAX + 8] = "";
	if (object)
		snprintf(what, sizeof what, "'%s' in ", object);
	enum poro_status st = poro_error_set(&s->err, code, "cannot %s %s'%s'%s%s", verb, what, file,
					     hdf5_reason[0] ? ": " : "", hdf5_reason);
	reason_clear();
	return st;
}

/* ---- small HDF5 helpers (hdf5_attr.h): each returns < 0 on failure, the reason in hdf5_reason -- */

static int new_group(hid_t file, const char *path)
{
	return hdf5_group_create(file, path, 0);
}

/* A contiguous dataset of n rows x width (1-D for width 1) of doubles, or of ints if is_int. */
static int put_dataset(hid_t file, const char *path, hsize_t n, int width, int is_int, const void *data)
{
	return hdf5_dataset_write(file, path, n, (hsize_t)width, is_int ? H5T_STD_I32LE : H5T_IEEE_F64LE,
				  is_int ? H5T_NATIVE_INT : H5T_NATIVE_DOUBLE, data);
}

/* Rows of a dataset whose shape must be rows x width (1-D for width 1); -1 on failure or another
 * shape (*shape_ok tells which). */
static long dataset_rows(hid_t ds, int width, int *shape_ok)
{
	hid_t space = H5Dget_space(ds);
	if (space < 0)
		return -1;
	hsize_t dims[2] = {0, 0};
	int rank = H5Sget_simple_extent_ndims(space);
	int ok = (rank == 1 || rank == 2) && H5Sget_simple_extent_dims(space, dims, NULL) == rank;
	H5Sclose(space);
	if (!ok)
		return -1;
	*shape_ok = width == 1 ? rank == 1 : rank == 2 && dims[1] == (hsize_t)width;
	return *shape_ok ? (long)dims[0] : -1;
}

/* ---- writing ----------------------------------------------------------------------------------- */

static enum poro_status write_set(struct sim *s, hid_t file, const char *set, const struct particles *p,
				  const char *tmp)
{
	char path[OBJECT_PATH_MAX];
	snprintf(path, sizeof path, "/%s", set);
	if (new_group(file, path) < 0)
		return h5_fail(s, PORO_EIO, "create", path, tmp);
	for (size_t k = 0; k < SAVED_COUNT; k++) {
		const struct saved_array *a = &saved_arrays[k];
		if (!is_saved(p, a))
			continue;
		snprintf(path, sizeof path, "/%s/%s", set, a->name);
		if (put_dataset(file, path, (hsize_t)p->n, a->width, a->is_int, array_of(p, a)) < 0)
			return h5_fail(s, PORO_EIO, "write", path, tmp);
	}
	return PORO_OK;
}

static enum poro_status write_contents(struct sim *s, hid_t file, const char *tmp)
{
	hid_t root = H5Gopen2(file, "/", H5P_DEFAULT);
	int rc = root < 0 || hdf5_attr_write_string(root, "format", CHECKPOINT_FORMAT) < 0 ||
		 hdf5_attr_write(root, "step", H5T_STD_I64LE, H5T_NATIVE_LONG, &s->step) < 0 ||
		 hdf5_attr_write(root, "time", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &s->time) < 0 ||
		 hdf5_attr_write(root, "dt", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &s->dt) < 0 ||
		 hdf5_attr_write(root, "water_outflow_mass", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE,
			  &s->water_outflow_mass) < 0 ? -1 : 0;
	if (root >= 0 && H5Gclose(root) < 0)
		rc = -1;
	if (rc < 0)
		return h5_fail(s, PORO_EIO, "write", "/", tmp);
	hid_t c = new_group(file, "/case") < 0 ? -1 : H5Gopen2(file, "/case", H5P_DEFAULT);
	rc = c < 0 || hdf5_attr_write_string(c, "json", s->spec->json) < 0 ? -1 : 0;
	if (c >= 0 && H5Gclose(c) < 0)
		rc = -1;
	if (rc < 0)
		return h5_fail(s, PORO_EIO, "write", "/case", tmp);
	enum poro_status st = write_set(s, file, "soil", &s->soil, tmp);
	if (!st)
		st = write_set(s, file, "water", &s->water, tmp);
	if (!st && put_dataset(file, "/probe_point", (hsize_t)s->spec->probe_count, 1, 1, s->probe_point) < 0)
		st = h5_fail(s, PORO_EIO, "write", "/probe_point", tmp);
	return st;
}

/* Flushes HDF5's caches to the kernel and the kernel's to disk. */
static enum poro_status file_sync(struct sim *s, hid_t file, const char *tmp)
{
	void *handle = NULL;
	if (H5Fflush(file, H5F_SCOPE_GLOBAL) < 0 || H5Fget_vfd_handle(file, H5P_DEFAULT, &handle) < 0)
		return h5_fail(s, PORO_EIO, "flush", NULL, tmp);
	if (fsync(*(int *)handle) != 0)   /* the sec2 driver's handle is its file descriptor */
		return poro_error_set(&s->err, PORO_EIO, "cannot flush '%s': %s", tmp, strerror(errno));
	return PORO_OK;
}

/* File access: a close closes every object left open (so the file really is closed), no file
 * locking (a reader may look at the file while a run goes on), as output.c does. */
static hid_t file_access(void)
{
	hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
	if (fapl >= 0 && (H5Pset_fclose_degree(fapl, H5F_CLOSE_STRONG) < 0 || H5Pset_file_locking(fapl, 0, 1) < 0)) {
		H5Pclose(fapl);
		return -1;
	}
	return fapl;
}

/* Makes the rename durable: the directory entry is data of the directory. */
static enum poro_status sync_dir(struct sim *s, const char *dir)
{
	int fd = open(dir, O_RDONLY | O_DIRECTORY);
	if (fd < 0 || fsync(fd) != 0) {
		int e = errno;
		if (fd >= 0)
			close(fd);
		return poro_error_set(&s->err, PORO_EIO, "cannot flush directory '%s': %s", dir, strerror(e));
	}
	close(fd);
	return PORO_OK;
}

enum poro_status checkpoint_write(struct sim *s, const char *dir)
{
	char tmp[CHECKPOINT_PATH_MAX], final[CHECKPOINT_PATH_MAX];
	if (snprintf(tmp, sizeof tmp, "%s/%s", dir, CHECKPOINT_TMP_NAME) >= (int)sizeof tmp ||
	    snprintf(final, sizeof final, "%s/%s", dir, CHECKPOINT_NAME) >= (int)sizeof final)
		return poro_error_set(&s->err, PORO_EIO, "cannot write a checkpoint in '%s': path too long", dir);
	H5Eset_auto2(H5E_DEFAULT, hdf5_record_reason, NULL);
	reason_clear();
	hid_t fapl = file_access();
	hid_t file = fapl < 0 ? -1 : H5Fcreate(tmp, H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
	if (fapl >= 0)
		H5Pclose(fapl);
	if (file < 0)
		return h5_fail(s, PORO_EIO, "create", NULL, tmp);
	enum poro_status st = write_contents(s, file, tmp);
	if (!st)
		st = file_sync(s, file, tmp);
	if (H5Fclose(file) < 0 && !st)
		st = h5_fail(s, PORO_EIO, "close", NULL, tmp);
	if (!st && rename(tmp, final) != 0)
		st = poro_error_set(&s->err, PORO_EIO, "cannot rename '%s' to '%s': %s", tmp, final, strerror(errno));
	if (st) {
		unlink(tmp);   /* the previous checkpoint, if any, stays as it was */
		reason_clear();
		return st;
	}
	return sync_dir(s, dir);
}

/* ---- loading ----------------------------------------------------------------------------------- */

/* Reads dataset path into data, which holds capacity rows; the rows read go to *rows. Rows beyond
 * capacity, another width or another type class are an error (PORO_EINVAL), so a damaged file
 * cannot write past an array. */
static enum poro_status read_dataset(struct sim *s, hid_t file, const char *path, int width, int is_int,
				     void *data, long capacity, long *rows, const char *name)
{
	hid_t ds = H5Dopen2(file, path, H5P_DEFAULT);
	if (ds < 0)
		return h5_fail(s, PORO_EIO, "read", path, name);
	int shape_ok = 0;
	long n = dataset_rows(ds, width, &shape_ok);
	hid_t type = H5Dget_type(ds);
	H5T_class_t cls = type < 0 ? H5T_NO_CLASS : H5Tget_class(type);
	if (type >= 0)
		H5Tclose(type);
	enum poro_status st = PORO_OK;
	if (n < 0 && !shape_ok)
		st = poro_error_set(&s->err, PORO_EINVAL, "cannot read '%s' in '%s': not %d values per point",
				    path, name, width);
	else if (n < 0)
		st = h5_fail(s, PORO_EIO, "read", path, name);
	else if (cls != (is_int ? H5T_INTEGER : H5T_FLOAT))
		st = poro_error_set(&s->err, PORO_EINVAL, "cannot read '%s' in '%s': not %s", path, name,
				    is_int ? "integers" : "floating-point numbers");
	else if (n > capacity)
		st = poro_error_set(&s->err, PORO_EINVAL, "cannot read '%s' in '%s': %ld points, the case "
				    "gives at most %ld", path, name, n, capacity);
	else if (n > 0 && H5Dread(ds, is_int ? H5T_NATIVE_INT : H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL,
				  H5P_DEFAULT, data) < 0)
		st = h5_fail(s, PORO_EIO, "read", path, name);
	H5Dclose(ds);
	*rows = n;
	return st;
}

/* 1 when every v[i] of n lies in [lo, hi). */
static int ints_in(const int *v, long n, int lo, int hi)
{
	for (long i = 0; i < n; i++)
		if (v[i] < lo || v[i] >= hi)
			return 0;
	return 1;
}

/* Reads every saved array of a set into p (capacity points); all must have the same length,
 * which becomes p->n. */
static enum poro_status read_set(struct sim *s, hid_t file, const char *set, struct particles *p, long capacity,
				 const char *name)
{
	char path[OBJECT_PATH_MAX];
	long n = -1;
	for (size_t k = 0; k < SAVED_COUNT; k++) {
		const struct saved_array *a = &saved_arrays[k];
		if (!is_saved(p, a))
			continue;
		long rows = 0;
		snprintf(path, sizeof path, "/%s/%s", set, a->name);
		enum poro_status st = read_dataset(s, file, path, a->width, a->is_int, array_of(p, a), capacity,
						   &rows, name);
		if (st)
			return st;
		if (n >= 0 && rows != n)
			return poro_error_set(&s->err, PORO_EINVAL, "cannot read '%s' in '%s': %ld points, "
					      "other arrays of %s have %ld", path, name, rows, set, n);
		n = rows;
	}
	if (!p->alias_of && !ints_in(p->body, n, 0, s->spec->body_count))
		return poro_error_set(&s->err, PORO_EINVAL, "cannot read '/%s/body' in '%s': a body index "
				      "outside 0 .. %d", set, name, s->spec->body_count - 1);
	if (p->surface_load && !ints_in(p->surface_load, n, -1, s->spec->load_count))
		return poro_error_set(&s->err, PORO_EINVAL, "cannot read '/%s/surface_load' in '%s': a load "
				      "index outside -1 .. %d", set, name, s->spec->load_count - 1);
	p->n = (idx_t)n;
	return PORO_OK;
}

/* The checkpoint must belong to the case s was created from. */
static enum poro_status check_case(struct sim *s, hid_t file, const char *name)
{
	hid_t c = H5Gopen2(file, "/case", H5P_DEFAULT);
	char *json = c < 0 ? NULL : hdf5_attr_read_string(c, "json");
	if (c >= 0)
		H5Gclose(c);
	if (!json)
		return h5_fail(s, PORO_EIO, "read", "/case", name);
	char where[WHERE_MAX];
	int d = case_json_difference(json, s->spec->json, where, sizeof where);
	free(json);
	if (d < 0)
		return poro_error_set(&s->err, PORO_EINVAL, "checkpoint '%s' holds a case that is not JSON", name);
	if (d > 0)
		return poro_error_set(&s->err, PORO_EINVAL, "checkpoint '%s' was written for a different case: "
				      "'%s' differs from the given case", name, where);
	return PORO_OK;
}

/* Format, step and time: a checkpoint of this layout, at a step of this run. */
static enum poro_status read_header(struct sim *s, hid_t file, const char *name, long *step, double *time,
				    double *outflow)
{
	hid_t root = H5Gopen2(file, "/", H5P_DEFAULT);
	char *format = root < 0 ? NULL : hdf5_attr_read_string(root, "format");
	double dt = 0.0;
	int rc = !format || hdf5_attr_read(root, "step", H5T_NATIVE_LONG, step) < 0 ||
		 hdf5_attr_read(root, "time", H5T_NATIVE_DOUBLE, time) < 0 || hdf5_attr_read(root, "dt", H5T_NATIVE_DOUBLE, &dt) < 0 ||
		 hdf5_attr_read(root, "water_outflow_mass", H5T_NATIVE_DOUBLE, outflow) < 0 ? -1 : 0;
	if (root >= 0)
		H5Gclose(root);
	enum poro_status st = PORO_OK;
	if (!format && root >= 0)
		st = poro_error_set(&s->err, PORO_EINVAL, "'%s' is not a checkpoint: it has no 'format' attribute", name);
	else if (format && strcmp(format, CHECKPOINT_FORMAT))
		st = poro_error_set(&s->err, PORO_EINVAL, "'%s' is not a checkpoint of format '%s' (format '%.40s')",
				    name, CHECKPOINT_FORMAT, format);
	else if (rc < 0)
		st = h5_fail(s, PORO_EIO, "read", "/", name);
	else if (dt != s->dt || *step < 0 || *step > s->steps_total || !(fabs(*time - (double)*step * dt) <= 0.5 * dt))
		st = poro_error_set(&s->err, PORO_EINVAL, "checkpoint '%s' is at step %ld, t = %.6g s with dt = %.6g s, "
				    "which this run (%ld steps of %.6g s) does not reach", name, *step, *time, dt,
				    s->steps_total, s->dt);
	free(format);
	return st;
}

/* Probe points index the sets they follow. */
static enum poro_status read_probe_points(struct sim *s, hid_t file, const char *name)
{
	long rows = 0;
	int count = s->spec->probe_count;
	enum poro_status st = read_dataset(s, file, "/probe_point", 1, 1, s->probe_point, count, &rows, name);
	if (!st && rows != count)
		st = poro_error_set(&s->err, PORO_EINVAL, "cannot read '/probe_point' in '%s': %ld probes, the case "
				    "has %d", name, rows, count);
	for (int i = 0; i < count && !st; i++) {
		enum probe_kind kind = s->spec->probes[i].kind;
		long n = kind == PROBE_PORE_PRESSURE ? s->water.n : kind == PROBE_DISPLACEMENT ? s->soil.n : 0;
		int q = s->probe_point[i];
		/* a pore-pressure probe whose point drained out follows none (-1) */
		int ok = kind == PROBE_AVERAGE ? q == -1 : (q >= 0 && q < n) || (kind == PROBE_PORE_PRESSURE && q == -1);
		if (!ok)
			st = poro_error_set(&s->err, PORO_EINVAL, "cannot read '/probe_point' in '%s': probe '%s' "
					    "follows point %d, which its set does not have", name,
					    s->spec->probes[i].name, q);
	}
	return st;
}

static enum poro_status load_contents(struct sim *s, hid_t file, const char *name)
{
	long step = 0;
	double time = 0.0, outflow = 0.0;
	enum poro_status st = read_header(s, file, name, &step, &time, &outflow);
	if (!st)
		st = check_case(s, file, name);
	const long soil_n = s->soil.n, water_n = s->water.n;
	if (!st)
		st = read_set(s, file, "soil", &s->soil, soil_n, name);
	if (!st && s->soil.n != soil_n)
		st = poro_error_set(&s->err, PORO_EINVAL, "checkpoint '%s' has %ld soil points, the case gives %ld",
				    name, (long)s->soil.n, soil_n);
	/* a double-point water set is allocated with one point per soil point of a saturated body
	 * (sim.c) and only loses points; a single-point one rides on exactly those soil points */
	if (!st)
		st = read_set(s, file, "water", &s->water, water_n, name);
	if (!st && !s->double_point && s->water.n != water_n)
		st = poro_error_set(&s->err, PORO_EINVAL, "checkpoint '%s' has %ld water values, the case gives %ld",
				    name, (long)s->water.n, water_n);
	if (!st)
		st = read_probe_points(s, file, name);
	if (st)
		return st;
	s->step = step;
	s->time = time;
	s->water_outflow_mass = outflow;
	s->resumed = 1;
	return PORO_OK;
}

enum poro_status checkpoint_load(struct sim *s, const char *path)
{
	H5Eset_auto2(H5E_DEFAULT, hdf5_record_reason, NULL);
	reason_clear();
	hid_t fapl = file_access();
	hid_t file = fapl < 0 ? -1 : H5Fopen(path, H5F_ACC_RDONLY, fapl);
	if (fapl >= 0)
		H5Pclose(fapl);
	if (file < 0)
		return h5_fail(s, PORO_EIO, "open checkpoint", NULL, path);
	enum poro_status st = load_contents(s, file, path);
	H5Fclose(file);
	reason_clear();
	return st;
}

int checkpoint_resumed(const struct sim *s) { return s->resumed; }
