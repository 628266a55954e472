/*
 * output_test.c - tests of the results writer (solver/output/output.c, solver/output/output_xdmf.c).
 *
 * Oracle: the values themselves. Particle sets are filled with high-entropy numbers, written as
 * frames, and read back with the HDF5 C API; every value must round-trip exactly (displacement as
 * the same x - x0 in double, pore pressure with its sign flipped). The crash tests run the writer
 * in a child process that dies without closing the file, either after two frames (_exit) or
 * killed with SIGKILL at a random moment of a long run, and then require every frame that
 * result.xdmf lists to read back exactly. Error tests check the status and that the message names
 * the path and the HDF5 object.
 */
#include "output.h"

#include <errno.h>
#include <hdf5.h>
#include <signal.h>
#include <stdint.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "../harness.h"

#define FRAMES 3
#define SAMPLES_PER_FRAME 240      /* 720 in all: past the sample buffer's first growth and a chunk */
#define PROBES 3

static const char *const probe_names[PROBES] = {"settlement", "base pressure", "flux_top"};
static const char *const probe_units[PROBES] = {"m", "Pa", "m/s"};

/* ---- fixtures ---------------------------------------------------------------------------------- */

#define DIRS_MAX 64
static char dirs[DIRS_MAX][64];
static int dirs_used;

/* A fresh directory under /tmp, removed at the end when every check passed. */
static char *make_dir(void)
{
	if (dirs_used == DIRS_MAX)
		return NULL;
	char *d = dirs[dirs_used];
	snprintf(d, 64, "/tmp/output_test.XXXXXX");
	if (!mkdtemp(d))
		return NULL;
	dirs_used++;
	return d;
}

/* Removes the directory make_dir() returned last, at once. */
static void drop_last_dir(void)
{
	if (dirs_used > 0)
		harness_remove_dir(dirs[--dirs_used]);
}

static void remove_dirs(void)
{
	for (int i = 0; i < dirs_used; i++)
		harness_remove_dir(dirs[i]);
}

static void fill(double *a, size_t n, double lo, double hi)
{
	for (size_t i = 0; i < n; i++)
		a[i] = rnd(lo, hi);
}

/* High-entropy values in every array the writer reads. */
static void randomize(struct particles *p)
{
	size_t n = (size_t)p->n;
	if (!p->alias_of) {
		fill(p->x0, 2 * n, -3.7, 11.3);
		for (size_t i = 0; i < 2 * n; i++)
			p->x[i] = p->x0[i] + rnd(-0.0173, 0.0291);
		fill(p->volume, n, 1.7e-3, 2.9e-3);
		fill(p->porosity, n, 0.27, 0.61);
	}
	fill(p->v, 2 * n, -0.37, 0.53);
	fill(p->mass, n, 2.1, 5.3);
	fill(p->pressure, n, -8.3e4, 1.9e3);
	if (p->stress) {
		fill(p->stress, 4 * n, -2.3e5, 4.1e4);
		fill(p->plastic_strain, n, 0.0, 0.031);
	}
}

/* A copy of what a frame must contain for one set. */
struct snapshot {
	idx_t n;
	double *x, *x0, *v, *pressure, *porosity, *volume, *mass, *stress, *plastic_strain;
};

static double *dup_array(const double *a, size_t n)
{
	if (!a)
		return NULL;
	double *c = malloc(n * sizeof *c);
	memcpy(c, a, n * sizeof *c);
	return c;
}

static struct snapshot snap(const struct particles *p)
{
	size_t n = (size_t)p->n;
	return (struct snapshot){
		.n = p->n, .x = dup_array(p->x, 2 * n), .x0 = dup_array(p->x0, 2 * n), .v = dup_array(p->v, 2 * n),
		.pressure = dup_array(p->pressure, n), .porosity = dup_array(p->porosity, n),
		.volume = dup_array(p->volume, n), .mass = dup_array(p->mass, n),
		.stress = dup_array(p->stress, 4 * n), .plastic_strain = dup_array(p->plastic_strain, n),
	};
}

static void snapshot_free(struct snapshot *s)
{
	free(s->x); free(s->x0); free(s->v); free(s->pressure); free(s->porosity);
	free(s->volume); free(s->mass); free(s->stress); free(s->plastic_strain);
}

/* A case JSON past HDF5's 64 kB object-header limit, with non-ASCII text. */
static char *big_case_json(void)
{
	size_t cap = 150000, len = 0;
	char *s = malloc(cap);
	len += (size_t)snprintf(s + len, cap - len, "{\"name\": \"Terzaghi \xc3\xa9prouvette \\u03c3\", \"points\": [");
	for (int i = 0; len + 64 < cap - 16; i++)
		len += (size_t)snprintf(s + len, cap - len, "%s[%.17g, %.17g]", i ? ", " : "", rnd(-5, 5), rnd(0, 9));
	snprintf(s + len, cap - len, "]}");
	return s;
}

static int count_of(const char *text, const char *needle)
{
	int c = 0;
	for (const char *p = text; (p = strstr(p, needle)); p += strlen(needle))
		c++;
	return c;
}

/* ---- reading back ------------------------------------------------------------------------------ */

/* Reads a double dataset; its shape must be rows x cols (cols 1: 1-D). NULL on any mismatch. */
static double *read_doubles(hid_t file, const char *path, hsize_t rows, hsize_t cols)
{
	hid_t ds = H5Dopen2(file, path, H5P_DEFAULT);
	if (ds < 0)
		return NULL;
	hid_t space = H5Dget_space(ds);
	hsize_t dims[2] = {0, 0};
	int rank = H5Sget_simple_extent_dims(space, dims, NULL);
	H5Sclose(space);
	int shape_ok = cols == 1 ? rank == 1 && dims[0] == rows : rank == 2 && dims[0] == rows && dims[1] == cols;
	hsize_t count = rows * cols;
	double *a = shape_ok ? malloc((count > 0 ? count : 1) * sizeof *a) : NULL;
	if (a && count > 0 && H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, a) < 0) {
		free(a);
		a = NULL;
	}
	H5Dclose(ds);
	return a;
}

static hsize_t dataset_length(hid_t file, const char *path)
{
	hid_t ds = H5Dopen2(file, path, H5P_DEFAULT);
	if (ds < 0)
		return (hsize_t)-1;
	hid_t space = H5Dget_space(ds);
	hsize_t n = (hsize_t)H5Sget_simple_extent_npoints(space);
	H5Sclose(space);
	H5Dclose(ds);
	return n;
}

/* A variable-length string attribute, malloc'ed; NULL if absent. */
static char *read_string_attr(hid_t file, const char *object, const char *name)
{
	hid_t a = H5Aopen_by_name(file, object, name, H5P_DEFAULT, H5P_DEFAULT);
	if (a < 0)
		return NULL;
	hid_t t = H5Tcopy(H5T_C_S1);
	H5Tset_size(t, H5T_VARIABLE);
	H5Tset_cset(t, H5T_CSET_UTF8);
	char *v = NULL, *copy = NULL;
	if (H5Aread(a, t, &v) >= 0 && v) {
		copy = malloc(strlen(v) + 1);
		strcpy(copy, v);
		H5free_memory(v);
	}
	H5Tclose(t);
	H5Aclose(a);
	return copy;
}

static int read_num_attr(hid_t file, const char *object, const char *name, hid_t type, void *out)
{
	hid_t a = H5Aopen_by_name(file, object, name, H5P_DEFAULT, H5P_DEFAULT);
	if (a < 0)
		return -1;
	int rc = H5Aread(a, type, out) < 0 ? -1 : 0;
	H5Aclose(a);
	return rc;
}

/* Index of the first mismatch between got and want (which may be transformed), -1 if none. */
enum transform { SAME, NEGATED, MINUS_X0, PADDED, PADDED_MINUS_X0, FULL_TENSOR };

static long first_mismatch(const double *got, const struct snapshot *s, const double *want, size_t width,
			   enum transform how)
{
	size_t n = (size_t)s->n;
	for (size_t i = 0; i < n; i++)
		for (size_t c = 0; c < width; c++) {
			double w;
			switch (how) {
			case NEGATED: w = -want[i]; break;
			case MINUS_X0: w = want[2 * i + c] - s->x0[2 * i + c]; break;
			case PADDED: w = c < 2 ? want[2 * i + c] : 0.0; break;
			case PADDED_MINUS_X0: w = c < 2 ? want[2 * i + c] - s->x0[2 * i + c] : 0.0; break;
			case FULL_TENSOR: { /* (xx, yy, xy, zz) -> 3 x 3 row-major */
				const double *sig = want + 4 * i;
				double full[9] = {sig[0], sig[2], 0, sig[2], sig[1], 0, 0, 0, sig[3]};
				w = full[c];
				break;
			}
			default: w = want[i * width + c]; break;
			}
			if (got[i * width + c] != w) /* exact: the writer must not round */
				return (long)(i * width + c);
		}
	return -1;
}

/* Checks every dataset of a set in a frame against its snapshot; returns the number of failures. */
/* double_point: the frame has water points of its own, which carry the pore pressure; the soil
 * set then has no pore_pressure. */
static int check_set(hid_t file, const char *frame, const char *set, const struct snapshot *s, int soil,
		     int double_point, const char *label)
{
	struct {
		const char *name; size_t width; const double *want; enum transform how; const char *units;
	} fields[] = {
		{"x", 2, s->x, SAME, "m"},
		{"v", 2, s->v, SAME, "m/s"},
		{"displacement", 2, s->x, MINUS_X0, "m"},
		{"pore_pressure", 1, s->pressure, NEGATED, "Pa"},
		{"porosity", 1, s->porosity, SAME, "1"},
		{"volume", 1, s->volume, SAME, "m^3/m"},
		{"mass", 1, s->mass, SAME, "kg/m"},
		{"displacement3", 3, s->x, PADDED_MINUS_X0, "m"},
		{"v3", 3, s->v, PADDED, "m/s"},
		{"stress", 4, s->stress, SAME, "Pa"},
		{"plastic_strain", 1, s->plastic_strain, SAME, "1"},
		{"stress9", 9, s->stress, FULL_TENSOR, "Pa"},
	};
	int failures = 0;
	size_t count = sizeof fields / sizeof fields[0] - (soil ? 0 : 3);
	for (size_t k = 0; k < count; k++) {
		char path[128], name[192];
		snprintf(path, sizeof path, "%s/%s/%s", frame, set, fields[k].name);
		if (soil && double_point && !strcmp(fields[k].name, "pore_pressure")) {
			snprintf(name, sizeof name, "%s %s is not written (the water points carry it)", label, path);
			CHECK(H5Lexists(file, path, H5P_DEFAULT) == 0, name, "%s exists", path);
			continue;
		}
		snprintf(name, sizeof name, "%s %s round-trips", label, path);
		double *got = read_doubles(file, path, (hsize_t)s->n, fields[k].width);
		long bad = got ? first_mismatch(got, s, fields[k].want, fields[k].width, fields[k].how) : -2;
		CHECK(bad == -1, name, "%s", bad == -2 ? "missing or wrong shape" : "value differs");
		failures += bad != -1;
		char *units = read_string_attr(file, path, "units");
		snprintf(name, sizeof name, "%s %s units", label, path);
		CHECK(units && !strcmp(units, fields[k].units), name, "got '%s'", units ? units : "(none)");
		free(units);
		free(got);
	}
	if (!soil) {
		char path[128];
		snprintf(path, sizeof path, "%s/%s/stress", frame, set);
		CHECK(H5Lexists(file, path, H5P_DEFAULT) == 0, "water set has no stress", "%s exists", path);
	}
	return failures;
}


/* ---- one complete run -------------------------------------------------------------------------- */

/* Everything a run writes, generated before writing, so a parent can check a child's file. */
struct run_fixture {
	struct particles soil, water;
	int double_point;
	struct snapshot soil_at[FRAMES], water_at[FRAMES];
	double frame_time[FRAMES];
	long frame_step[FRAMES];
	double sample_time[FRAMES * SAMPLES_PER_FRAME];
	double sample_value[FRAMES * SAMPLES_PER_FRAME][PROBES];
};

static void fixture_init(struct run_fixture *r, int double_point, idx_t n_soil, idx_t n_water)
{
	memset(r, 0, sizeof *r);
	r->double_point = double_point;
	particles_init(&r->soil, n_soil, 1, NULL);
	if (double_point)
		particles_init(&r->water, n_water, 0, NULL);
	double t = 0.0;
	for (int k = 0; k < FRAMES; k++) {
		for (int s = 0; s < SAMPLES_PER_FRAME; s++) {
			int j = k * SAMPLES_PER_FRAME + s;
			r->sample_time[j] = t += rnd(1.3e-4, 2.9e-4);
			for (int p = 0; p < PROBES; p++)
				r->sample_value[j][p] = rnd(-7.1e3, 9.3e3);
		}
		r->frame_time[k] = t;
		r->frame_step[k] = 1009L * (k + 1) + 17;
		randomize(&r->soil);
		r->soil_at[k] = snap(&r->soil);
		if (double_point) {
			if (k == FRAMES - 1) { /* water leaving through a drained face: fewer points */
				particles_remove(&r->water, 3);
				particles_remove(&r->water, 0);
			}
			randomize(&r->water);
			r->water_at[k] = snap(&r->water);
		}
	}
}

static void fixture_release(struct run_fixture *r)
{
	for (int k = 0; k < FRAMES; k++) {
		snapshot_free(&r->soil_at[k]);
		snapshot_free(&r->water_at[k]);
	}
	particles_release(&r->soil);
	particles_release(&r->water);
}

/* Puts a snapshot's values, and its number of points, back into the particle arrays. */
static void load(struct particles *p, const struct snapshot *s)
{
	p->n = s->n; /* never more than the set was created with */
	size_t n = (size_t)p->n;
	memcpy(p->x, s->x, 2 * n * sizeof(double));
	memcpy(p->x0, s->x0, 2 * n * sizeof(double));
	memcpy(p->v, s->v, 2 * n * sizeof(double));
	memcpy(p->pressure, s->pressure, n * sizeof(double));
	memcpy(p->porosity, s->porosity, n * sizeof(double));
	memcpy(p->volume, s->volume, n * sizeof(double));
	memcpy(p->mass, s->mass, n * sizeof(double));
	if (p->stress) {
		memcpy(p->stress, s->stress, 4 * n * sizeof(double));
		memcpy(p->plastic_strain, s->plastic_strain, n * sizeof(double));
	}
}

/* Writes the first `frames` frames of r with their probe samples. finish 0: die right after the
 * last frame as a killed process would (the caller is then a child). Returns 0 on success. */
static int write_run(struct run_fixture *r, const char *dir, const char *json, int frames, int finish)
{
	struct poro_error err = {0};
	struct output *o = NULL;
	if (output_create(&o, dir, json, "v0.1.2-7-gdeadbee", PROBES, probe_names, probe_units, &err))
		return printf("# output_create: %s\n", err.message), -1;
	for (int k = 0; k < frames; k++) {
		for (int s = 0; s < SAMPLES_PER_FRAME; s++) {
			int j = k * SAMPLES_PER_FRAME + s;
			if (output_probe_sample(o, r->sample_time[j], r->sample_value[j], &err))
				return printf("# sample: %s\n", err.message), -1;
		}
		load(&r->soil, &r->soil_at[k]);
		if (r->double_point)
			load(&r->water, &r->water_at[k]);
		struct output_frame f = {r->frame_time[k], r->frame_step[k], &r->soil,
					 r->double_point ? &r->water : NULL};
		if (output_frame_write(o, &f, &err))
			return printf("# frame: %s\n", err.message), -1;
	}
	if (!finish)
		_exit(0);
	long particles = r->soil.n + (r->double_point ? r->water.n : 0);
	if (output_finish(o, "succeeded", 3037, particles, 12.625, &err))
		return printf("# finish: %s\n", err.message), -1;
	enum poro_status st = output_finish(o, "failed", 0, 0, 0, &err);
	CHECK(st == PORO_EINVAL, "output_finish twice is refused", "status %d", (int)st);
	output_destroy(&o);
	CHECK(o == NULL, "output_destroy clears the pointer", "pointer not cleared");
	output_destroy(&o);
	output_destroy(NULL);
	return 0;
}

static void check_probes(hid_t file, const struct run_fixture *r, int samples, const char *label)
{
	for (int p = 0; p < PROBES; p++) {
		char path[128], name[192];
		snprintf(path, sizeof path, "/probes/%s/time", probe_names[p]);
		double *t = read_doubles(file, path, (hsize_t)samples, 1);
		snprintf(path, sizeof path, "/probes/%s/value", probe_names[p]);
		double *v = read_doubles(file, path, (hsize_t)samples, 1);
		int ok = t && v;
		for (int j = 0; ok && j < samples; j++)
			ok = t[j] == r->sample_time[j] && v[j] == r->sample_value[j][p];
		snprintf(name, sizeof name, "%s probe '%s' has %d exact samples", label, probe_names[p], samples);
		CHECK(ok, name, "length %lld or values differ", (long long)dataset_length(file, path));
		char *units = read_string_attr(file, path, "units");
		snprintf(name, sizeof name, "%s probe '%s' units", label, probe_names[p]);
		CHECK(units && !strcmp(units, probe_units[p]), name, "got '%s'", units ? units : "(none)");
		free(units);
		free(t);
		free(v);
	}
}

static void check_frames(hid_t file, const struct run_fixture *r, int frames, const char *label)
{
	char name[128];
	for (int k = 0; k < frames; k++) {
		char frame[32];
		snprintf(frame, sizeof frame, "/frames/%06d", k);
		double t = 0;
		long step = 0;
		int ok = read_num_attr(file, frame, "time", H5T_NATIVE_DOUBLE, &t) == 0 &&
			 read_num_attr(file, frame, "step", H5T_NATIVE_LONG, &step) == 0;
		snprintf(name, sizeof name, "%s %s time and step", label, frame);
		CHECK(ok && t == r->frame_time[k] && step == r->frame_step[k], name, "time %.17g step %ld", t, step);
		check_set(file, frame, "soil", &r->soil_at[k], 1, r->double_point, label);
		if (r->double_point) {
			check_set(file, frame, "water", &r->water_at[k], 0, 1, label);
		} else {
			char path[64];
			snprintf(path, sizeof path, "%s/water", frame);
			snprintf(name, sizeof name, "%s %s has no water group", label, frame);
			CHECK(H5Lexists(file, path, H5P_DEFAULT) == 0, name, "water group present");
		}
	}
	char extra[32];
	snprintf(extra, sizeof extra, "/frames/%06d", frames);
	snprintf(name, sizeof name, "%s has exactly %d frames", label, frames);
	CHECK(H5Lexists(file, extra, H5P_DEFAULT) == 0, name, "%s exists", extra);
	/* the index of frames lists exactly these, in order */
	double *times = read_doubles(file, "/frame_times", (hsize_t)frames, 1);
	double *steps = read_doubles(file, "/frame_steps", (hsize_t)frames, 1);   /* int64, read as doubles */
	int same = times && steps;
	for (int k = 0; same && k < frames; k++)
		same = times[k] == r->frame_time[k] && steps[k] == (double)r->frame_step[k];
	snprintf(name, sizeof name, "%s /frame_times and /frame_steps list the %d frames", label, frames);
	CHECK(same, name, "%s", times && steps ? "values differ" : "missing or wrong length");
	free(times);
	free(steps);
}

static hid_t open_result(const char *dir)
{
	char path[128];
	snprintf(path, sizeof path, "%s/result.h5", dir);
	return H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
}

/* Number of frames result.xdmf lists, -1 if it is missing or not well formed at a glance. */
static int xdmf_frames(const char *dir)
{
	char path[128];
	snprintf(path, sizeof path, "%s/result.xdmf", dir);
	char *x = harness_read_file(path);
	if (!x)
		return -1;
	int frames = count_of(x, "<Grid Name=\"soil\" GridType=\"Uniform\"");
	int grids = frames + count_of(x, "<Grid Name=\"water\" GridType=\"Uniform\"");
	int ok = !strncmp(x, "<?xml", 5) && strstr(x, "</Xdmf>") && count_of(x, "<Time ") == grids &&
		 count_of(x, "<Grid ") == count_of(x, "</Grid>") &&
		 count_of(x, "<Attribute ") == count_of(x, "</Attribute>") &&
		 count_of(x, "<DataItem ") == count_of(x, "</DataItem>");
	free(x);
	return ok ? frames : -1;
}

/* Every data item of result.xdmf names a dataset of result.h5 with the dimensions it declares.
 * Returns the number of items checked, -1 on the first mismatch. */
static int xdmf_items_resolve(const char *xdmf, hid_t file)
{
	int items = 0;
	for (const char *p = xdmf; (p = strstr(p, "<DataItem Dimensions=\"")); items++) {
		p += strlen("<DataItem Dimensions=\"");
		unsigned long long want[2] = {0, 0};
		int rank = sscanf(p, "%llu %llu", &want[0], &want[1]);
		const char *ref = strstr(p, ">result.h5:");
		if (!ref || rank < 1)
			return -1;
		ref += strlen(">result.h5:");
		char path[128];
		size_t len = strcspn(ref, "<");
		snprintf(path, sizeof path, "%.*s", (int)len, ref);
		hid_t ds = H5Dopen2(file, path, H5P_DEFAULT);
		if (ds < 0)
			return printf("# %s is not in result.h5\n", path), -1;
		hid_t space = H5Dget_space(ds);
		hsize_t dims[2] = {0, 0};
		int got = H5Sget_simple_extent_dims(space, dims, NULL);
		H5Sclose(space);
		H5Dclose(ds);
		if (got != rank || dims[0] != want[0] || (rank == 2 && dims[1] != want[1]))
			return printf("# %s has other dimensions than result.xdmf says\n", path), -1;
	}
	return items;
}

static void check_xdmf(const char *dir, int frames, int double_point, const char *label)
{
	char path[128], name[128];
	snprintf(name, sizeof name, "%s result.xdmf is well formed and lists %d frames", label, frames);
	int listed = xdmf_frames(dir);
	CHECK(listed == frames, name, "%d", listed);
	snprintf(path, sizeof path, "%s/result.xdmf", dir);
	char *x = harness_read_file(path);
	if (!x)
		return;
	const int sets = double_point ? 2 : 1;
	int grids = frames * sets + sets;
	snprintf(name, sizeof name, "%s result.xdmf has a temporal collection per point set and %d grids", label,
		 grids);
	CHECK(count_of(x, "CollectionType=\"Temporal\"") == sets && count_of(x, "<Grid ") == grids &&
	      count_of(x, "CollectionType=\"Spatial\"") == 0, name, "%d grids", count_of(x, "<Grid "));
	snprintf(path, sizeof path, "result.h5:/frames/%06d/soil/x<", frames - 1);
	snprintf(name, sizeof name, "%s result.xdmf references the last frame", label);
	CHECK(strstr(x, path) != NULL, name, "no %s", path);
	snprintf(name, sizeof name, "%s result.xdmf water grids", label);
	CHECK(count_of(x, "<Grid Name=\"water\" GridType=\"Uniform\"") == (double_point ? frames : 0), name, "%d",
	      count_of(x, "<Grid Name=\"water\" GridType=\"Uniform\""));
	hid_t file = open_result(dir);
	int items = file >= 0 ? xdmf_items_resolve(x, file) : -1;
	/* topology, geometry and attributes: the soil's 8, without pore_pressure in double point, and
	 * the water's 6 */
	int expected = frames * (double_point ? 7 + 6 : 8);
	snprintf(name, sizeof name, "%s result.xdmf data items all resolve in result.h5", label);
	CHECK(items == expected, name, "%d of %d", items, expected);
	if (file >= 0)
		H5Fclose(file);
	free(x);
	snprintf(path, sizeof path, "%s/.result.xdmf.tmp", dir);
	snprintf(name, sizeof name, "%s no temporary xdmf left", label);
	CHECK(access(path, F_OK) != 0, name, "%s exists", path);
}

static void check_run(hid_t file, const char *json, long particles, const char *label)
{
	char name[128];
	char *case_json = read_string_attr(file, "/case", "json");
	snprintf(name, sizeof name, "%s /case json is identical (%zu bytes)", label, strlen(json));
	CHECK(case_json && !strcmp(case_json, json), name, "differs");
	char *status = read_string_attr(file, "/run", "status");
	char *version = read_string_attr(file, "/run", "solver_version");
	char *start = read_string_attr(file, "/run", "start_time");
	char *end = read_string_attr(file, "/run", "end_time");
	long steps = 0, count = 0;
	double wall = 0;
	read_num_attr(file, "/run", "steps", H5T_NATIVE_LONG, &steps);
	read_num_attr(file, "/run", "particles", H5T_NATIVE_LONG, &count);
	read_num_attr(file, "/run", "wall_seconds", H5T_NATIVE_DOUBLE, &wall);
	snprintf(name, sizeof name, "%s /run status succeeded", label);
	CHECK(status && !strcmp(status, "succeeded"), name, "got '%s'", status ? status : "(none)");
	snprintf(name, sizeof name, "%s /run attributes", label);
	CHECK(version && !strcmp(version, "v0.1.2-7-gdeadbee") && steps == 3037 && wall == 12.625 &&
	      count == particles, name, "version %s steps %ld particles %ld wall %g", version ? version : "(none)",
	      steps, count, wall);
	snprintf(name, sizeof name, "%s /run times are ISO 8601 UTC", label);
	CHECK(start && end && strlen(start) == 20 && start[10] == 'T' && start[19] == 'Z' && strcmp(start, end) <= 0,
	      name, "start %s end %s", start ? start : "-", end ? end : "-");
	free(case_json); free(status); free(version); free(start); free(end);
}

static void test_complete_run(int double_point)
{
	const char *label = double_point ? "double point:" : "single point:";
	static struct run_fixture r;
	fixture_init(&r, double_point, 37, 23);
	char *dir = make_dir();
	char *json = big_case_json();
	char name[128];
	snprintf(name, sizeof name, "%s complete run writes", label);
	CHECK(write_run(&r, dir, json, FRAMES, 1) == 0, name, "see the line above");
	hid_t file = open_result(dir);
	snprintf(name, sizeof name, "%s result.h5 opens", label);
	CHECK(file >= 0, name, "H5Fopen failed");
	if (file >= 0) {
		check_frames(file, &r, FRAMES, label);
		check_probes(file, &r, FRAMES * SAMPLES_PER_FRAME, label);
		check_run(file, json, 37 + (double_point ? 23 - 2 : 0), label); /* 2 water points left */
		H5Fclose(file);
	}
	check_xdmf(dir, FRAMES, double_point, label);
	free(json);
	fixture_release(&r);
}

/* ---- crash safety ------------------------------------------------------------------------------ */

/* A child writes two frames and dies without output_finish() or output_destroy(), as kill -9 after
 * the second frame would leave it. Both frames and their probe samples must read back. */
static void test_exit_without_close(void)
{
	const char *label = "killed after 2 frames:";
	static struct run_fixture r;
	fixture_init(&r, 1, 41, 29);
	char *dir = make_dir();
	fflush(stdout);
	pid_t pid = fork();
	if (pid == 0) {
		write_run(&r, dir, "{\"case\": \"killed\"}", 2, 0);
		_exit(3); /* write_run failed before the simulated kill */
	}
	int status = 0;
	waitpid(pid, &status, 0);
	CHECK(WIFEXITED(status) && WEXITSTATUS(status) == 0, "killed after 2 frames: child wrote them",
	      "status %d", status);
	hid_t file = open_result(dir);
	CHECK(file >= 0, "killed after 2 frames: result.h5 opens", "H5Fopen failed");
	if (file >= 0) {
		check_frames(file, &r, 2, label);
		check_probes(file, &r, 2 * SAMPLES_PER_FRAME, label);
		char *st = read_string_attr(file, "/run", "status");
		char *end = read_string_attr(file, "/run", "end_time");
		CHECK(st && !strcmp(st, "running") && !end, "killed after 2 frames: /run stays running, no end_time",
		      "status '%s', end_time '%s'", st ? st : "(none)", end ? end : "(none)");
		free(st);
		free(end);
		H5Fclose(file);
	}
	check_xdmf(dir, 2, 1, label);
	fixture_release(&r);
}

#define KILL_POINTS 20000          /* large enough that a frame takes a while to write */
#define KILL_FRAMES_MAX 400
#ifndef KILL_WAIT_MAX
#define KILL_WAIT_MAX 4            /* frames written before the kill: 1 .. 1 + this */
#endif

/* Frame k's values are a function of (k, i), so the parent can check them without the child. */
static double kill_value(long k, long i)
{
	return (double)k * 1.25 + (double)i * 3.0517578125e-05 + 0.1;
}

static void kill_child(const char *dir, int pipe_fd)
{
	struct particles soil;
	struct poro_error err = {0};
	struct output *o = NULL;
	const char *names[] = {"k"}, *units[] = {"1"};
	if (particles_init(&soil, KILL_POINTS, 1, &err) ||
	    output_create(&o, dir, "{}", "test", 1, names, units, &err))
		_exit(4);
	for (long k = 0; k < KILL_FRAMES_MAX; k++) {
		for (long i = 0; i < 2 * KILL_POINTS; i++)
			soil.x[i] = kill_value(k, i);
		for (long i = 0; i < KILL_POINTS; i++)
			soil.pressure[i] = -kill_value(k, i);
		double sample = (double)k;
		if (output_probe_sample(o, (double)k, &sample, &err) ||
		    output_frame_write(o, &(struct output_frame){(double)k, k, &soil, NULL}, &err))
			_exit(5);
		if (write(pipe_fd, "f", 1) != 1)
			_exit(6);
	}
	_exit(0);
}

static double now_seconds(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Every frame that result.xdmf lists reads back exactly; so do their probe samples. */
static int check_killed_file(const char *dir, int reported)
{
	int listed = xdmf_frames(dir);
	if (listed < reported)
		return printf("# xdmf lists %d frames, %d were reported done\n", listed, reported), -1;
	hid_t file = open_result(dir);
	if (file < 0)
		return printf("# result.h5 does not open\n"), -1;
	int bad = 0;
	for (long k = 0; k < listed && !bad; k++) {
		char path[64];
		snprintf(path, sizeof path, "/frames/%06ld/soil/x", k);
		double *x = read_doubles(file, path, KILL_POINTS, 2);
		snprintf(path, sizeof path, "/frames/%06ld/soil/pore_pressure", k);
		double *p = read_doubles(file, path, KILL_POINTS, 1);
		bad = !x || !p;
		for (long i = 0; !bad && i < KILL_POINTS; i++)
			bad = x[2 * i] != kill_value(k, 2 * i) || p[i] != kill_value(k, i);
		if (bad)
			printf("# frame %ld of %d does not read back\n", k, listed);
		free(x);
		free(p);
	}
	double *samples = read_doubles(file, "/probes/k/time", (hsize_t)dataset_length(file, "/probes/k/time"), 1);
	hsize_t n = dataset_length(file, "/probes/k/value");
	if (!bad && (!samples || n < (hsize_t)listed)) {
		printf("# probe has %lld samples for %d frames\n", (long long)n, listed);
		bad = 1;
	}
	for (long k = 0; !bad && k < listed; k++)
		bad = samples[k] != (double)k;
	free(samples);
	H5Fclose(file);
	return bad ? -1 : listed;
}

/* SIGKILL at random moments of a run, mostly in the middle of writing a frame. */
static void test_kill_at_random_moments(void)
{
	const char *env = getenv("OUTPUT_TEST_KILLS");
	int kills = env ? atoi(env) : 6, failures = 0, frames_checked = 0;
	for (int trial = 0; trial < kills; trial++) {
		char *dir = make_dir();
		int fds[2];
		if (!dir || pipe(fds) != 0)
			break;
		fflush(stdout);
		pid_t pid = fork();
		if (pid == 0) {
			close(fds[0]);
			kill_child(dir, fds[1]);
		}
		close(fds[1]);
		int wait_frames = 1 + (int)rnd(0, KILL_WAIT_MAX), got = 0;
		char c;
		double t0 = now_seconds(), period = 0.0;
		while (got < wait_frames && read(fds[0], &c, 1) == 1) {
			got++;
			if (got == 1)
				t0 = now_seconds();
		}
		period = got > 1 ? (now_seconds() - t0) / (got - 1) : 0.02;
		struct timespec pause = {0, (long)(rnd(0.0, 1.2) * period * 1e9) % 1000000000L};
		nanosleep(&pause, NULL);
		kill(pid, SIGKILL);
		while (read(fds[0], &c, 1) == 1)
			got++; /* frames completed before the signal landed */
		close(fds[0]);
		int status = 0;
		waitpid(pid, &status, 0);
		int frames = check_killed_file(dir, got);
		if (frames < 0 || !WIFSIGNALED(status)) {
			failures++;
		} else {
			frames_checked += frames;
			drop_last_dir();
		}
	}
	CHECK(failures == 0, "killed at random moments: every listed frame reads back",
	      "%d of %d runs damaged", failures, kills);
	printf("INFO output: %d runs killed at random moments, %d listed frames read back\n", kills, frames_checked);
}

/* ---- errors ------------------------------------------------------------------------------------ */

static void test_missing_directory(void)
{
	struct output *o = (struct output *)&o;
	struct poro_error err = {0};
	const char *dir = "/tmp/output_test.none/deeper";
	enum poro_status st = output_create(&o, dir, "{}", "v", 0, NULL, NULL, &err);
	CHECK(st == PORO_EIO && o == NULL, "missing directory: PORO_EIO", "status %d", (int)st);
	CHECK(strstr(err.message, "'/tmp/output_test.none/deeper'") != NULL, "missing directory: message names it",
	      "message '%s'", err.message);

	char *file_dir = make_dir();
	char path[128];
	snprintf(path, sizeof path, "%s/plain", file_dir);
	FILE *f = fopen(path, "w");
	if (f)
		fclose(f);
	st = output_create(&o, path, "{}", "v", 0, NULL, NULL, &err);
	CHECK(st == PORO_EIO && strstr(err.message, path), "directory that is a file: PORO_EIO naming it",
	      "status %d, '%s'", (int)st, err.message);

	const char *bad[] = {"a/b"}, *units[] = {"m"};
	st = output_create(&o, file_dir, "{}", "v", 1, bad, units, &err);
	CHECK(st == PORO_EINVAL && strstr(err.message, "'a/b'"), "probe name with a slash: PORO_EINVAL",
	      "status %d, '%s'", (int)st, err.message);
	const char *twice[] = {"p", "p"}, *units2[] = {"m", "m"};
	st = output_create(&o, file_dir, "{}", "v", 2, twice, units2, &err);
	CHECK(st == PORO_EINVAL, "duplicate probe names: PORO_EINVAL", "status %d", (int)st);
}

/* A write that fails part way (the file size limit stands in for a full disk) is reported naming
 * the dataset, and leaves no half frame: the retry takes the same number. */
static void child_file_too_large(const char *dir, int fd)
{
	struct particles small, big;
	struct poro_error err = {0};
	struct output *o = NULL;
	if (particles_init(&small, 13, 1, &err) || particles_init(&big, 200000, 1, &err) ||
	    output_create(&o, dir, "{}", "v", 0, NULL, NULL, &err))
		_exit(4);
	randomize(&small);
	randomize(&big);
	if (output_frame_write(o, &(struct output_frame){0.5, 1, &small, NULL}, &err))
		_exit(5);
	char path[128];
	snprintf(path, sizeof path, "%s/result.h5", dir);
	struct stat sb;
	stat(path, &sb);
	signal(SIGXFSZ, SIG_IGN);
	struct rlimit lim = {(rlim_t)sb.st_size + 300000, RLIM_INFINITY};
	setrlimit(RLIMIT_FSIZE, &lim);
	enum poro_status st = output_frame_write(o, &(struct output_frame){1.5, 2, &big, NULL}, &err);
	dprintf(fd, "%d %s\n", (int)st, err.message);
	lim.rlim_cur = RLIM_INFINITY;
	setrlimit(RLIMIT_FSIZE, &lim);
	st = output_frame_write(o, &(struct output_frame){2.5, 3, &small, NULL}, &err);
	if (!st)
		st = output_finish(o, "failed", 3, 13, 0.25, &err);
	dprintf(fd, "%d %s\n", (int)st, st ? err.message : "");
	output_destroy(&o);
	_exit(0);
}

static void test_write_failure(void)
{
	char *dir = make_dir();
	int fds[2];
	if (!dir || pipe(fds) != 0)
		return;
	fflush(stdout);
	pid_t pid = fork();
	if (pid == 0) {
		close(fds[0]);
		child_file_too_large(dir, fds[1]);
	}
	close(fds[1]);
	char report[2 * PORO_ERROR_MESSAGE_MAX] = "";
	size_t used = 0;
	ssize_t got;
	while ((got = read(fds[0], report + used, sizeof report - 1 - used)) > 0)
		used += (size_t)got;
	report[used] = '\0';
	close(fds[0]);
	waitpid(pid, NULL, 0);
	int first = -1, second = -1;
	char *line2 = strchr(report, '\n');
	sscanf(report, "%d", &first);
	if (line2)
		sscanf(line2 + 1, "%d", &second);
	printf("# %.*s\n", (int)strcspn(report, "\n"), report);
	const char *want = "cannot write '/frames/000001/soil/";
	CHECK(first == PORO_EIO && strstr(report, want) && strstr(report, dir), "full disk: PORO_EIO naming the dataset",
	      "report '%s'", report);
	CHECK(second == PORO_OK, "full disk: the next frame is written after space returns", "report '%s'", report);
	hid_t file = open_result(dir);
	if (file >= 0) {
		double *x = read_doubles(file, "/frames/000001/soil/x", 13, 2);
		CHECK(x != NULL && H5Lexists(file, "/frames/000002", H5P_DEFAULT) == 0,
		      "full disk: the retry reuses the frame number", "frame 000001 is not the small retry");
		free(x);
		H5Fclose(file);
	}
	CHECK(xdmf_frames(dir) == 2, "full disk: result.xdmf lists the 2 good frames", "%d", xdmf_frames(dir));
}

int main(void)
{
	H5Eset_auto2(H5E_DEFAULT, NULL, NULL); /* expected failures (absent objects) stay quiet */
	test_complete_run(1);
	test_complete_run(0);
	test_exit_without_close();
	test_kill_at_random_moments();
	test_missing_directory();
	test_write_failure();
	if (!harness_failed_count)
		remove_dirs();
	HARNESS_EXIT();
}
