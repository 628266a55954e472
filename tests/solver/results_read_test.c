/*
 * results_read_test.c - tests of the results reader (solver/output/results_read.c).
 *
 * Oracle: the live simulation. A small consolidation column (double point, then single point)
 * runs through the library's sim_run() into a temporary directory; the reader must find the
 * frames the documented schedule writes (t = 0, every frame_interval, the end) at their times,
 * the point counts of sim_soil()/sim_water(), and in the last frame exactly the live state
 * (positions, velocities, stress, pore pressure positive in compression). A file left by a killed
 * run (status "running") must count only the frames result.xdmf lists. Error tests check the
 * status, that the message names the file and the object, and that nothing is printed.
 */
#include "results_read.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../harness.h"
#include "output.h"
#include "poro.h"

#define DT 1.0e-4
#define END 0.0025              /* 25 steps */
#define FRAME_INTERVAL 0.0009   /* frames at 0, 0.0009, 0.0018 and the end */
#define FRAMES 4
#define TIME_TOL 1e-12

/* A 0.1 m x 0.25 m column, 160 soil points, loaded on top, under gravity. %s: phases. */
static const char case_format[] =
	"{\"schema\": \"poro-case/1\", \"title\": \"results_read test column\","
	" \"formulation\": {\"scheme\": \"semi_implicit\", \"phases\": \"%s\", \"shape\": \"quadratic_bspline\"},"
	" \"grid\": {\"origin\": [0.0, 0.0], \"extent\": [0.1, 0.3], \"cell_size\": 0.025},"
	" \"materials\": [{\"name\": \"silt\", \"model\": \"linear_elastic\", \"density\": 2683,"
	"   \"youngs_modulus\": 1.37e7, \"poisson_ratio\": 0.23}],"
	" \"bodies\": [{\"name\": \"column\", \"material\": \"silt\", \"rectangle\": {\"min\": [0.0, 0.0],"
	"   \"max\": [0.1, 0.25]}, \"particles_per_cell\": 2, \"porosity\": 0.347, \"hydraulic_conductivity\": 2.3e-3}],"
	" \"fluid\": {\"density\": 1000},"
	" \"gravity\": {\"acceleration\": [0.0, -9.81]},"
	" \"boundaries\": {\"left\": {\"soil\": \"slip\", \"water\": \"slip\"},"
	"   \"right\": {\"soil\": \"slip\", \"water\": \"slip\"}, \"bottom\": {\"soil\": \"slip\", \"water\": \"slip\"}},"
	" \"loads\": [{\"body\": \"column\", \"face\": \"top\", \"traction\": [0.0, -1.2345e4]}],"
	" \"time\": {\"dt\": %g, \"end\": %g}, \"output\": {\"frame_interval\": %g},"
	" \"probes\": [{\"name\": \"p_base\", \"kind\": \"pore_pressure\", \"point\": [0.05, 0.0]}]}";

/* ---- fixtures ---------------------------------------------------------------------------------- */

static int spill(const char *path, const char *text)
{
	FILE *f = fopen(path, "wb");
	if (!f)
		return -1;
	int rc = fputs(text, f) < 0 ? -1 : 0;
	return fclose(f) != 0 ? -1 : rc;
}

/* ---- comparing with the live state --------------------------------------------------------------- */

/* Largest |file - live * sign| over n*width values, or INFINITY when the shape differs or the read fails. */
static double frame_vs_live(struct results *r, long frame, const char *set, const char *name, const double *live,
			    double sign, long n, int width)
{
	struct poro_error err = {0};
	double *a = NULL, worst = 0.0;
	long rows = -1;
	int cols = -1;
	if (results_frame_read(r, frame, set, name, &a, &rows, &cols, &err)) {
		printf("INFO cannot read %s/%s: %s\n", set, name, err.message);
		return INFINITY;
	}
	if (rows != n || cols != width)
		worst = INFINITY;
	for (long i = 0; rows == n && cols == width && i < n * width; i++)
		worst = fmax(worst, fabs(a[i] - sign * live[i]));
	free(a);
	return worst;
}

/* Rows of a set's x in a frame, or -1. */
static long set_rows(struct results *r, long frame, const char *set)
{
	struct poro_error err = {0};
	double *a = NULL;
	long rows = -1;
	if (results_frame_read(r, frame, set, "x", &a, &rows, NULL, &err))
		rows = -1;
	free(a);
	return rows;
}

static void check_frames(struct results *r, const struct sim *s, const char *label)
{
	char name[128];
	long frames = results_frame_count(r);
	snprintf(name, sizeof name, "%s_frame_count", label);
	CHECK(frames == FRAMES, name, "%ld frames, expected %d", frames, FRAMES);
	const double expected[FRAMES] = {0.0, FRAME_INTERVAL, 2 * FRAME_INTERVAL, END};
	int times_ok = frames == FRAMES, increasing = 1, soil_ok = 1;
	double prev = -INFINITY;
	for (long k = 0; k < frames; k++) {
		struct poro_error err = {0};
		double t = NAN;
		if (results_frame_time(r, k, &t, &err))
			printf("INFO frame %ld: %s\n", k, err.message);
		increasing &= t > prev;
		if (k < FRAMES)
			times_ok &= fabs(t - expected[k]) <= TIME_TOL;
		prev = t;
		soil_ok &= set_rows(r, k, "soil") == sim_soil(s)->n;
	}
	snprintf(name, sizeof name, "%s_frame_times_increase", label);
	CHECK(increasing && frames > 1, name, "times not strictly increasing");
	snprintf(name, sizeof name, "%s_frame_times_follow_schedule", label);
	CHECK(times_ok && fabs(prev - sim_time(s)) <= TIME_TOL, name, "last time %.17g, sim at %.17g", prev,
	      sim_time(s));
	snprintf(name, sizeof name, "%s_soil_count_every_frame", label);
	CHECK(soil_ok, name, "a frame's soil set has other than %ld rows", (long)sim_soil(s)->n);
}

/* The last frame holds exactly the live state (stored doubles round-trip exactly). */
static void check_last_frame(struct results *r, const struct sim *s, const char *label)
{
	char name[128];
	long last = results_frame_count(r) - 1;
	const struct particles *soil = sim_soil(s), *water = sim_water(s);
	long ns = soil->n, nw = water->n;
	double worst = fmax(frame_vs_live(r, last, "soil", "x", soil->x, 1, ns, 2),
			    frame_vs_live(r, last, "soil", "v", soil->v, 1, ns, 2));
	worst = fmax(worst, frame_vs_live(r, last, "soil", "stress", soil->stress, 1, ns, 4));
	snprintf(name, sizeof name, "%s_last_frame_soil_equals_live", label);
	CHECK(worst == 0.0, name, "largest difference %.3e", worst);

	/* pore pressure: positive in compression in the file, sim_pore_pressure() at the carrying points */
	idx_t np = sim_pressure_point_count(s);
	double *p = malloc(sizeof(double) * (size_t)np), *px = malloc(2 * sizeof(double) * (size_t)np);
	sim_pore_pressure(s, p, px);
	const char *carrier = sim_is_double_point(s) ? "water" : "soil";
	worst = fmax(frame_vs_live(r, last, carrier, "pore_pressure", p, 1, np, 1),
		     frame_vs_live(r, last, carrier, "x", px, 1, np, 2));
	snprintf(name, sizeof name, "%s_last_frame_pore_pressure_equals_live", label);
	CHECK(worst == 0.0, name, "largest difference %.3e over %ld %s points", worst, (long)np, carrier);
	free(p);
	free(px);

	struct poro_error err = {0};
	int has_water = results_frame_has_set(r, last, "water", &err);
	snprintf(name, sizeof name, "%s_water_set_as_formulation", label);
	CHECK(has_water == sim_is_double_point(s), name, "has water %d, double point %d", has_water,
	      sim_is_double_point(s));
	if (!sim_is_double_point(s))
		return;
	worst = fmax(frame_vs_live(r, last, "water", "x", water->x, 1, nw, 2),
		     frame_vs_live(r, last, "water", "v", water->v, 1, nw, 2));
	worst = fmax(worst, frame_vs_live(r, last, "water", "pore_pressure", water->pressure, -1, nw, 1));
	snprintf(name, sizeof name, "%s_last_frame_water_equals_live", label);
	CHECK(worst == 0.0, name, "largest difference %.3e (file %ld rows, sim %ld)", worst,
	      set_rows(r, last, "water"), nw);
}

/* The probe series: one sample per step from t = 0 (sim_run samples every step), strictly
 * increasing times ending at the run's end, the last value the simulation's, units "Pa"; a probe
 * the case does not have is refused by name. */
static void check_probe(struct results *r, const struct sim *s, const char *phases)
{
	char name[128];
	double *t = NULL, *v = NULL;
	char *units = NULL;
	long n = 0;
	struct poro_error err = {0};
	enum poro_status st = results_probe_read(r, "p_base", &t, &v, &n, &units, &err);
	snprintf(name, sizeof name, "%s_probe_read", phases);
	CHECK(!st && n > 1, name, "%ld samples: %s", n, err.message);
	int increasing = 1;
	for (long k = 1; k < n; k++)
		increasing &= t[k] > t[k - 1];
	snprintf(name, sizeof name, "%s_probe_times_increase_to_end", phases);
	CHECK(!st && increasing && fabs(t[n - 1] - sim_time(s)) <= TIME_TOL, name, "last time %.17g, sim at %.17g",
	      n ? t[n - 1] : -1.0, sim_time(s));
	snprintf(name, sizeof name, "%s_probe_last_value_and_units", phases);
	CHECK(!st && v[n - 1] == sim_probe_value(s, 0) && units && !strcmp(units, "Pa"), name,
	      "last %.17g, sim %.17g, units '%s'", n ? v[n - 1] : 0.0, sim_probe_value(s, 0), units ? units : "");
	free(t), free(v), free(units);
	st = results_probe_read(r, "p_top", &t, &v, &n, &units, &err);
	snprintf(name, sizeof name, "%s_unknown_probe_refused", phases);
	CHECK(st == PORO_EINVAL && !t && !v && strstr(err.message, "p_top"), name, "status %d: %s", st, err.message);
}

/* Runs the column with the given phases into dir and checks what the reader gives back. */
static void check_run(const char *phases, const char *dir)
{
	char json[4096], path[128], name[128];
	snprintf(json, sizeof json, case_format, phases, DT, END, FRAME_INTERVAL);
	struct case_spec *c = NULL;
	struct sim *s = NULL;
	struct results *r = NULL;
	struct poro_error err = {0};
	enum poro_status st = case_load_string(json, &c, &err);
	if (!st)
		st = sim_create(&s, c, &err);
	if (!st && sim_run(s, dir, "results_read_test", NULL, NULL, NULL))
		st = poro_error_set(&err, sim_error(s)->code, "%s", sim_error(s)->message);
	snprintf(name, sizeof name, "%s_run", phases);
	CHECK(!st, name, "%s", err.message);
	if (!st)
		st = results_open(&r, harness_join(path, sizeof path, dir, "result.h5"), &err);
	snprintf(name, sizeof name, "%s_open", phases);
	CHECK(!st && r, name, "%s", err.message);
	if (!st) {
		snprintf(name, sizeof name, "%s_case_json_as_given", phases);
		CHECK(!strcmp(results_case_json(r), json), name, "got %.80s...", results_case_json(r));
		check_frames(r, s, phases);
		check_last_frame(r, s, phases);
		check_probe(r, s, phases);
	}
	results_close(&r);
	snprintf(name, sizeof name, "%s_close_clears_pointer", phases);
	CHECK(r == NULL, name, "pointer not cleared");
	sim_destroy(&s);
	case_destroy(&c);
}

/* ---- a killed run ------------------------------------------------------------------------------- */

/* Two frames written, the writer abandoned (status stays "running"), result.xdmf put back to the
 * version that listed one: the second frame group exists but does not count. */
static void check_running_file(const char *dir)
{
	char json[4096], path[128], xdmf[128];
	snprintf(json, sizeof json, case_format, "single_point", DT, END, FRAME_INTERVAL);
	struct case_spec *c = NULL;
	struct sim *s = NULL;
	struct output *o = NULL;
	struct poro_error err = {0};
	char *one_frame = NULL;
	int ok = !case_load_string(json, &c, &err) && !sim_create(&s, c, &err) &&
		 !output_create(&o, dir, json, "results_read_test", 0, NULL, NULL, &err);
	struct output_frame fr = {.time = 0.0, .step = 0, .soil = ok ? sim_soil(s) : NULL};
	ok = ok && !output_frame_write(o, &fr, &err) && (one_frame = harness_read_file(harness_join(xdmf, sizeof xdmf, dir, "result.xdmf")));
	fr.time = 1.7e-3, fr.step = 17;
	ok = ok && !output_frame_write(o, &fr, &err);
	output_destroy(&o);
	char *two_frames = ok ? harness_read_file(xdmf) : NULL;
	ok = ok && two_frames && !spill(xdmf, one_frame);
	CHECK(ok, "running_file_prepared", "%s", err.message);

	struct results *r = NULL;
	harness_join(path, sizeof path, dir, "result.h5");
	long listed_one = ok && !results_open(&r, path, &err) ? results_frame_count(r) : -1;
	results_close(&r);
	CHECK(listed_one == 1, "running_file_counts_frames_xdmf_lists", "%ld frames (%s)", listed_one, err.message);
	ok = ok && !spill(xdmf, two_frames);
	long listed_two = ok && !results_open(&r, path, &err) ? results_frame_count(r) : -1;
	results_close(&r);
	CHECK(listed_two == 2, "running_file_counts_both_listed_frames", "%ld frames", listed_two);
	free(one_frame);
	free(two_frames);
	sim_destroy(&s);
	case_destroy(&c);
}

/* ---- errors -------------------------------------------------------------------------------------- */

/* stderr redirected into a file while the reader runs, to check it prints nothing. The open errors
 * run first in main(), before any writer in this process has replaced HDF5's default printer. */
struct capture {
	int saved, fd;
	char path[128];
};

static void capture_begin(struct capture *c, const char *dir)
{
	fflush(stderr);
	c->saved = dup(2);
	c->fd = open(harness_join(c->path, sizeof c->path, dir, "stderr.txt"), O_CREAT | O_TRUNC | O_WRONLY, 0600);
	dup2(c->fd, 2);
}

/* Bytes written to stderr since capture_begin(). */
static long capture_end(struct capture *c)
{
	fflush(stderr);
	dup2(c->saved, 2);
	close(c->saved);
	close(c->fd);
	struct stat sb;
	return stat(c->path, &sb) == 0 ? (long)sb.st_size : -1;
}

static void check_open_errors(const char *dir)
{
	char missing[128], plain[128], missing_msg[PORO_ERROR_MESSAGE_MAX];
	struct poro_error err = {0};
	struct results *r = NULL;
	struct capture cap;
	capture_begin(&cap, dir);
	enum poro_status absent = results_open(&r, harness_join(missing, sizeof missing, dir, "absent/result.h5"), &err);
	int missing_ok = absent == PORO_EIO && r == NULL && strstr(err.message, missing) != NULL;
	strcpy(missing_msg, err.message);
	/* a file that exists but is no HDF5 file */
	spill(harness_join(plain, sizeof plain, dir, "plain.h5"), "{\"schema\": \"poro-case/1\"}\n");
	enum poro_status st = results_open(&r, plain, &err);
	long printed = capture_end(&cap);
	CHECK(missing_ok, "missing_file_is_eio_naming_path", "status %d: %s", absent, missing_msg);
	CHECK(st == PORO_EIO && r == NULL && strstr(err.message, plain), "non_hdf5_file_is_eio_naming_path",
	      "status %d: %s", st, err.message);
	CHECK(printed == 0, "open_errors_print_nothing", "%ld bytes written to stderr", printed);
}

/* results_check_file() tells a result file, a wrong file (invalid input) and a missing one (I/O). */
static void check_file_kinds(const char *run_dir, const char *dir)
{
	char result[128], missing[128], plain[128];
	struct poro_error err = {0}, plain_err = {0}, dir_err = {0};
	harness_join(result, sizeof result, run_dir, "result.h5");
	harness_join(plain, sizeof plain, dir, "plain.h5");   /* written by check_open_errors() */
	enum poro_status ok = results_check_file(result, &err);
	enum poro_status absent = results_check_file(harness_join(missing, sizeof missing, dir, "absent.h5"), &err);
	enum poro_status text = results_check_file(plain, &plain_err);
	enum poro_status folder = results_check_file(run_dir, &dir_err);
	CHECK(ok == PORO_OK, "check_file_accepts_result", "status %d", ok);
	CHECK(absent == PORO_EIO && strstr(err.message, missing), "check_file_missing_is_eio_naming_path",
	      "status %d: %s", absent, err.message);
	CHECK(text == PORO_EINVAL && strstr(plain_err.message, plain) && strstr(plain_err.message, "not an HDF5 file"),
	      "check_file_non_hdf5_is_einval", "status %d: %s", text, plain_err.message);
	CHECK(folder == PORO_EINVAL && strstr(dir_err.message, "directory"), "check_file_directory_is_einval",
	      "status %d: %s", folder, dir_err.message);
}

static void check_read_errors(const char *run_dir, const char *dir)
{
	char path[128], object[64], dataset_msg[PORO_ERROR_MESSAGE_MAX];
	struct poro_error err = {0};
	struct results *r = NULL;
	double *a = (double *)&err, t = 0;
	long rows = -1;
	struct capture cap;
	capture_begin(&cap, dir);
	if (results_open(&r, harness_join(path, sizeof path, run_dir, "result.h5"), &err)) {
		capture_end(&cap);
		CHECK(0, "read_errors_open", "%s", err.message);
		return;
	}
	long last = results_frame_count(r) - 1;
	enum poro_status no_dataset = results_frame_read(r, last, "soil", "no_such_field", &a, &rows, NULL, &err);
	strcpy(dataset_msg, err.message);
	enum poro_status past_end = results_frame_read(r, last + 1, "soil", "x", &a, &rows, NULL, &err);
	enum poro_status bad_set = results_frame_read(r, 0, "air", "x", &a, &rows, NULL, &err);
	enum poro_status bad_time = results_frame_time(r, -1, &t, &err);
	results_close(&r);
	long printed = capture_end(&cap);
	snprintf(object, sizeof object, "/frames/%06ld/soil/no_such_field", last);
	CHECK(no_dataset == PORO_EIO && a == NULL && strstr(dataset_msg, object) && strstr(dataset_msg, path),
	      "missing_dataset_is_eio_naming_file_and_object", "status %d: %s", no_dataset, dataset_msg);
	CHECK(past_end == PORO_EINVAL && bad_set == PORO_EINVAL && bad_time == PORO_EINVAL,
	      "bad_arguments_are_einval", "frame past end %d, set 'air' %d, frame -1 %d", past_end, bad_set, bad_time);
	CHECK(printed == 0, "read_errors_print_nothing", "%ld bytes written to stderr", printed);
}

int main(void)
{
	char *dp = harness_temp_dir("results_read_test"), *sp = harness_temp_dir("results_read_test"), *killed = harness_temp_dir("results_read_test"), *scratch = harness_temp_dir("results_read_test");
	if (!dp || !sp || !killed || !scratch) {
		CHECK(0, "temporary_directories", "mkdtemp failed");
		HARNESS_EXIT();
	}
	check_open_errors(scratch);
	check_run("double_point", dp);
	check_run("single_point", sp);
	check_running_file(killed);
	check_read_errors(dp, scratch);
	check_file_kinds(dp, scratch);
	if (!harness_failed_count) {
		harness_remove_dir(dp);
		harness_remove_dir(sp);
		harness_remove_dir(killed);
		harness_remove_dir(scratch);
	}
	HARNESS_EXIT();
}
