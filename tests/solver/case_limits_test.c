/*
 * case_limits_test.c - the case loader's limits and its cost (case.h, docs/case-spec.md "Limits").
 *
 * Each limit is checked from both sides on the Terzaghi case of tests/cases/: a case exactly at
 * the limit loads, one step over it is refused with the limit's JSON pointer and a message that
 * names the limit and the value. The counts a case implies (cells, steps, frames, checkpoints,
 * material points) are set with binary-exact numbers (0.125, 0.5, 1563 m) so "at the limit" is
 * exact, not a rounding. Also: duplicate names found among 10,000 probes (a hash lookup each,
 * where a scan of the earlier names once made validation quadratic), the cap on the problems a
 * refused case lists and the count of the rest, the loader's entry for an already parsed
 * document, and how far below each limit every shipped case is (INFO lines).
 *
 * Documents are built with jansson and loaded with case_load_json(), the server's entry; the
 * duplicate and cap checks also go through case_load_string(), the command line's.
 */
#include "case.h"
#include "element.h"

#include <glob.h>
#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../harness.h"

#define PROBES_TIMED CASE_PROBES_MAX     /* probes of the case whose validation time is printed */

static char root_dir[256];

/* The repository root, from __FILE__ ("" when compiled with a relative path from the root). */
static void find_root(void)
{
	const char *suffix = "tests/solver/case_limits_test.c";
	snprintf(root_dir, sizeof root_dir, "%.*s", (int)(strlen(__FILE__) - strlen(suffix)), __FILE__);
}

/* tests/cases/terzaghi.json as a tree the caller owns; NULL after a FAIL line. */
static json_t *terzaghi(void)
{
	char path[512];
	json_error_t e;
	snprintf(path, sizeof path, "%stests/cases/terzaghi.json", root_dir);
	json_t *doc = json_load_file(path, 0, &e);
	if (!doc)
		CHECK(0, "terzaghi case read", "%s: %s", path, e.text);
	return doc;
}

static json_t *section(json_t *doc, const char *key)
{
	return json_object_get(doc, key);
}

/* Loads doc (taking it); returns the status and leaves the message in err. */
static enum poro_status load(json_t *doc, struct poro_error *err)
{
	struct case_spec *c = NULL;
	enum poro_status st = doc ? case_load_json(doc, &c, err) : PORO_EINVAL;
	case_destroy(&c);
	json_decref(doc);
	return st;
}

static void expect_valid(const char *name, json_t *doc)
{
	struct poro_error err = { 0 };
	enum poro_status st = load(doc, &err);
	CHECK(st == PORO_OK, name, "status %d: %s", st, err.message);
}

/* doc must be refused with one problem, the line `want` exactly. */
static void expect_refused(const char *name, json_t *doc, const char *want)
{
	struct poro_error err = { 0 };
	enum poro_status st = load(doc, &err);
	CHECK(st == PORO_EINVAL && strcmp(err.message, want) == 0, name, "status %d, message '%s', want '%s'", st,
	      err.message, want);
}

/* n probes named p0, p1, ... at the middle of the Terzaghi column. */
static json_t *probes(int n)
{
	json_t *a = json_array();
	for (int i = 0; i < n; i++) {
		char name[32];
		snprintf(name, sizeof name, "p%d", i);
		json_array_append_new(a, json_pack("{s:s, s:s, s:[f, f]}", "name", name, "kind", "pore_pressure", "point",
						   0.05, 0.5));
	}
	return a;
}

static json_t *with_probes(int n)
{
	json_t *doc = terzaghi();
	json_object_set_new(doc, "probes", probes(n));
	return doc;
}

/* The case with its list `list` made n items long by copies of the first, renamed PREFIX1,
 * PREFIX2, ... when prefix is given (the first keeps its name: the body's material is "soil",
 * the load's body "column"). Bodies may overlap, loads repeat. */
static json_t *with_copies(const char *list, int n, const char *prefix)
{
	json_t *doc = terzaghi(), *items = section(doc, list), *first = json_array_get(items, 0);
	for (int i = 1; i < n; i++) {
		char name[32];
		json_t *copy = json_deep_copy(first);
		snprintf(name, sizeof name, "%s%d", prefix ? prefix : "", i);
		if (prefix)
			json_object_set_new(copy, "name", json_string(name));
		json_array_append_new(items, copy);
	}
	return doc;
}

static json_t *with_materials(int n) { return with_copies("materials", n, "m"); }
static json_t *with_bodies(int n) { return with_copies("bodies", n, "b"); }
static json_t *with_loads(int n) { return with_copies("loads", n, NULL); }

/* A polygon of n vertices on a circle of radius 0.04 m about [0.05, 0.5], inside the grid. */
static json_t *polygon(int n)
{
	json_t *a = json_array();
	for (int i = 0; i < n; i++) {
		double t = 6.283185307179586 * i / n;
		json_array_append_new(a, json_pack("[f, f]", 0.05 + 0.04 * cos(t), 0.5 + 0.04 * sin(t)));
	}
	return a;
}

/* The case with its column's rectangle replaced by polygons: `count` bodies of n vertices, then
 * one of `last` vertices when last > 0. */
static json_t *with_polygons(int count, int n, int last)
{
	json_t *doc = with_bodies(count + (last > 0));
	json_t *list = section(doc, "bodies");
	for (int i = 0; i < count + (last > 0); i++) {
		json_t *b = json_array_get(list, (size_t)i);
		json_object_del(b, "rectangle");
		json_object_set_new(b, "polygon", polygon(i < count ? n : last));
	}
	return doc;
}

static void test_list_limits(void)
{
	char want[256];
	expect_valid("probes at the limit load", with_probes(CASE_PROBES_MAX));
	snprintf(want, sizeof want, "/probes: must list at most %d probes (the case limit), got %d", CASE_PROBES_MAX,
		 CASE_PROBES_MAX + 1);
	expect_refused("probes over the limit refused", with_probes(CASE_PROBES_MAX + 1), want);
	expect_valid("materials at the limit load", with_materials(CASE_MATERIALS_MAX));
	snprintf(want, sizeof want, "/materials: must list at most %d materials (the case limit), got %d",
		 CASE_MATERIALS_MAX, CASE_MATERIALS_MAX + 1);
	expect_refused("materials over the limit refused", with_materials(CASE_MATERIALS_MAX + 1), want);
	expect_valid("bodies at the limit load", with_bodies(CASE_BODIES_MAX));
	snprintf(want, sizeof want, "/bodies: must list at most %d bodies (the case limit), got %d", CASE_BODIES_MAX,
		 CASE_BODIES_MAX + 1);
	expect_refused("bodies over the limit refused", with_bodies(CASE_BODIES_MAX + 1), want);
	expect_valid("loads at the limit load", with_loads(CASE_LOADS_MAX));
	snprintf(want, sizeof want, "/loads: must list at most %d loads (the case limit), got %d", CASE_LOADS_MAX,
		 CASE_LOADS_MAX + 1);
	expect_refused("loads over the limit refused", with_loads(CASE_LOADS_MAX + 1), want);
}

static void test_polygon_limits(void)
{
	char want[256];
	expect_valid("polygon of the most vertices loads", with_polygons(1, CASE_POLYGON_MAX, 0));
	snprintf(want, sizeof want, "/bodies/0/polygon: must have 3 to %d vertices, got %d", CASE_POLYGON_MAX,
		 CASE_POLYGON_MAX + 1);
	expect_refused("polygon of too many vertices refused", with_polygons(1, CASE_POLYGON_MAX + 1, 0), want);
	/* CASE_POLYGON_VERTICES_MAX in all: full polygons and one for the rest */
	int full = CASE_POLYGON_VERTICES_MAX / CASE_POLYGON_MAX, rest = CASE_POLYGON_VERTICES_MAX % CASE_POLYGON_MAX;
	expect_valid("polygon vertices at the limit in all load", with_polygons(full, CASE_POLYGON_MAX, rest));
	snprintf(want, sizeof want, "/bodies: must have at most %d polygon vertices in all (the case limit), got %d",
		 CASE_POLYGON_VERTICES_MAX, CASE_POLYGON_VERTICES_MAX + 1);
	expect_refused("polygon vertices over the limit in all refused",
		       with_polygons(full, CASE_POLYGON_MAX, rest + 1), want);
}

/* A name or title of n characters 'a'. */
static json_t *text_of(size_t n)
{
	char *s = malloc(n + 1);
	memset(s, 'a', n);
	s[n] = '\0';
	json_t *v = json_string(s);
	free(s);
	return v;
}

/* A title of n characters U+00E9 (two bytes each in UTF-8). */
static json_t *accented_text_of(size_t n)
{
	char *s = malloc(2 * n + 1);
	for (size_t i = 0; i < n; i++)
		s[2 * i] = (char)0xc3, s[2 * i + 1] = (char)0xa9;
	s[2 * n] = '\0';
	json_t *v = json_string(s);
	free(s);
	return v;
}

static void test_text_limits(void)
{
	char want[256];
	json_t *doc = terzaghi();
	json_object_set_new(json_array_get(section(doc, "probes"), 2), "name", text_of(CASE_NAME_MAX - 1));
	expect_valid("name of the most characters loads", doc);
	doc = terzaghi();
	json_object_set_new(json_array_get(section(doc, "probes"), 2), "name", text_of(CASE_NAME_MAX));
	snprintf(want, sizeof want, "/probes/2/name: must be 1 to %d characters long, got %d", CASE_NAME_MAX - 1,
		 CASE_NAME_MAX);
	expect_refused("name too long refused", doc, want);
	doc = terzaghi();
	json_object_set_new(doc, "title", text_of(CASE_TITLE_MAX));
	expect_valid("title of the most characters loads", doc);
	doc = terzaghi();
	json_object_set_new(doc, "title", text_of(CASE_TITLE_MAX + 1));
	snprintf(want, sizeof want, "/title: must be at most %d characters long, got %d", CASE_TITLE_MAX,
		 CASE_TITLE_MAX + 1);
	expect_refused("title too long refused", doc, want);
	/* the schema's maxLength counts characters: 255 accented letters (510 bytes) were refused
	 * when the limit counted bytes */
	doc = terzaghi();
	json_object_set_new(doc, "title", accented_text_of(CASE_TITLE_MAX));
	expect_valid("title of the most accented characters loads", doc);
	doc = terzaghi();
	json_object_set_new(doc, "title", accented_text_of(CASE_TITLE_MAX + 1));
	expect_refused("title of too many accented characters refused", doc, want);
}

/* The case on a grid of 1 m cells, nx by ny. */
static json_t *with_grid(double nx, double ny)
{
	json_t *doc = terzaghi();
	json_object_set_new(doc, "grid", json_pack("{s:[f, f], s:[f, f], s:f}", "origin", 0.0, 0.0, "extent", nx, ny,
						   "cell_size", 1.0));
	return doc;
}

static void test_grid_limit(void)
{
	char want[256];
	expect_valid("grid at the cell limit loads", with_grid(1e4, 1e4));
	snprintf(want, sizeof want, "/grid: must have at most %.0f cells (the case limit), got %.0f", CASE_CELLS_MAX,
		 1e4 * 10001);
	expect_refused("grid over the cell limit refused", with_grid(1e4, 10001), want);
	expect_refused("a reported 1.6e9 cells refused", with_grid(4e4, 4e4),
		       "/grid: must have at most 100000000 cells (the case limit), got 1600000000");
}

/* The case with dt, end, frame_interval (0: none) and a checkpoint interval (0: none). Its soil is
 * made soft (E = 10 Pa: a CFL step h / c_p of 0.34 s) so that the large steps these counts are built
 * from stay within the stable step the loader also checks (solver/stable_dt.h). */
static json_t *with_time(double dt, double end, double frame_interval, double checkpoint_interval)
{
	json_t *doc = terzaghi();
	json_object_set_new(json_array_get(section(doc, "materials"), 0), "youngs_modulus", json_real(10.0));
	json_object_set_new(doc, "time", json_pack("{s:f, s:f}", "dt", dt, "end", end));
	json_object_set_new(doc, "output", json_pack("{s:f}", "frame_interval", frame_interval));
	if (checkpoint_interval > 0)
		json_object_set_new(doc, "checkpoint", json_pack("{s:f}", "interval", checkpoint_interval));
	return doc;
}

static void test_time_limits(void)
{
	char want[256];
	expect_valid("steps at the limit load", with_time(0.125, 0.125 * CASE_STEPS_MAX, 0, 0));
	snprintf(want, sizeof want, "/time/end: must take at most %.0f steps of /time/dt (the case limit), got %.0f",
		 CASE_STEPS_MAX, CASE_STEPS_MAX + 1);
	expect_refused("steps over the limit refused", with_time(0.125, 0.125 * (CASE_STEPS_MAX + 1), 0, 0), want);
	expect_refused("a reported end time of 1e12 s refused", with_time(1e-4, 1e12, 0, 0),
		       "/time/end: must take at most 1000000000 steps of /time/dt (the case limit), got 1e+16");
	expect_valid("frames at the limit load", with_time(0.25, 0.5 * CASE_FRAMES_MAX, 0.5, 0));
	snprintf(want, sizeof want,
		 "/output/frame_interval: must give at most %.0f frames over /time/end (the case limit), got %.0f",
		 CASE_FRAMES_MAX, CASE_FRAMES_MAX + 1);
	expect_refused("frames over the limit refused", with_time(0.25, 0.5 * (CASE_FRAMES_MAX + 1), 0.5, 0), want);
	/* a frame is written at most once a step, so an interval below dt costs one frame a step */
	expect_valid("frame interval below dt counts a frame a step", with_time(0.25, 1.0, 1e-12, 0));
	expect_valid("checkpoints at the limit load", with_time(0.25, 0.5 * CASE_CHECKPOINTS_MAX, 0, 0.5));
	snprintf(want, sizeof want,
		 "/checkpoint/interval: must give at most %.0f checkpoints over /time/end (the case limit), got %.0f",
		 CASE_CHECKPOINTS_MAX, CASE_CHECKPOINTS_MAX + 1);
	expect_refused("checkpoints over the limit refused", with_time(0.25, 0.5 * (CASE_CHECKPOINTS_MAX + 1), 0, 0.5),
		       want);
}

/* The column widened to `width` m on a 1 m grid 2000 x 1000 cells, 8x8 points a cell. */
static json_t *with_points(double width)
{
	json_t *doc = with_grid(2000, 1000);
	json_t *body = json_array_get(section(doc, "bodies"), 0);
	json_object_set_new(body, "rectangle", json_pack("{s:[f, f], s:[f, f]}", "min", 0.0, 0.0, "max", width, 1000.0));
	json_object_set_new(body, "particles_per_cell", json_integer(8));
	return doc;
}

static void test_points_limit(void)
{
	char want[256];
	/* 1562.5 m x 1000 m of 1 m cells with 64 points each: 1e8 points */
	expect_valid("material points at the limit load", with_points(CASE_POINTS_MAX / 64 / 1000));
	snprintf(want, sizeof want, "/bodies: must seed at most %.0f material points (area / cell_size^2 x "
		 "particles_per_cell^2) (the case limit), got %.0f", CASE_POINTS_MAX, 1563.0 * 1000 * 64);
	expect_refused("material points over the limit refused", with_points(1563), want);
}

/* A case text of n probes whose last repeats the first's name; its wall time of validation is printed. */
static void test_duplicate_among_many(void)
{
	json_t *doc = with_probes(PROBES_TIMED);
	json_t *list = section(doc, "probes");
	json_object_set_new(json_array_get(list, PROBES_TIMED - 1), "name", json_string("p0"));
	char *text = json_dumps(doc, 0);
	json_decref(doc);
	struct case_spec *c = NULL;
	struct poro_error err = { 0 };
	double t0 = harness_wall_seconds();
	enum poro_status st = case_load_string(text, &c, &err);
	double seconds = harness_wall_seconds() - t0;
	char want[128];
	snprintf(want, sizeof want, "/probes/%d/name: duplicate probe name 'p0', also at /probes/0", PROBES_TIMED - 1);
	CHECK(st == PORO_EINVAL && strcmp(err.message, want) == 0, "duplicate found at the end of 10000 probes",
	      "status %d, message '%s'", st, err.message);
	free(text);
	doc = with_probes(PROBES_TIMED);
	text = json_dumps(doc, 0);
	json_decref(doc);
	t0 = harness_wall_seconds();
	st = case_load_string(text, &c, &err);
	double valid_seconds = harness_wall_seconds() - t0;
	CHECK(st == PORO_OK, "case of 10000 probes loads", "%s", err.message);
	printf("INFO validating %d probes: %.1f ms (%.2f us a probe); with a duplicate at the end: %.1f ms\n",
	       PROBES_TIMED, 1e3 * valid_seconds, 1e6 * valid_seconds / PROBES_TIMED, 1e3 * seconds);
	case_destroy(&c);
	free(text);
}

static int count_lines(const char *s)
{
	int n = *s != '\0';
	for (; *s; s++)
		n += *s == '\n';
	return n;
}

/* n probes with one problem each: outside the grid (a long line) or without a point (a short one). */
static json_t *bad_probes(int n, int long_lines)
{
	json_t *doc = with_probes(n);
	json_t *list = section(doc, "probes"), *p;
	size_t i;
	json_array_foreach(list, i, p) {
		if (long_lines)
			json_object_set_new(p, "point", json_pack("[f, f]", 9.25, 9.75));
		else
			json_object_del(p, "point");
	}
	return doc;
}

static void test_problem_cap(void)
{
	const int n = 1000;
	json_t *doc = bad_probes(n, 0);
	char *text = json_dumps(doc, 0);
	json_decref(doc);
	struct case_spec *c = NULL;
	struct poro_error err = { 0 };
	enum poro_status st = case_load_string(text, &c, &err);
	free(text);
	char first[64], last[64], more[64];
	snprintf(first, sizeof first, "/probes/0/point: missing required key\n");
	snprintf(last, sizeof last, "\n/probes/%d/point: missing required key\n", CASE_PROBLEMS_MAX - 1);
	snprintf(more, sizeof more, "\n%s%d more problems", CASE_PROBLEMS_MORE, n - CASE_PROBLEMS_MAX);
	const char *tail = strrchr(err.message, '\n');
	CHECK(st == PORO_EINVAL && count_lines(err.message) == CASE_PROBLEMS_MAX + 1, "problems capped",
	      "%d lines for %d problems", count_lines(err.message), n);
	CHECK(strncmp(err.message, first, strlen(first)) == 0 && strstr(err.message, last) != NULL,
	      "the first problems listed in document order", "message '%.300s'", err.message);
	CHECK(tail && strcmp(tail, more) == 0, "a last line counts the rest", "last line '%s'", tail ? tail + 1 : "");
	CHECK(case_problem_count(err.message) == n, "problem count read back", "%ld for %d", case_problem_count(err.message),
	      n);

	/* long lines: fewer fit in the message; the count line is still whole and the count right */
	struct poro_error long_err = { 0 };
	st = load(bad_probes(n, 1), &long_err);
	size_t length = strlen(long_err.message);
	tail = strrchr(long_err.message, '\n');
	int listed = count_lines(long_err.message) - 1;
	snprintf(more, sizeof more, "\n%s%d more problems", CASE_PROBLEMS_MORE, n - listed);
	CHECK(st == PORO_EINVAL && length < sizeof long_err.message - 1 && tail && strcmp(tail, more) == 0 &&
	      listed <= CASE_PROBLEMS_MAX, "long problems capped by the message size", "%zu bytes, %d listed, last line '%s'",
	      length, listed, tail ? tail + 1 : "");
	CHECK(case_problem_count(long_err.message) == n, "long problem count read back", "%ld for %d",
	      case_problem_count(long_err.message), n);
	CHECK(case_problem_count("") == 0 && case_problem_count(NULL) == 0 && case_problem_count("/a: x\n/b: y") == 2,
	      "problem count of short messages", "wrong count");
}

/* case_load_json keeps the canonical text; a root that is not an object is refused. */
static void test_load_json(void)
{
	json_t *doc = terzaghi();
	struct case_spec *c = NULL;
	struct poro_error err = { 0 };
	char *canonical = json_dumps(doc, JSON_COMPACT | JSON_SORT_KEYS);
	enum poro_status st = case_load_json(doc, &c, &err);
	CHECK(st == PORO_OK && c && canonical && strcmp(c->json, canonical) == 0 && c->probe_count == 3,
	      "parsed case loads with its canonical text", "status %d: %s", st, err.message);
	case_destroy(&c);
	free(canonical);
	json_decref(doc);
	json_t *array = json_array();
	st = case_load_json(array, &c, &err);
	CHECK(st == PORO_EINVAL && !c && strcmp(err.message, "/: expected an object, got array") == 0,
	      "parsed non-object refused", "status %d: %s", st, err.message);
	json_decref(array);
}

/* How many times each limit is the shipped case's count (printed). */
static void report_margins(const char *path, const struct case_spec *c)
{
	double h = c->grid.cell_size, cells = (c->grid.extent[0] / h) * (c->grid.extent[1] / h);
	double steps = c->time.end / c->time.dt, points = 0;
	double frames = c->output.frame_interval > 0 ? c->time.end / c->output.frame_interval : 2;
	double checkpoints = c->checkpoint.interval > 0 ? c->time.end / c->checkpoint.interval : 0;
	for (int b = 0; b < c->body_count; b++) {
		const struct case_body *body = &c->bodies[b];
		points += (body->max[0] - body->min[0]) * (body->max[1] - body->min[1]) / (h * h) *
			  body->particles_per_cell * body->particles_per_cell;   /* polygons: their boxes, an upper bound */
	}
	const char *name = strrchr(path, '/') ? strrchr(path, '/') + 1 : path;
	char shown[32] = "none";
	if (checkpoints > 0)
		snprintf(shown, sizeof shown, "%.0fx", CASE_CHECKPOINTS_MAX / checkpoints);
	printf("INFO limit/used %s: cells %.0fx, points %.0fx, steps %.0fx, frames %.0fx, checkpoints %s, "
	       "probes %.0fx, bodies %dx\n", name, CASE_CELLS_MAX / cells, CASE_POINTS_MAX / points,
	       CASE_STEPS_MAX / steps, CASE_FRAMES_MAX / frames, shown, (double)CASE_PROBES_MAX / c->probe_count,
	       CASE_BODIES_MAX / c->body_count);
}

static void test_shipped_margins(void)
{
	char pattern[512];
	glob_t found;
	snprintf(pattern, sizeof pattern, "%stests/cases/*.json", root_dir);
	int loaded = 0, total = 0;
	if (glob(pattern, 0, NULL, &found) == 0) {
		for (size_t i = 0; i < found.gl_pathc; i++) {
			if (element_case_file_is_element(found.gl_pathv[i]))
				continue;
			struct case_spec *c = NULL;
			struct poro_error err = { 0 };
			total++;
			if (case_load_file(found.gl_pathv[i], &c, &err) == PORO_OK) {
				loaded++;
				report_margins(found.gl_pathv[i], c);
			} else {
				printf("INFO %s refused: %s\n", found.gl_pathv[i], err.message);
			}
			case_destroy(&c);
		}
		globfree(&found);
	}
	CHECK(total > 0 && loaded == total, "every shipped simulation case within the limits", "%d of %d loaded",
	      loaded, total);
}

int main(void)
{
	find_root();
	test_list_limits();
	test_polygon_limits();
	test_text_limits();
	test_grid_limit();
	test_time_limits();
	test_points_limit();
	test_duplicate_among_many();
	test_problem_cap();
	test_load_json();
	test_shipped_margins();
	HARNESS_EXIT();
}
