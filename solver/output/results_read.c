/*
 * results_read.c - the results reader (results_read.h): result.h5 opened read-only through HDF5.
 * The layout is schemas/results.md; the object names are the writer's (output_xdmf.h), so the
 * two halves of the contract cannot drift apart.
 *
 * Assumptions, all from the writer: frames are groups /frames/000000, /frames/000001, ... with no
 * gaps; datasets are 1-D or 2-D arrays of doubles; /case "json" and /run "status" are
 * variable-length strings. A frame group that is present but not listed in result.xdmf of a
 * running file is treated as absent (results_read.h).
 *
 * Errors. HDF5 reports a failure by calling the error handler installed on its default stack. The
 * writer installs its own; each public function here installs a recorder for the duration of
 * the call and puts back whatever was there before, so reading never prints and never disturbs
 * the writer's handler in the same process.
 */
#include "results_read.h"

#include <errno.h>
#include <hdf5.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "hdf5_reason.h"

#include "output_xdmf.h"

#define RESULTS_PATH_MAX 512        /* object paths inside result.h5 */
#define RESULTS_XDMF_FRAME "<Time " /* appears once per frame listed in result.xdmf */

struct results {
	char *path;          /* the file as given, for messages */
	hid_t file;
	long frames;         /* frames counted at open (results_read.h) */
	char *case_json;     /* /case "json", NUL-terminated */
};

/* ---- errors ------------------------------------------------------------------------------------ */

/* The caller's HDF5 error handler, put aside for one public call. */
struct handler {
	H5E_auto2_t func;
	void *data;
};

static struct handler quiet_begin(void)
{
	struct handler h = {NULL, NULL};
	H5Eget_auto2(H5E_DEFAULT, &h.func, &h.data);
	H5Eset_auto2(H5E_DEFAULT, hdf5_record_reason, NULL);
	hdf5_reason[0] = '\0';
	return h;
}

/* Restores the handler and passes status through, so a public call ends `return quiet_end(h, st);`. */
static enum poro_status quiet_end(struct handler h, enum poro_status status)
{
	H5Eclear2(H5E_DEFAULT);
	H5Eset_auto2(H5E_DEFAULT, h.func, h.data);
	return status;
}

/* Records "cannot VERB 'OBJECT' in 'FILE': REASON". */
static enum poro_status h5_fail(const char *path, struct poro_error *err, const char *verb, const char *object)
{
	return poro_error_set(err, PORO_EIO, "cannot %s '%s' in '%s'%s%s", verb, object, path,
			      hdf5_reason[0] ? ": " : "", hdf5_reason);
}

static enum poro_status no_memory(struct poro_error *err, const char *what)
{
	return poro_error_set(err, PORO_ENOMEM, "cannot allocate %s", what);
}

/* ---- small HDF5 helpers: each returns < 0 on failure, the reason in hdf5_reason ---------------- */

/* A variable-length string attribute as a newly allocated copy in *out. */
static int read_string_attr(hid_t file, const char *object, const char *name, char **out)
{
	*out = NULL;
	hid_t type = H5Tcopy(H5T_C_S1);
	if (type < 0)
		return -1;
	hid_t a = -1;
	char *v = NULL;
	int rc = H5Tset_size(type, H5T_VARIABLE) < 0 || H5Tset_cset(type, H5T_CSET_UTF8) < 0 ||
		 (a = H5Aopen_by_name(file, object, name, H5P_DEFAULT, H5P_DEFAULT)) < 0 ||
		 H5Aread(a, type, &v) < 0 ? -1 : 0;
	if (!rc && v) {
		*out = malloc(strlen(v) + 1);
		if (*out)
			strcpy(*out, v);
	}
	if (v)
		H5free_memory(v);
	if (a >= 0)
		H5Aclose(a);
	H5Tclose(type);
	return rc;
}

static int read_double_attr(hid_t file, const char *object, const char *name, double *out)
{
	hid_t a = H5Aopen_by_name(file, object, name, H5P_DEFAULT, H5P_DEFAULT);
	if (a < 0)
		return -1;
	int rc = H5Aread(a, H5T_NATIVE_DOUBLE, out) < 0 ? -1 : 0;
	H5Aclose(a);
	return rc;
}

/* ---- opening ----------------------------------------------------------------------------------- */

/* Frame groups present: /frames/000000 onwards, up to the first one missing. */
static long count_frame_groups(hid_t file)
{
	char path[RESULTS_PATH_MAX];
	htri_t has = H5Lexists(file, "/frames", H5P_DEFAULT);
	if (has <= 0)
		return has < 0 ? -1 : 0;
	long n = 0;
	for (;; n++) {
		snprintf(path, sizeof path, OUTPUT_FRAME_FORMAT, n);
		has = H5Lexists(file, path, H5P_DEFAULT);
		if (has <= 0)
			return has < 0 ? -1 : n;
	}
}

/* Frames listed in the result.xdmf next to path, or -1 when it cannot be read. */
static long count_xdmf_frames(const char *path)
{
	const char *slash = strrchr(path, '/');
	int dir_len = slash ? (int)(slash - path) : 1;
	char xdmf[RESULTS_PATH_MAX];
	if (snprintf(xdmf, sizeof xdmf, "%.*s/%s", dir_len, slash ? path : ".", OUTPUT_XDMF_NAME) >=
	    (int)sizeof xdmf)
		return -1;
	FILE *f = fopen(xdmf, "r");
	if (!f)
		return -1;
	/* a line holds at most one element, and <Time .../> is one short line */
	char line[256];
	long n = 0;
	while (fgets(line, sizeof line, f))
		if (strstr(line, RESULTS_XDMF_FRAME))
			n++;
	int failed = ferror(f);
	fclose(f);
	return failed ? -1 : n;
}

/* Frames that count (results_read.h): in a running file, only those result.xdmf lists. */
static enum poro_status count_frames(struct results *r, struct poro_error *err)
{
	r->frames = count_frame_groups(r->file);
	if (r->frames < 0)
		return h5_fail(r->path, err, "list", "/frames");
	char *status = NULL;
	if (read_string_attr(r->file, "/run", "status", &status) < 0)
		return h5_fail(r->path, err, "read", "/run status");
	if (!status)
		return no_memory(err, "the run status");
	if (!strcmp(status, "running")) {
		long listed = count_xdmf_frames(r->path);
		if (listed >= 0 && listed < r->frames)
			r->frames = listed;
	}
	free(status);
	return PORO_OK;
}

/* Opens path read-only, or returns < 0 with the reason in hdf5_reason. */
static hid_t open_read_only(const char *path)
{
	hid_t file = H5I_INVALID_HID, fapl = H5Pcreate(H5P_FILE_ACCESS);
	/* STRONG: closing the file closes anything left open; no locking: the writer takes none */
	if (fapl >= 0 && H5Pset_fclose_degree(fapl, H5F_CLOSE_STRONG) >= 0 &&
	    H5Pset_file_locking(fapl, 0, 1) >= 0)
		file = H5Fopen(path, H5F_ACC_RDONLY, fapl);
	if (fapl >= 0)
		H5Pclose(fapl);
	return file;
}

static enum poro_status open_file(struct results *r, struct poro_error *err)
{
	struct stat sb;
	if (stat(r->path, &sb) != 0)
		return poro_error_set(err, PORO_EIO, "cannot open '%s': %s", r->path, strerror(errno));
	r->file = open_read_only(r->path);
	if (r->file < 0)
		return poro_error_set(err, PORO_EIO, "cannot open '%s'%s%s", r->path, hdf5_reason[0] ? ": " : "",
				      hdf5_reason);
	if (read_string_attr(r->file, "/case", "json", &r->case_json) < 0)
		return h5_fail(r->path, err, "read", "/case json");
	if (!r->case_json)
		return no_memory(err, "the case text");
	return count_frames(r, err);
}

enum poro_status results_open(struct results **out, const char *path, struct poro_error *err)
{
	*out = NULL;
	if (!path)
		return poro_error_set(err, PORO_EINVAL, "cannot open results: no path");
	struct results *r = calloc(1, sizeof *r);
	if (!r || !(r->path = malloc(strlen(path) + 1))) {
		free(r);
		return no_memory(err, "the results reader");
	}
	strcpy(r->path, path);
	r->file = H5I_INVALID_HID;
	struct handler h = quiet_begin();
	enum poro_status st = open_file(r, err);
	if (st)
		results_close(&r);
	*out = r;
	return quiet_end(h, st);
}

/* What an HDF5 file lacks to be a result file, or NULL when it has /case "json" and /run. */
static const char *missing_result_object(hid_t file)
{
	if (H5Lexists(file, "/case", H5P_DEFAULT) <= 0 || H5Aexists_by_name(file, "/case", "json", H5P_DEFAULT) <= 0)
		return "it has no /case json";
	if (H5Lexists(file, "/run", H5P_DEFAULT) <= 0)
		return "it has no /run";
	return NULL;
}

static int is_hdf5(const char *path)
{
#if H5_VERSION_GE(1, 12, 0)
	return H5Fis_accessible(path, H5P_DEFAULT) > 0;
#else
	return H5Fis_hdf5(path) > 0;
#endif
}

enum poro_status results_check_file(const char *path, struct poro_error *err)
{
	struct stat sb;
	if (!path)
		return poro_error_set(err, PORO_EINVAL, "cannot check results: no path");
	FILE *f = fopen(path, "rb");
	if (!f || fstat(fileno(f), &sb) != 0) {
		int e = errno;
		if (f)
			fclose(f);
		return poro_error_set(err, PORO_EIO, "cannot open '%s': %s", path, strerror(e));
	}
	fclose(f);
	if (S_ISDIR(sb.st_mode))
		return poro_error_set(err, PORO_EINVAL, "'%s' is not a result file: it is a directory", path);
	struct handler h = quiet_begin();
	if (!is_hdf5(path))
		return quiet_end(h, poro_error_set(err, PORO_EINVAL, "'%s' is not a result file: not an HDF5 file", path));
	hid_t file = open_read_only(path);
	if (file < 0)
		return quiet_end(h, poro_error_set(err, PORO_EIO, "cannot open '%s'%s%s", path,
						   hdf5_reason[0] ? ": " : "", hdf5_reason));
	const char *missing = missing_result_object(file);
	H5Fclose(file);
	if (missing)
		return quiet_end(h, poro_error_set(err, PORO_EINVAL, "'%s' is not a result file: %s", path, missing));
	return quiet_end(h, PORO_OK);
}

void results_close(struct results **rp)
{
	if (!rp || !*rp)
		return;
	struct results *r = *rp;
	if (r->file >= 0) {
		struct handler h = quiet_begin();
		H5Fclose(r->file);
		quiet_end(h, PORO_OK);
	}
	free(r->case_json);
	free(r->path);
	free(r);
	*rp = NULL;
}

/* ---- frames ------------------------------------------------------------------------------------ */

long results_frame_count(const struct results *r)
{
	return r->frames;
}

const char *results_case_json(const struct results *r)
{
	return r->case_json;
}

static enum poro_status check_frame(const struct results *r, long frame, struct poro_error *err)
{
	if (frame < 0 || frame >= r->frames)
		return poro_error_set(err, PORO_EINVAL, "no frame %ld in '%s': it has %ld frames", frame, r->path,
				      r->frames);
	return PORO_OK;
}

/* path gets the set's group of a frame, after checking both. */
static enum poro_status set_path(const struct results *r, long frame, const char *set, char *path,
				 size_t size, struct poro_error *err)
{
	if (!set || (strcmp(set, "soil") && strcmp(set, "water")))
		return poro_error_set(err, PORO_EINVAL, "unknown point set '%s': expected 'soil' or 'water'",
				      set ? set : "(null)");
	enum poro_status st = check_frame(r, frame, err);
	if (!st)
		snprintf(path, size, OUTPUT_FRAME_FORMAT "/%s", frame, set);
	return st;
}

enum poro_status results_frame_time(struct results *r, long frame, double *time, struct poro_error *err)
{
	char path[RESULTS_PATH_MAX];
	enum poro_status st = check_frame(r, frame, err);
	if (st)
		return st;
	snprintf(path, sizeof path, OUTPUT_FRAME_FORMAT, frame);
	struct handler h = quiet_begin();
	if (read_double_attr(r->file, path, "time", time) < 0) {
		char object[RESULTS_PATH_MAX + 8];
		snprintf(object, sizeof object, "%s time", path);
		st = h5_fail(r->path, err, "read", object);
	}
	return quiet_end(h, st);
}

int results_frame_has_set(struct results *r, long frame, const char *set, struct poro_error *err)
{
	char path[RESULTS_PATH_MAX];
	if (set_path(r, frame, set, path, sizeof path, err))
		return -1;
	struct handler h = quiet_begin();
	htri_t has = H5Lexists(r->file, path, H5P_DEFAULT);
	if (has < 0)
		h5_fail(r->path, err, "look up", path);
	quiet_end(h, PORO_OK);
	return has < 0 ? -1 : has > 0;
}

/* Reads the whole of dataset path as doubles into a new array. */
static enum poro_status read_dataset(const struct results *r, const char *path, double **values, long *rows,
				     int *width, struct poro_error *err)
{
	hid_t ds = H5Dopen2(r->file, path, H5P_DEFAULT);
	if (ds < 0)
		return h5_fail(r->path, err, "open", path);
	hsize_t dims[2] = {0, 1};
	hid_t space = H5Dget_space(ds);
	int rank = space < 0 ? -1 : H5Sget_simple_extent_ndims(space);
	if (rank == 1 || rank == 2)
		rank = H5Sget_simple_extent_dims(space, dims, NULL);
	if (space >= 0)
		H5Sclose(space);
	enum poro_status st = PORO_OK;
	if (rank != 1 && rank != 2)
		st = rank < 0 ? h5_fail(r->path, err, "read", path)
			      : poro_error_set(err, PORO_EIO, "cannot read '%s' in '%s': %d dimensions, expected 1 or 2",
					       path, r->path, rank);
	size_t count = (size_t)dims[0] * (size_t)dims[1];
	double *a = st ? NULL : malloc((count ? count : 1) * sizeof *a);
	if (!st && !a)
		st = no_memory(err, path);
	if (!st && count && H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, a) < 0)
		st = h5_fail(r->path, err, "read", path);
	H5Dclose(ds);
	if (st) {
		free(a);
		return st;
	}
	*values = a;
	*rows = (long)dims[0];
	if (width)
		*width = (int)dims[1];
	return PORO_OK;
}

enum poro_status results_frame_read(struct results *r, long frame, const char *set, const char *name,
				    double **values, long *rows, int *width, struct poro_error *err)
{
	*values = NULL;
	*rows = 0;
	char group[RESULTS_PATH_MAX / 2], path[RESULTS_PATH_MAX];
	enum poro_status st = set_path(r, frame, set, group, sizeof group, err);
	if (st)
		return st;
	if (!name || !*name || strchr(name, '/') || strlen(name) >= sizeof path - sizeof group)
		return poro_error_set(err, PORO_EINVAL, "invalid dataset name '%s'", name ? name : "(null)");
	snprintf(path, sizeof path, "%s/%s", group, name);
	struct handler h = quiet_begin();
	st = read_dataset(r, path, values, rows, width, err);
	return quiet_end(h, st);
}

enum poro_status results_probe_read(struct results *r, const char *name, double **time, double **value,
				    long *count, char **units, struct poro_error *err)
{
	*time = *value = NULL;
	*units = NULL;
	*count = 0;
	char group[RESULTS_PATH_MAX / 2], path[RESULTS_PATH_MAX];
	if (!name || !*name || strchr(name, '/') || strlen(name) >= sizeof group - 16)
		return poro_error_set(err, PORO_EINVAL, "invalid probe name '%s'", name ? name : "(null)");
	snprintf(group, sizeof group, "/probes/%s", name);
	struct handler h = quiet_begin();
	if (H5Lexists(r->file, "/probes", H5P_DEFAULT) <= 0 || H5Lexists(r->file, group, H5P_DEFAULT) <= 0)
		return quiet_end(h, poro_error_set(err, PORO_EINVAL, "no probe '%s' in '%s'", name, r->path));
	long n_time = 0, n_value = 0;
	snprintf(path, sizeof path, "%s/time", group);
	enum poro_status st = read_dataset(r, path, time, &n_time, NULL, err);
	snprintf(path, sizeof path, "%s/value", group);
	if (!st)
		st = read_dataset(r, path, value, &n_value, NULL, err);
	if (!st && read_string_attr(r->file, path, "units", units) < 0)
		st = h5_fail(r->path, err, "read units of", path);
	if (!st && n_time != n_value)
		st = poro_error_set(err, PORO_EIO, "probe '%s' in '%s' has %ld times but %ld values", name, r->path,
				    n_time, n_value);
	if (st) {
		free(*time), free(*value), free(*units);
		*time = *value = NULL;
		*units = NULL;
		return quiet_end(h, st);
	}
	*count = n_time;
	return quiet_end(h, PORO_OK);
}
