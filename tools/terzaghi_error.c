/*
 * terzaghi_error.c - the terzaghi-error command: how far a finished consolidation run is from
 * Terzaghi's closed form.
 *
 *   terzaghi-error DIR     reads DIR/result.h5 and prints one line, e.g.
 *   terzaghi: t = 0.981 s (Tv = 1.000), RMS pore-pressure error 0.26% of q over 640 points
 *
 * The case is taken from the file's /case, so the command needs nothing but the run directory.
 * For the last frame it computes the RMS over the points that carry pore pressure (the water set
 * in double point, the soil set in single point) of (p - p_Terzaghi) / q, the measure of 000
 * §5.1 and tests/verify/consolidation_test.c. Symbols as in the paper (000 Eqs. 84-86):
 *   q    magnitude of the first load's traction, Pa (a step load)
 *   H    height of the first body (the column), m; the drainage length Hd is H, or H/2 when the
 *        bottom face is drained too
 *   m_v  = (1 + nu)(1 - 2 nu) / ((1 - nu) E), the oedometric compressibility, 1/Pa
 *   c_v  = k / (rho_w g m_v), g = 9.81 m/s^2;  Tv = c_v t / Hd^2
 *   z    depth below the drained top, top - y (and the distance to the nearer drained face when
 *        both drain)
 * Assumes a one-dimensional column: one body, loaded on top, drained at the top. Exit 0, or 2
 * with a message when DIR holds no readable result or its case is not such a column.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../tests/verify/analytic.h"
#include "case.h"
#include "results_read.h"

#define G 9.81                 /* gravitational acceleration in c_v, m/s^2 (000 Eq. 85) */
#define EXIT_INVALID 2
#define PATH_MAX_LEN 4096

/* The column as the closed form sees it. */
struct column {
	double q;              /* load, Pa */
	double top, bottom;    /* y of the body's top and bottom faces, m */
	double Hd;             /* drainage length, m */
	double cv;             /* consolidation coefficient, m^2/s */
	int drained_both;      /* the bottom face drains too */
};

static int fail(const char *what, const char *detail)
{
	fprintf(stderr, "terzaghi-error: %s%s%s\n", what, detail ? ": " : "", detail ? detail : "");
	return EXIT_INVALID;
}

static int column_of(const struct case_spec *c, struct column *col)
{
	if (c->load_count < 1 || c->body_count < 1)
		return -1;
	const struct case_material *m = &c->materials[c->bodies[0].material];
	const struct case_body *b = &c->bodies[0];
	double nu = m->poisson_ratio, E = m->youngs_modulus;
	double mv = (1 + nu) * (1 - 2 * nu) / ((1 - nu) * E);    /* 000 Eq. 86 */
	col->q = hypot(c->loads[0].traction[0], c->loads[0].traction[1]);
	col->top = b->max[1];
	col->bottom = b->min[1];
	col->drained_both = c->boundaries[FACE_BOTTOM].drainage == DRAINAGE_DRAINED;
	col->Hd = (col->top - col->bottom) / (col->drained_both ? 2 : 1);
	col->cv = b->hydraulic_conductivity / (c->fluid.density * G * mv);
	return col->q > 0 && col->Hd > 0 ? 0 : -1;
}

/* RMS of (p - p_Terzaghi) / q over n points at positions x[2n]. */
static double rms_error(const struct column *col, double Tv, const double *p, const double *x, long n)
{
	double sum = 0.0;
	for (long i = 0; i < n; i++) {
		double y = x[2 * i + 1], z = col->top - y;
		if (col->drained_both)
			z = fmin(z, y - col->bottom);
		double e = (p[i] - terzaghi_pressure(z, col->Hd, Tv, col->q)) / col->q;
		sum += e * e;
	}
	return sqrt(sum / (double)n);
}

/* Reads the pressure-carrying set of the last frame and prints the line. */
static int report(struct results *r, const struct case_spec *c, const struct column *col)
{
	struct poro_error err = {0};
	long last = results_frame_count(r) - 1;
	const char *set = c->formulation.phases == PHASES_DOUBLE_POINT ? "water" : "soil";
	double t = 0, *p = NULL, *x = NULL;
	long n = 0, nx = 0;
	int width = 0;
	if (last < 0)
		return fail("no frames in the result", NULL);
	int rc = EXIT_INVALID;
	if (results_frame_time(r, last, &t, &err) ||
	    results_frame_read(r, last, set, "pore_pressure", &p, &n, NULL, &err) ||
	    results_frame_read(r, last, set, "x", &x, &nx, &width, &err))
		fail("cannot read the last frame", err.message);
	else if (nx != n || width != 2 || n == 0)
		fail("the last frame has no pressure-carrying points, or x and pore_pressure disagree", NULL);
	else
		rc = 0;
	if (!rc) {
		double Tv = col->cv * t / (col->Hd * col->Hd);
		printf("terzaghi: t = %.4g s (Tv = %.3f), RMS pore-pressure error %.2f%% of q over %ld points\n", t,
		       Tv, 100.0 * rms_error(col, Tv, p, x, n), n);
	}
	free(p);
	free(x);
	return rc;
}

int main(int argc, char **argv)
{
	if (argc != 2) {
		fprintf(stderr, "usage: terzaghi-error DIR   (DIR holds a run's result.h5)\n");
		return EXIT_INVALID;
	}
	char path[PATH_MAX_LEN];
	if (snprintf(path, sizeof path, "%s/result.h5", argv[1]) >= (int)sizeof path)
		return fail("directory name too long", argv[1]);
	struct poro_error err = {0};
	struct results *r = NULL;
	if (results_open(&r, path, &err))
		return fail("no readable result", err.message);
	struct case_spec *c = NULL;
	struct column col;
	int rc;
	if (case_load_string(results_case_json(r), &c, &err))
		rc = fail("the case stored in the result does not load", err.message);
	else if (column_of(c, &col))
		rc = fail("the case is not a loaded consolidation column", c->title);
	else
		rc = report(r, c, &col);
	case_destroy(&c);
	results_close(&r);
	return rc;
}
