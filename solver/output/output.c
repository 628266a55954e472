/*
 * output.c - the results writer (output.h): result.h5 through HDF5, result.xdmf through
 * output_xdmf.c. The layout is documented for users in schemas/results.md; this is the only file
 * that includes hdf5.h (STYLE rule 5).
 *
 * Format choices. The file keeps HDF5's default (earliest) format bounds, so every reader built on
 * HDF5 1.8 or later opens it, and a killed run leaves no "open for writing" mark in the superblock
 * (the newer superblock has one, and readers then refuse the file until h5clear). Strings are
 * variable-length UTF-8 (h5py reads them as str); variable-length data lives in the global heap,
 * so the /case "json" attribute is not bound by the 64 kB object-header limit. The writer takes no
 * file lock, so a reader may open result.h5 while the run goes on and sees the last flushed state.
 *
 * Crash safety (output.h). A frame is written as new objects, the buffered probe samples are
 * appended to chunked extendible datasets, the file is flushed and fsync'ed, and only then is
 * result.xdmf rewritten to list the frame. Between two flushes the metadata already on disk is
 * only added to, never moved: the /frames group is created with a local heap large enough for
 * OUTPUT_FRAME_NAMES_HINT bytes of frame names, so adding a frame does not reallocate it, and the
 * probe datasets and the index of frames (/frame_times, /frame_steps, /frame_names) grow in place. So a run killed while it writes a frame loses that frame only.
 * What no HDF5 1.10 file without SWMR (which needs the newest format) can promise is a
 * crash-consistent order of the writes inside one flush; the window is the flush itself, a few
 * milliseconds per frame; in stress runs of the SIGKILL test in tests/solver/output_test.c (550
 * kills at random moments, up to 120 frames into a run) no completed frame was ever damaged.
 *
 * Signs and units: SI throughout; pore pressure is stored internally tension positive
 * (particles.h) and written positive in compression (-pressure).
 */
#include "output.h"

#include <errno.h>
#include <hdf5.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "case.h"
#include "hdf5_attr.h"
#include "hdf5_reason.h"

#include "output_xdmf.h"

#define OUTPUT_PATH_MAX 512             /* object paths inside result.h5 */
#define OUTPUT_FRAME_NAMES_HINT 65536   /* bytes of /frames link names reserved: 8192 frames */
#define OUTPUT_PROBE_CHUNK 512          /* samples per chunk of a probe dataset */
#define OUTPUT_SAMPLES_INITIAL 256      /* first capacity of the probe sample buffer */
/* gzip level of the frames' datasets, with byte shuffling. Measured on the Mohr-Coulomb slope
 * (tests/cases/mc_slope_k1e-3_double_point.json, run to 1 s: 3 frames): result.h5 20.9 MB
 * uncompressed, 8.7 MB at level 1; the run took 1.06 times as long (median of 3 pairs, range
 * 0.93-1.19, one thread). On a 21-frame run of it, levels 4 and 6 made the file only 1.0% and
 * 1.2% smaller than level 1 (schemas/results.md). */
#define OUTPUT_DEFLATE_LEVEL 1

struct output_probe {
	char *name;
	char *units;
	hid_t time;          /* /probes/<name>/time, open for the life of the file */
	hid_t value;         /* /probes/<name>/value */
};

struct output {
	char *dir;
	char *path;                     /* DIR/result.h5, for messages */
	hid_t file;                     /* -1 once closed */
	hid_t string;                   /* variable-length UTF-8 string type */
	int finished;

	int probe_count;
	struct output_probe *probes;    /* [probe_count] */
	double *sample_time;            /* [sample_capacity] samples not yet in the file, s */
	double *sample_value;           /* [sample_capacity * probe_count], sample-major */
	size_t sample_count, sample_capacity;
	hsize_t samples_written;        /* length of every probe dataset */

	struct xdmf_index xdmf;         /* the completed frames, as result.xdmf lists them */
	long frame_next;                /* sequence number of the next frame group */
	double *frame_time;             /* [frame_capacity] time of each listed frame, s (/frame_times) */
	int64_t *frame_step;            /* [frame_capacity] its step (/frame_steps) */
	char (*frame_name)[16];         /* [frame_capacity] its group name under /frames (/frame_names) */
	size_t frame_count, frame_capacity;

	double *scratch;                /* [scratch_capacity] derived fields of one set */
	size_t scratch_capacity;
};

/* ---- errors --------------------------------------------------------------------------------- */

static void reason_clear(void)
{
	hdf5_reason[0] = '\0';
	H5Eclear2(H5E_DEFAULT);
}

/* Records "cannot VERB 'OBJECT' in 'DIR/result.h5': REASON", or without OBJECT (NULL) for the
 * file as a whole "cannot VERB 'DIR/result.h5': REASON". */
static enum poro_status h5_fail(const struct output *o, struct poro_error *err, const char *verb,
				const char *object)
{
	char what[OUTPUT_PATH_MAX + 8];
	if (object)
		snprintf(what, sizeof what, "'%s' in ", object);
	else
		what[0] = '\0';
	enum poro_status st = poro_error_set(err, PORO_EIO, "cannot %s %s'%s'%s%s", verb, what, o->path,
					     hdf5_reason[0] ? ": " : "", hdf5_reason);
	reason_clear();
	return st;
}

static enum poro_status no_memory(struct poro_error *err, const char *what)
{
	return poro_error_set(err, PORO_ENOMEM, "cannot allocate %s", what);
}

/* ---- small HDF5 helpers (hdf5_attr.h): each returns < 0 on failure, the reason in hdf5_reason -- */

static int attr_string(const struct output *o, hid_t loc, const char *name, const char *value)
{
	return hdf5_attr_write(loc, name, o->string, o->string, &value);
}

static int attr_double(hid_t loc, const char *name, double value)
{
	return hdf5_attr_write(loc, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &value);
}

static int attr_long(hid_t loc, const char *name, long value)
{
	return hdf5_attr_write(loc, name, H5T_STD_I64LE, H5T_NATIVE_LONG, &value);
}

/* Attributes on the object at an absolute path. */
static int path_attr_string(const struct output *o, const char *path, const char *name, const char *value)
{
	hid_t obj = H5Oopen(o->file, path, H5P_DEFAULT);
	if (obj < 0)
		return -1;
	int rc = attr_string(o, obj, name, value);
	return H5Oclose(obj) < 0 ? -1 : rc;
}

/* A dataset of n rows and width columns (width 1: 1-D) of file_type, written from data in
 * mem_type, with a "units" attribute when units is not NULL; chunked, shuffled and deflated at
 * OUTPUT_DEFLATE_LEVEL (hdf5_attr.h). */
static int put_dataset(const struct output *o, const char *path, hsize_t n, hsize_t width, hid_t file_type,
		       hid_t mem_type, const void *data, const char *units)
{
	if (hdf5_dataset_write_compressed(o->file, path, n, width, file_type, mem_type, data, OUTPUT_DEFLATE_LEVEL) < 0)
		return -1;
	return units ? path_attr_string(o, path, "units", units) : 0;
}

/* ---- one point set of a frame ------------------------------------------------------------------ */

/* How a written field is obtained from the particle arrays. */
enum derive {
	AS_STORED,         /* the array itself */
	DISPLACEMENT,      /* x - x0, N x 2 */
	COMPRESSION,       /* -pressure: positive in compression */
	PAD_XYZ,           /* an N x 2 array padded with z = 0 to N x 3, for ParaView */
	DISPLACEMENT_XYZ,  /* x - x0 padded the same way */
	FULL_TENSOR,       /* (xx, yy, xy, zz) as the full 3 x 3 tensor, row-major, for ParaView */
};

struct field {
	const char *name;
	int width;
	const char *units;
	enum derive derive;
	size_t array;       /* offsetof(struct particles, source array) */
	int soil_only;      /* skeleton state: the soil set only */
	int water_carried;  /* in double point the water points carry it: not written for the soil */
};

#define ARRAY(member) offsetof(struct particles, member)

/* The datasets of soil/ and water/ (schemas/results.md). The last three are copies in the shapes
 * ParaView's XDMF readers need (3-component vectors, 9-component tensors); output_xdmf.c
 * reads them, pore_pressure, porosity and plastic_strain by these names. */
static const struct field set_fields[] = {
	{"x", 2, "m", AS_STORED, ARRAY(x), 0, 0},
	{"v", 2, "m/s", AS_STORED, ARRAY(v), 0, 0},
	{"displacement", 2, "m", DISPLACEMENT, ARRAY(x), 0, 0},
	{"pore_pressure", 1, "Pa", COMPRESSION, ARRAY(pressure), 0, 1},
	{"porosity", 1, "1", AS_STORED, ARRAY(porosity), 0, 0},
	{"volume", 1, "m^3/m", AS_STORED, ARRAY(volume), 0, 0},
	{"mass", 1, "kg/m", AS_STORED, ARRAY(mass), 0, 0},
	{"stress", 4, "Pa", AS_STORED, ARRAY(stress), 1, 0},
	{"plastic_strain", 1, "1", AS_STORED, ARRAY(plastic_strain), 1, 0},
	{"displacement3", 3, "m", DISPLACEMENT_XYZ, ARRAY(x), 0, 0},
	{"v3", 3, "m/s", PAD_XYZ, ARRAY(v), 0, 0},
	{"stress9", 9, "Pa", FULL_TENSOR, ARRAY(stress), 1, 0},
};

static const double *array_of(const struct particles *p, size_t array)
{
	return *(double *const *)((const char *)p + array);
}

/* The values of field f, either the stored array or derived into scratch [9n]. */
static const double *field_values(const struct field *f, const struct particles *p, double *scratch)
{
	const double *a = array_of(p, f->array);
	idx_t n = p->n;
	switch (f->derive) {
	case AS_STORED:
		return a;
	case DISPLACEMENT:
		for (idx_t i = 0; i < 2 * n; i++)
			scratch[i] = p->x[i] - p->x0[i];
		return scratch;
	case COMPRESSION:
		for (idx_t i = 0; i < n; i++)
			scratch[i] = -a[i];
		return scratch;
	case PAD_XYZ:
	case DISPLACEMENT_XYZ:
		for (idx_t i = 0; i < n; i++) {
			int shift = f->derive == DISPLACEMENT_XYZ;
			scratch[3 * i] = a[2 * i] - (shift ? p->x0[2 * i] : 0.0);
			scratch[3 * i + 1] = a[2 * i + 1] - (shift ? p->x0[2 * i + 1] : 0.0);
			scratch[3 * i + 2] = 0.0;
		}
		return scratch;
	case FULL_TENSOR:
		for (idx_t i = 0; i < n; i++) {
			double xx = a[4 * i], yy = a[4 * i + 1], xy = a[4 * i + 2], zz = a[4 * i + 3];
			double full[9] = {xx, xy, 0.0, xy, yy, 0.0, 0.0, 0.0, zz};
			memcpy(scratch + 9 * i, full, sizeof full);
		}
		return scratch;
	}
	return a;
}

static enum poro_status scratch_reserve(struct output *o, size_t count, struct poro_error *err)
{
	if (count <= o->scratch_capacity)
		return PORO_OK;
	double *s = realloc(o->scratch, count * sizeof *s);
	if (!s)
		return no_memory(err, "the output scratch space");
	o->scratch = s;
	o->scratch_capacity = count;
	return PORO_OK;
}

/* The Polyvertex connectivity 0 .. n-1 that result.xdmf needs for a set of n points, written once
 * per distinct n. */
static enum poro_status points_index(struct output *o, long n, struct poro_error *err)
{
	char path[OUTPUT_PATH_MAX];
	snprintf(path, sizeof path, OUTPUT_POINTS_FORMAT, n);
	htri_t exists = H5Lexists(o->file, path, H5P_DEFAULT);
	if (exists > 0)
		return PORO_OK;
	if (exists < 0)
		return h5_fail(o, err, "look up", path);
	int32_t *index = malloc((n > 0 ? (size_t)n : 1) * sizeof *index);
	if (!index)
		return no_memory(err, "the xdmf point index");
	for (long i = 0; i < n; i++)
		index[i] = (int32_t)i;
	int rc = put_dataset(o, path, (hsize_t)n, 1, H5T_STD_I32LE, H5T_NATIVE_INT32, index, NULL);
	free(index);
	return rc < 0 ? h5_fail(o, err, "write", path) : PORO_OK;
}

/* double_point: the frame has a water set of its own, whose points carry the pore pressure; the
 * soil points' pressure array is then unused (all zero), and writing it gave readers a soil
 * pore_pressure of -0 everywhere. */
static enum poro_status write_set(struct output *o, const char *frame_path, const char *set,
				  const struct particles *p, int double_point, struct poro_error *err)
{
	int soil = strcmp(set, "soil") == 0;
	char group[OUTPUT_PATH_MAX / 2], path[OUTPUT_PATH_MAX];
	snprintf(group, sizeof group, "%s/%s", frame_path, set);
	if (!p->x || !p->x0 || !p->v || !p->pressure || !p->porosity || !p->volume || !p->mass ||
	    (soil && (!p->stress || !p->plastic_strain)))
		return poro_error_set(err, PORO_EINVAL, "cannot write '%s': the point set lacks an array",
				      group);
	enum poro_status st = scratch_reserve(o, 9 * (size_t)p->n, err);
	if (st)
		return st;
	if (hdf5_group_create(o->file, group, 0) < 0)
		return h5_fail(o, err, "create", group);
	for (size_t k = 0; k < sizeof set_fields / sizeof set_fields[0]; k++) {
		const struct field *f = &set_fields[k];
		if ((f->soil_only && !soil) || (f->water_carried && soil && double_point))
			continue;
		snprintf(path, sizeof path, "%s/%s", group, f->name);
		const double *values = field_values(f, p, o->scratch);
		if (put_dataset(o, path, (hsize_t)p->n, (hsize_t)f->width, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE,
				values, f->units) < 0)
			return h5_fail(o, err, "write", path);
	}
	snprintf(path, sizeof path, "%s/stress", group);
	if (soil && path_attr_string(o, path, "components", "xx yy xy zz") < 0)
		return h5_fail(o, err, "write", path);
	return points_index(o, p->n, err);
}

/* ---- probes ------------------------------------------------------------------------------------ */

static hid_t probe_dataset(const struct output *o, const char *path, const char *units)
{
	hsize_t zero = 0, unlimited = H5S_UNLIMITED, chunk = OUTPUT_PROBE_CHUNK;
	hid_t space = H5Screate_simple(1, &zero, &unlimited);
	hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
	hid_t ds = -1;
	if (space >= 0 && dcpl >= 0 && H5Pset_chunk(dcpl, 1, &chunk) >= 0)
		ds = H5Dcreate2(o->file, path, H5T_IEEE_F64LE, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
	if (ds >= 0 && attr_string(o, ds, "units", units) < 0) {
		H5Dclose(ds);
		ds = -1;
	}
	if (dcpl >= 0)
		H5Pclose(dcpl);
	if (space >= 0)
		H5Sclose(space);
	return ds;
}

static enum poro_status probes_create(struct output *o, struct poro_error *err)
{
	char path[OUTPUT_PATH_MAX];
	for (int j = 0; j < o->probe_count; j++) {
		struct output_probe *pr = &o->probes[j];
		snprintf(path, sizeof path, "/probes/%s", pr->name);
		if (hdf5_group_create(o->file, path, 0) < 0)
			return h5_fail(o, err, "create", path);
		snprintf(path, sizeof path, "/probes/%s/time", pr->name);
		if ((pr->time = probe_dataset(o, path, "s")) < 0)
			return h5_fail(o, err, "create", path);
		snprintf(path, sizeof path, "/probes/%s/value", pr->name);
		if ((pr->value = probe_dataset(o, path, pr->units)) < 0)
			return h5_fail(o, err, "create", path);
	}
	return PORO_OK;
}

/* Writes count values, taken every stride from values, at [start, start + count) of ds, extending
 * it to start + count. */
static int probe_append(hid_t ds, hsize_t start, hsize_t count, const double *values, hsize_t stride)
{
	hsize_t end = start + count, mem_n = (count - 1) * stride + 1, zero = 0, one = 1;
	if (H5Dset_extent(ds, &end) < 0)
		return -1;
	hid_t file_space = H5Dget_space(ds);
	hid_t mem_space = H5Screate_simple(1, &mem_n, NULL);
	int rc = file_space < 0 || mem_space < 0 ||
		 H5Sselect_hyperslab(file_space, H5S_SELECT_SET, &start, NULL, &count, NULL) < 0 ||
		 H5Sselect_hyperslab(mem_space, H5S_SELECT_SET, &zero, &stride, &count, &one) < 0 ||
		 H5Dwrite(ds, H5T_NATIVE_DOUBLE, mem_space, file_space, H5P_DEFAULT, values) < 0 ? -1 : 0;
	if (mem_space >= 0)
		H5Sclose(mem_space);
	if (file_space >= 0)
		H5Sclose(file_space);
	return rc;
}

/* Moves the buffered samples into the file. Every probe is written at the same offset, so a
 * retry after a partial failure rewrites the same range. */
static enum poro_status probes_write(struct output *o, struct poro_error *err)
{
	if (o->sample_count == 0)
		return PORO_OK;
	char path[OUTPUT_PATH_MAX];
	hsize_t n = o->sample_count, stride = (hsize_t)o->probe_count;
	for (int j = 0; j < o->probe_count; j++) {
		struct output_probe *pr = &o->probes[j];
		if (probe_append(pr->time, o->samples_written, n, o->sample_time, 1) < 0) {
			snprintf(path, sizeof path, "/probes/%s/time", pr->name);
			return h5_fail(o, err, "write", path);
		}
		if (probe_append(pr->value, o->samples_written, n, o->sample_value + j, stride) < 0) {
			snprintf(path, sizeof path, "/probes/%s/value", pr->name);
			return h5_fail(o, err, "write", path);
		}
	}
	o->samples_written += n;
	o->sample_count = 0;
	return PORO_OK;
}

enum poro_status output_probe_sample(struct output *o, double time, const double *values,
				     struct poro_error *err)
{
	if (!o || o->finished)
		return poro_error_set(err, PORO_EINVAL, "cannot sample probes: the output is closed");
	if (o->probe_count == 0)
		return PORO_OK;
	if (o->sample_count == o->sample_capacity) {
		size_t cap = o->sample_capacity ? 2 * o->sample_capacity : OUTPUT_SAMPLES_INITIAL;
		double *t = realloc(o->sample_time, cap * sizeof *t);
		if (t)
			o->sample_time = t;
		double *v = t ? realloc(o->sample_value, cap * (size_t)o->probe_count * sizeof *v) : NULL;
		if (!v)
			return no_memory(err, "the probe sample buffer");
		o->sample_value = v;
		o->sample_capacity = cap;
	}
	o->sample_time[o->sample_count] = time;
	memcpy(o->sample_value + o->sample_count * (size_t)o->probe_count, values,
	       (size_t)o->probe_count * sizeof *values);
	o->sample_count++;
	return PORO_OK;
}

/* ---- the index of frames: /frame_times, /frame_steps, /frame_names ---------------------------- */

/* One extendible 1-D dataset of the index (chunked: it grows by a row per frame). */
static int index_dataset(const struct output *o, const char *path, hid_t type, const char *units)
{
	hsize_t zero = 0, unlimited = H5S_UNLIMITED, chunk = 256;
	hid_t space = H5Screate_simple(1, &zero, &unlimited);
	hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
	hid_t ds = -1;
	if (space >= 0 && dcpl >= 0 && H5Pset_chunk(dcpl, 1, &chunk) >= 0)
		ds = H5Dcreate2(o->file, path, type, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
	int rc = ds < 0 || (units && attr_string(o, ds, "units", units) < 0) ? -1 : 0;
	if (ds >= 0 && H5Dclose(ds) < 0)
		rc = -1;
	if (dcpl >= 0)
		H5Pclose(dcpl);
	if (space >= 0)
		H5Sclose(space);
	return rc;
}

/* Sets an index dataset to the listed frames' values, created first if the file has none (a file
 * written before the index existed, continued by a resumed run). */
static int index_put(const struct output *o, const char *path, hid_t file_type, hid_t mem_type, const char *units,
		     const void *values)
{
	htri_t exists = H5Lexists(o->file, path, H5P_DEFAULT);
	if (exists < 0 || (!exists && index_dataset(o, path, file_type, units) < 0))
		return -1;
	hid_t ds = H5Dopen2(o->file, path, H5P_DEFAULT);
	hsize_t n = o->frame_count;
	int rc = ds < 0 || H5Dset_extent(ds, &n) < 0 ||
		 (n > 0 && H5Dwrite(ds, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, values) < 0) ? -1 : 0;
	if (ds >= 0 && H5Dclose(ds) < 0)
		rc = -1;
	return rc;
}

/* Writes the whole index (a few bytes per frame, at most CASE_FRAMES_MAX frames: rewriting it is
 * cheaper than keeping appends and cuts in step). */
static enum poro_status index_write(struct output *o, struct poro_error *err)
{
	hid_t name_type = H5Tcopy(H5T_C_S1);
	int rc = name_type < 0 || H5Tset_size(name_type, sizeof o->frame_name[0]) < 0 ? -1 : 0;
	if (!rc && index_put(o, "/frame_times", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, "s", o->frame_time) < 0)
		rc = -1;
	if (!rc && index_put(o, "/frame_steps", H5T_STD_I64LE, H5T_NATIVE_INT64, NULL, o->frame_step) < 0)
		rc = -1;
	if (!rc && index_put(o, "/frame_names", name_type, name_type, NULL, o->frame_name) < 0)
		rc = -1;
	if (name_type >= 0)
		H5Tclose(name_type);
	return rc < 0 ? h5_fail(o, err, "write", "/frame_times") : PORO_OK;
}

/* Adds a listed frame to the index in memory. */
static enum poro_status index_add(struct output *o, long sequence, double time, long step, struct poro_error *err)
{
	if (o->frame_count == o->frame_capacity) {
		size_t cap = o->frame_capacity ? 2 * o->frame_capacity : 64;
		double *t = realloc(o->frame_time, cap * sizeof *t);
		if (t)
			o->frame_time = t;
		int64_t *k = t ? realloc(o->frame_step, cap * sizeof *k) : NULL;
		if (k)
			o->frame_step = k;
		char (*names)[16] = k ? realloc(o->frame_name, cap * sizeof *names) : NULL;
		if (!names)
			return no_memory(err, "the frame index");
		o->frame_name = names;
		o->frame_capacity = cap;
	}
	o->frame_time[o->frame_count] = time;
	o->frame_step[o->frame_count] = step;
	memset(o->frame_name[o->frame_count], 0, sizeof o->frame_name[0]);
	snprintf(o->frame_name[o->frame_count], sizeof o->frame_name[0], "%06ld", sequence);
	o->frame_count++;
	return PORO_OK;
}

/* ---- file -------------------------------------------------------------------------------------- */

/* Makes what has been written so far durable: HDF5's caches to the kernel, then the kernel's to disk. */
static enum poro_status file_sync(struct output *o, struct poro_error *err)
{
	void *handle = NULL;
	if (H5Fflush(o->file, H5F_SCOPE_GLOBAL) < 0 || H5Fget_vfd_handle(o->file, H5P_DEFAULT, &handle) < 0)
		return h5_fail(o, err, "flush", NULL);
	if (fsync(*(int *)handle) != 0) /* the sec2 driver's handle is its file descriptor */
		return poro_error_set(err, PORO_EIO, "cannot flush '%s': %s", o->path, strerror(errno));
	return PORO_OK;
}

static void iso_time_now(char *buf, size_t size)
{
	time_t now = time(NULL);
	struct tm tm;
	if (!gmtime_r(&now, &tm) || !strftime(buf, size, "%Y-%m-%dT%H:%M:%SZ", &tm))
		snprintf(buf, size, "unknown");
}

static enum poro_status file_create(struct output *o, const char *case_json, const char *solver_version,
				    struct poro_error *err)
{
	hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
	/* STRONG: H5Fclose closes every object left open, so the file is really closed;
	 * no locking: readers may open the file during the run */
	if (fapl >= 0 && H5Pset_fclose_degree(fapl, H5F_CLOSE_STRONG) >= 0 &&
	    H5Pset_file_locking(fapl, 0, 1) >= 0)
		o->file = H5Fcreate(o->path, H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
	if (fapl >= 0)
		H5Pclose(fapl);
	if (o->file < 0)
		return h5_fail(o, err, "create", NULL);
	o->string = H5Tcopy(H5T_C_S1);
	if (o->string < 0 || H5Tset_size(o->string, H5T_VARIABLE) < 0 ||
	    H5Tset_cset(o->string, H5T_CSET_UTF8) < 0)
		return h5_fail(o, err, "create", "string type");
	if (hdf5_group_create(o->file, "/case", 0) < 0 || path_attr_string(o, "/case", "json", case_json) < 0)
		return h5_fail(o, err, "write", "/case");
	char now[32];
	iso_time_now(now, sizeof now);
	if (hdf5_group_create(o->file, "/run", 0) < 0 ||
	    path_attr_string(o, "/run", "solver_version", solver_version) < 0 ||
	    path_attr_string(o, "/run", "start_time", now) < 0 ||
	    path_attr_string(o, "/run", "status", "running") < 0)
		return h5_fail(o, err, "write", "/run");
	if (hdf5_group_create(o->file, "/frames", OUTPUT_FRAME_NAMES_HINT) < 0)
		return h5_fail(o, err, "create", "/frames");
	if (hdf5_group_create(o->file, "/probes", 0) < 0)
		return h5_fail(o, err, "create", "/probes");
	if (hdf5_group_create(o->file, "/xdmf", 0) < 0)
		return h5_fail(o, err, "create", "/xdmf");
	enum poro_status st = probes_create(o, err);
	if (!st)
		st = index_write(o, err);   /* empty until the first frame */
	return st ? st : file_sync(o, err);
}

/* Probe names become HDF5 link names: no '/', not "." or "..", unique. */
static enum poro_status check_probes(int count, const char *const *names, const char *const *units,
				     struct poro_error *err)
{
	if (count < 0 || (count > 0 && (!names || !units)))
		return poro_error_set(err, PORO_EINVAL, "invalid probe list");
	for (int j = 0; j < count; j++) {
		const char *s = names[j];
		if (!s || !*s || strchr(s, '/') || !strcmp(s, ".") || !strcmp(s, "..") ||
		    strlen(s) > OUTPUT_PATH_MAX / 2)
			return poro_error_set(err, PORO_EINVAL, "invalid probe name '%s'", s ? s : "(null)");
		if (!units[j])
			return poro_error_set(err, PORO_EINVAL, "probe '%s' has no units", s);
		for (int k = 0; k < j; k++)
			if (!strcmp(names[k], s))
				return poro_error_set(err, PORO_EINVAL, "duplicate probe name '%s'", s);
	}
	return PORO_OK;
}

static char *copy(const char *s)
{
	char *c = malloc(strlen(s) + 1);
	return c ? strcpy(c, s) : NULL;
}

static enum poro_status probes_init(struct output *o, int count, const char *const *names,
				    const char *const *units, struct poro_error *err)
{
	o->probes = calloc(count > 0 ? (size_t)count : 1, sizeof *o->probes);
	if (!o->probes)
		return no_memory(err, "the probe list");
	o->probe_count = count;
	for (int j = 0; j < count; j++) {
		o->probes[j].time = o->probes[j].value = H5I_INVALID_HID;
		o->probes[j].name = copy(names[j]);
		o->probes[j].units = copy(units[j]);
		if (!o->probes[j].name || !o->probes[j].units)
			return no_memory(err, "the probe list");
	}
	return PORO_OK;
}

/* The writer without its file: arguments checked, probe list copied, paths made. */
static enum poro_status writer_new(struct output **out, const char *dir, const char *case_json,
				   const char *solver_version, int probe_count, const char *const *probe_names,
				   const char *const *probe_units, struct poro_error *err)
{
	*out = NULL;
	if (!dir || !case_json || !solver_version)
		return poro_error_set(err, PORO_EINVAL, "cannot create results: no directory, case or version");
	enum poro_status st = check_probes(probe_count, probe_names, probe_units, err);
	if (st)
		return st;
	struct stat sb;
	if (stat(dir, &sb) != 0)
		return poro_error_set(err, PORO_EIO, "cannot create results in '%s': %s", dir, strerror(errno));
	if (!S_ISDIR(sb.st_mode))
		return poro_error_set(err, PORO_EIO, "cannot create results in '%s': not a directory", dir);
	/* the library never prints: HDF5's error reports are recorded for h5_fail() instead */
	H5Eset_auto2(H5E_DEFAULT, hdf5_record_reason, NULL);
	reason_clear();

	struct output *o = calloc(1, sizeof *o);
	if (!o)
		return no_memory(err, "the output writer");
	o->file = o->string = H5I_INVALID_HID;
	size_t len = strlen(dir) + sizeof "/" OUTPUT_H5_NAME;
	o->dir = copy(dir);
	o->path = malloc(len);
	if (!o->dir || !o->path) {
		output_destroy(&o);
		return no_memory(err, "the output writer");
	}
	snprintf(o->path, len, "%s/%s", dir, OUTPUT_H5_NAME);
	st = probes_init(o, probe_count, probe_names, probe_units, err);
	if (st) {
		output_destroy(&o);
		return st;
	}
	*out = o;
	return PORO_OK;
}

enum poro_status output_create(struct output **out, const char *dir, const char *case_json,
			       const char *solver_version, int probe_count, const char *const *probe_names,
			       const char *const *probe_units, struct poro_error *err)
{
	enum poro_status st = writer_new(out, dir, case_json, solver_version, probe_count, probe_names,
					 probe_units, err);
	if (!st && (st = file_create(*out, case_json, solver_version, err)))
		output_destroy(out);
	return st;
}

/* ---- frames ------------------------------------------------------------------------------------ */

static enum poro_status frame_groups(struct output *o, const char *path, const struct output_frame *f,
				     struct poro_error *err)
{
	if (hdf5_group_create(o->file, path, 0) < 0)
		return h5_fail(o, err, "create", path);
	hid_t g = H5Gopen2(o->file, path, H5P_DEFAULT);
	int rc = g < 0 || attr_double(g, "time", f->time) < 0 || attr_long(g, "step", f->step) < 0 ? -1 : 0;
	if (g >= 0 && H5Gclose(g) < 0)
		rc = -1;
	if (rc < 0)
		return h5_fail(o, err, "write", path);
	enum poro_status st = write_set(o, path, "soil", f->soil, f->water != NULL, err);
	if (!st && f->water)
		st = write_set(o, path, "water", f->water, 1, err);
	return st;
}

enum poro_status output_frame_write(struct output *o, const struct output_frame *f, struct poro_error *err)
{
	if (!o || o->finished)
		return poro_error_set(err, PORO_EINVAL, "cannot write a frame: the output is closed");
	if (!f || !f->soil)
		return poro_error_set(err, PORO_EINVAL, "cannot write a frame without a soil point set");
	char path[OUTPUT_PATH_MAX];
	snprintf(path, sizeof path, OUTPUT_FRAME_FORMAT, o->frame_next);
	reason_clear();
	enum poro_status st = frame_groups(o, path, f, err);
	if (!st)
		st = index_add(o, o->frame_next, f->time, f->step, err);
	if (!st && (st = index_write(o, err)))
		o->frame_count--;
	if (!st)
		st = probes_write(o, err);
	if (!st)
		st = file_sync(o, err);
	if (st) {
		/* best effort: leave no half frame behind, so the next one can take its number */
		H5Ldelete(o->file, path, H5P_DEFAULT);
		reason_clear();
		return st;
	}
	struct xdmf_frame listed = {o->frame_next++, f->time, f->soil->n, f->water ? f->water->n : -1};
	st = xdmf_index_add(&o->xdmf, &listed, err);
	return st ? st : xdmf_index_write(&o->xdmf, o->dir, err);
}

/* ---- continuing a file (a resumed run) ------------------------------------------------------- */

/* Cuts every probe series back to its samples at times <= keep_until; all must keep as many. */
static enum poro_status probes_cut(struct output *o, double keep_until, struct poro_error *err)
{
	char path[OUTPUT_PATH_MAX];
	for (int j = 0; j < o->probe_count; j++) {
		struct output_probe *pr = &o->probes[j];
		snprintf(path, sizeof path, "/probes/%s/time", pr->name);
		pr->time = H5Dopen2(o->file, path, H5P_DEFAULT);
		snprintf(path, sizeof path, "/probes/%s/value", pr->name);
		pr->value = pr->time < 0 ? -1 : H5Dopen2(o->file, path, H5P_DEFAULT);
		if (pr->value < 0)
			return h5_fail(o, err, "open", path);
		hid_t space = H5Dget_space(pr->time), vspace = H5Dget_space(pr->value);
		hssize_t n = space < 0 ? -1 : H5Sget_simple_extent_npoints(space);
		hssize_t nv = vspace < 0 ? -1 : H5Sget_simple_extent_npoints(vspace);
		if (space >= 0)
			H5Sclose(space);
		if (vspace >= 0)
			H5Sclose(vspace);
		double *t = n >= 0 ? malloc(((size_t)n + 1) * sizeof *t) : NULL;
		if (!t || (n > 0 && H5Dread(pr->time, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, t) < 0)) {
			free(t);
			snprintf(path, sizeof path, "/probes/%s/time", pr->name);
			return n < 0 ? h5_fail(o, err, "read", path) : no_memory(err, "a probe series");
		}
		hsize_t keep = 0;   /* samples are in time order: keep the leading ones */
		while ((hssize_t)keep < n && t[keep] <= keep_until)
			keep++;
		free(t);
		if (nv < (hssize_t)keep || (j > 0 && keep != o->samples_written))
			return poro_error_set(err, PORO_EINVAL, "cannot continue '%s': probe '%s' has %lld samples "
					      "up to the checkpoint, %lld values, other probes %llu", o->path, pr->name,
					      (long long)keep, (long long)nv, (unsigned long long)o->samples_written);
		if (H5Dset_extent(pr->time, &keep) < 0 || H5Dset_extent(pr->value, &keep) < 0)
			return h5_fail(o, err, "cut", path);
		o->samples_written = keep;
	}
	return PORO_OK;
}

/* Points in <frame>/<set>/x, -1 when the set is absent or unreadable. */
static long set_points(const struct output *o, const char *frame, const char *set)
{
	char path[OUTPUT_PATH_MAX];
	snprintf(path, sizeof path, "%s/%s/x", frame, set);
	if (H5Lexists(o->file, frame, H5P_DEFAULT) <= 0 || H5Lexists(o->file, path, H5P_DEFAULT) <= 0)
		return -1;
	hid_t ds = H5Dopen2(o->file, path, H5P_DEFAULT);
	hid_t space = ds < 0 ? -1 : H5Dget_space(ds);
	hsize_t dims[2] = {0, 0};
	int rank = space < 0 ? -1 : H5Sget_simple_extent_dims(space, dims, NULL);
	if (space >= 0)
		H5Sclose(space);
	if (ds >= 0)
		H5Dclose(ds);
	return rank == 2 ? (long)dims[0] : -1;
}

/* Keeps the frames at times <= keep_until, in sequence order, and lists them in the xdmf index;
 * deletes the rest (later frames, and one a killed run left half written). */
static enum poro_status frames_cut(struct output *o, double keep_until, struct poro_error *err)
{
	H5G_info_t info;
	if (H5Gget_info_by_name(o->file, "/frames", &info, H5P_DEFAULT) < 0)
		return h5_fail(o, err, "open", "/frames");
	/* the names first: deleting links while walking them by index would skip some */
	char (*names)[16] = calloc(info.nlinks + 1, sizeof *names);
	if (!names)
		return no_memory(err, "the frame list");
	enum poro_status st = PORO_OK;
	for (hsize_t i = 0; i < info.nlinks && !st; i++)
		if (H5Lget_name_by_idx(o->file, "/frames", H5_INDEX_NAME, H5_ITER_INC, i, names[i], sizeof names[i],
				       H5P_DEFAULT) < 0)
			st = h5_fail(o, err, "list", "/frames");
	int keeping = 1;
	for (hsize_t i = 0; i < info.nlinks && !st; i++) {
		char path[OUTPUT_PATH_MAX];
		snprintf(path, sizeof path, "/frames/%s", names[i]);
		double time = 0.0;
		long step = 0;
		long soil_n = set_points(o, path, "soil");
		long index = strtol(names[i], NULL, 10);
		hid_t a = H5Aopen_by_name(o->file, path, "time", H5P_DEFAULT, H5P_DEFAULT);
		int ok = a >= 0 && H5Aread(a, H5T_NATIVE_DOUBLE, &time) >= 0;
		if (a >= 0)
			H5Aclose(a);
		a = ok ? H5Aopen_by_name(o->file, path, "step", H5P_DEFAULT, H5P_DEFAULT) : -1;
		ok = ok && a >= 0 && H5Aread(a, H5T_NATIVE_LONG, &step) >= 0;
		if (a >= 0)
			H5Aclose(a);
		reason_clear();   /* a frame that cannot be read is dropped, not an error */
		keeping = keeping && ok && soil_n >= 0 && time <= keep_until;
		if (!keeping) {
			if (H5Ldelete(o->file, path, H5P_DEFAULT) < 0)
				st = h5_fail(o, err, "delete", path);
			continue;
		}
		long water_n = set_points(o, path, "water");   /* -1: single point */
		reason_clear();
		struct xdmf_frame listed = {index, time, soil_n, water_n};
		st = xdmf_index_add(&o->xdmf, &listed, err);
		if (!st)
			st = index_add(o, index, time, step, err);
		o->frame_next = index + 1;
	}
	free(names);
	return st ? st : index_write(o, err);
}

static enum poro_status file_reopen(struct output *o, const char *case_json, const char *solver_version,
				    double keep_until, struct poro_error *err)
{
	hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
	if (fapl >= 0 && H5Pset_fclose_degree(fapl, H5F_CLOSE_STRONG) >= 0 && H5Pset_file_locking(fapl, 0, 1) >= 0)
		o->file = H5Fopen(o->path, H5F_ACC_RDWR, fapl);
	if (fapl >= 0)
		H5Pclose(fapl);
	if (o->file < 0)
		return h5_fail(o, err, "open", NULL);
	o->string = H5Tcopy(H5T_C_S1);
	if (o->string < 0 || H5Tset_size(o->string, H5T_VARIABLE) < 0 || H5Tset_cset(o->string, H5T_CSET_UTF8) < 0)
		return h5_fail(o, err, "create", "string type");
	char *stored = NULL, where[OUTPUT_PATH_MAX];
	hid_t a = H5Aopen_by_name(o->file, "/case", "json", H5P_DEFAULT, H5P_DEFAULT);
	int rc = a < 0 || H5Aread(a, o->string, &stored) < 0 || !stored ? -1 : 0;
	if (a >= 0)
		H5Aclose(a);
	if (rc < 0)
		return h5_fail(o, err, "read", "/case");
	int d = case_json_difference(stored, case_json, where, sizeof where);
	H5free_memory(stored);
	if (d)
		return poro_error_set(err, PORO_EINVAL, "cannot continue '%s': it holds the results of a different "
				      "case ('%s' differs)", o->path, d > 0 ? where : "/case");
	hid_t run = H5Gopen2(o->file, "/run", H5P_DEFAULT);
	rc = run < 0 || attr_string(o, run, "status", "running") < 0 ||
	     attr_string(o, run, "solver_version", solver_version) < 0 ||
	     attr_double(run, "resumed_from_time", keep_until) < 0 ? -1 : 0;
	if (run >= 0 && H5Gclose(run) < 0)
		rc = -1;
	if (rc < 0)
		return h5_fail(o, err, "write", "/run");
	enum poro_status st = probes_cut(o, keep_until, err);
	if (!st)
		st = frames_cut(o, keep_until, err);
	if (!st)
		st = file_sync(o, err);
	return st ? st : xdmf_index_write(&o->xdmf, o->dir, err);
}

enum poro_status output_reopen(struct output **out, const char *dir, const char *case_json,
			       const char *solver_version, int probe_count, const char *const *probe_names,
			       const char *const *probe_units, double keep_until, struct poro_error *err)
{
	enum poro_status st = writer_new(out, dir, case_json, solver_version, probe_count, probe_names,
					 probe_units, err);
	if (!st && (st = file_reopen(*out, case_json, solver_version, keep_until, err)))
		output_destroy(out);
	return st;
}

enum poro_status output_flush(struct output *o, struct poro_error *err)
{
	if (!o || o->finished)
		return poro_error_set(err, PORO_EINVAL, "cannot flush the output: it is closed");
	reason_clear();
	enum poro_status st = probes_write(o, err);
	return st ? st : file_sync(o, err);
}

/* ---- end of the run ------------------------------------------------------------------------------ */

/* Closes everything; returns < 0 when HDF5 could not close the file cleanly. */
static int file_close(struct output *o)
{
	int rc = 0;
	for (int j = 0; j < o->probe_count && o->probes; j++) {
		if (o->probes[j].time >= 0)
			H5Dclose(o->probes[j].time);
		if (o->probes[j].value >= 0)
			H5Dclose(o->probes[j].value);
		o->probes[j].time = o->probes[j].value = H5I_INVALID_HID;
	}
	if (o->string >= 0)
		H5Tclose(o->string);
	if (o->file >= 0 && H5Fclose(o->file) < 0)
		rc = -1;
	o->string = o->file = H5I_INVALID_HID;
	return rc;
}

static enum poro_status run_attributes(struct output *o, const char *status, long steps, long particles,
				       double wall_seconds, struct poro_error *err)
{
	char now[32];
	iso_time_now(now, sizeof now);
	hid_t run = H5Gopen2(o->file, "/run", H5P_DEFAULT);
	int rc = run < 0 || attr_string(o, run, "end_time", now) < 0 ||
		 attr_double(run, "wall_seconds", wall_seconds) < 0 || attr_long(run, "steps", steps) < 0 ||
		 attr_long(run, "particles", particles) < 0 ||
		 attr_string(o, run, "status", status) < 0 ? -1 : 0;
	if (run >= 0 && H5Gclose(run) < 0)
		rc = -1;
	return rc < 0 ? h5_fail(o, err, "write", "/run") : PORO_OK;
}

enum poro_status output_finish(struct output *o, const char *status, long steps, long particles,
			       double wall_seconds, struct poro_error *err)
{
	if (!o || o->finished)
		return poro_error_set(err, PORO_EINVAL, "cannot finish the output: it is closed");
	if (!status || (strcmp(status, "succeeded") && strcmp(status, "failed")))
		return poro_error_set(err, PORO_EINVAL, "invalid run status '%s'", status ? status : "(null)");
	reason_clear();
	enum poro_status st = probes_write(o, err);
	if (!st)
		st = run_attributes(o, status, steps, particles, wall_seconds, err);
	if (!st)
		st = file_sync(o, err);
	o->finished = 1;
	if (file_close(o) < 0 && !st)
		st = h5_fail(o, err, "close", NULL);
	reason_clear();
	return st;
}

void output_destroy(struct output **op)
{
	if (!op || !*op)
		return;
	struct output *o = *op;
	if (o->file >= 0 && !o->finished) {
		/* an abandoned run: keep the probe samples, leave /run status "running" */
		probes_write(o, NULL);
	}
	file_close(o);
	reason_clear();
	for (int j = 0; j < o->probe_count && o->probes; j++) {
		free(o->probes[j].name);
		free(o->probes[j].units);
	}
	free(o->probes);
	free(o->sample_time);
	free(o->sample_value);
	free(o->frame_time);
	free(o->frame_step);
	free(o->frame_name);
	xdmf_index_release(&o->xdmf);
	free(o->scratch);
	free(o->dir);
	free(o->path);
	free(o);
	*op = NULL;
}
