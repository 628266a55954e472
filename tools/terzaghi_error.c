/*
 * terzaghi_error.c - the terzaghi-error command: how far a finished consolidation run is from
 * Terzaghi's closed form.
 *
 *   terzaghi-error DIR     reads DIR/result.h5 and prints one line, e.g.
 *   terzaghi: t = 0.981 s, RMS pore-pressure error 0.26% of q over 640 points
 *
 * The case is taken from the file's /case, so the command needs nothing but the run directory.
 * For the last frame it computes the RMS over the points that carry pore pressure (the water set
 * in double point, the soil set in single point) of (p - p_Terzaghi) / q, each point at the soil's
 * reference height there, the measure of 000 §5.1 and tests/verify/consolidation_test.c, with the
 * solver's own figure function (figures.h: the terzaghi_rms a run reports in its metrics.json is
 * this number). Symbols as in the paper (000 Eqs. 84-86):
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

#include "case.h"
#include "figures.h"
#include "particles.h"
#include "results_read.h"

#define EXIT_INVALID 2
#define PATH_MAX_LEN 4096

static int fail(const char *what, const char *detail)
{
	fprintf(stderr, "terzaghi-error: %s%s%s\n", what, detail ? ": " : "", detail ? detail : "");
	return EXIT_INVALID;
}

/* Reads the last frame: the pressure-carrying set (p, x) and the soil set (x, displacement), from
 * which the soil's reference positions x0 = x - displacement give each point's reference height. */
static int report(struct results *r, const struct case_spec *c)
{
	struct poro_error err = {0};
	long last = results_frame_count(r) - 1;
	const char *set = c->formulation.phases == PHASES_DOUBLE_POINT ? "water" : "soil";
	double t = 0, *p = NULL, *x = NULL, *sx = NULL, *su = NULL;
	long n = 0, nx = 0, ns = 0, nu = 0;
	int width = 0, swidth = 0, uwidth = 0;
	if (last < 0)
		return fail("no frames in the result", NULL);
	int rc = EXIT_INVALID;
	if (results_frame_time(r, last, &t, &err) ||
	    results_frame_read(r, last, set, "pore_pressure", &p, &n, NULL, &err) ||
	    results_frame_read(r, last, set, "x", &x, &nx, &width, &err) ||
	    results_frame_read(r, last, "soil", "x", &sx, &ns, &swidth, &err) ||
	    results_frame_read(r, last, "soil", "displacement", &su, &nu, &uwidth, &err))
		fail("cannot read the last frame", err.message);
	else if (nx != n || width != 2 || n == 0 || ns != nu || swidth != 2 || uwidth != 2 || ns == 0)
		fail("the last frame has no pressure-carrying points, or its arrays disagree", NULL);
	else
		rc = 0;
	if (!rc) {
		for (long i = 0; i < 2 * ns; i++)
			su[i] = sx[i] - su[i];    /* the reference positions */
		struct particles soil = { .n = (idx_t)ns, .x = sx, .x0 = su };
		double rms = figure_terzaghi_rms(c, &soil, t, p, x, n);
		if (isnan(rms))
			rc = fail("the case is not a loaded consolidation column", c->title);
		else
			printf("terzaghi: t = %.4g s, RMS pore-pressure error %.2f%% of q over %ld points\n", t, 100.0 * rms, n);
	}
	free(p);
	free(x);
	free(sx);
	free(su);
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
	int rc;
	if (case_load_string(results_case_json(r), &c, &err))
		rc = fail("the case stored in the result does not load", err.message);
	else
		rc = report(r, c);
	case_destroy(&c);
	results_close(&r);
	return rc;
}
