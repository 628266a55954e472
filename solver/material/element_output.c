/*
 * element_output.c - the single-element driver's files (element.h): element.csv for programs and
 * element.svg for people, two plots drawn by hand (no plotting library): q against p and q against
 * axial strain, stresses in kPa and strains in percent, axes through nice round ticks.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "element.h"

#define PATH_SIZE 4096
#define PANEL_WIDTH 460.0          /* px per plot, margins included */
#define PANEL_HEIGHT 360.0
#define MARGIN_LEFT 70.0
#define MARGIN_RIGHT 20.0
#define MARGIN_TOP 40.0
#define MARGIN_BOTTOM 50.0
#define TICKS 5                    /* about this many intervals per axis */

static enum poro_status write_csv(const struct element_result *r, const char *path, struct poro_error *err)
{
	FILE *f = fopen(path, "w");
	if (!f)
		return poro_error_set(err, PORO_EIO, "cannot create '%s': %s", path, strerror(errno));
	fprintf(f, "axial_strain,p,q,volumetric_strain");
	for (int k = 0; k < r->output_count; k++)
		fprintf(f, ",%s", r->output_names[k]);
	fprintf(f, "\n");
	for (int i = 0; i < r->rows; i++) {
		const struct element_row *w = &r->row[i];
		fprintf(f, "%.12g,%.12g,%.12g,%.12g", w->axial_strain, w->p, w->q, w->volumetric_strain);
		for (int k = 0; k < r->output_count; k++)
			fprintf(f, ",%.12g", w->outputs[k]);
		fprintf(f, "\n");
	}
	if (fclose(f))
		return poro_error_set(err, PORO_EIO, "cannot write '%s': %s", path, strerror(errno));
	return PORO_OK;
}

/* An axis: data range widened to nice ticks (1, 2 or 5 times a power of ten), 0 included. */
struct axis {
	double lo, hi, step;
};

static struct axis nice_axis(double lo, double hi)
{
	lo = fmin(lo, 0), hi = fmax(hi, 0);
	if (hi - lo <= 0)
		hi = lo + 1;
	double raw = (hi - lo) / TICKS, power = pow(10, floor(log10(raw))), unit = raw / power;
	double step = (unit <= 1 ? 1 : unit <= 2 ? 2 : unit <= 5 ? 5 : 10) * power;
	struct axis a = { floor(lo / step) * step, ceil(hi / step) * step, step };
	return a;
}

/* One plot at horizontal offset x0: x[i] against y[i], n points. */
static void plot(FILE *f, double x0, const char *title, const char *xlabel, const char *ylabel, const double *x,
		 const double *y, int n)
{
	double xmin = x[0], xmax = x[0], ymin = y[0], ymax = y[0];
	for (int i = 1; i < n; i++) {
		xmin = fmin(xmin, x[i]), xmax = fmax(xmax, x[i]);
		ymin = fmin(ymin, y[i]), ymax = fmax(ymax, y[i]);
	}
	struct axis ax = nice_axis(xmin, xmax), ay = nice_axis(ymin, ymax);
	double left = x0 + MARGIN_LEFT, right = x0 + PANEL_WIDTH - MARGIN_RIGHT;
	double top = MARGIN_TOP, bottom = PANEL_HEIGHT - MARGIN_BOTTOM;
#define PX(v) (left + ((v) - ax.lo) / (ax.hi - ax.lo) * (right - left))
#define PY(v) (bottom - ((v) - ay.lo) / (ay.hi - ay.lo) * (bottom - top))
	fprintf(f, "<g>\n<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\" font-weight=\"bold\">%s</text>\n",
		(left + right) / 2, top - 16, title);
	fprintf(f, "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" fill=\"none\" stroke=\"#444\"/>\n",
		left, top, right - left, bottom - top);
	for (int i = 0; ax.lo + i * ax.step <= ax.hi + 1e-9 * ax.step; i++) {
		double v = ax.lo + i * ax.step, px = PX(v);
		fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#ddd\"/>\n", px, top, px, bottom);
		fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">%g</text>\n", px, bottom + 16,
			fabs(v) < 1e-12 * ax.step ? 0.0 : v);
	}
	for (int i = 0; ay.lo + i * ay.step <= ay.hi + 1e-9 * ay.step; i++) {
		double v = ay.lo + i * ay.step, py = PY(v);
		fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#ddd\"/>\n", left, py, right, py);
		fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"end\">%g</text>\n", left - 6, py + 4,
			fabs(v) < 1e-12 * ay.step ? 0.0 : v);
	}
	fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">%s</text>\n", (left + right) / 2, bottom + 36,
		xlabel);
	fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\" transform=\"rotate(-90 %.1f %.1f)\">%s</text>\n",
		x0 + 18, (top + bottom) / 2, x0 + 18, (top + bottom) / 2, ylabel);
	fprintf(f, "<polyline fill=\"none\" stroke=\"#c0392b\" stroke-width=\"1.5\" points=\"");
	for (int i = 0; i < n; i++)
		fprintf(f, "%.2f,%.2f ", PX(x[i]), PY(y[i]));
	fprintf(f, "\"/>\n</g>\n");
#undef PX
#undef PY
}

/* Escapes &, < and > of a title for XML into out[size]. */
static const char *xml_text(const char *s, char *out, size_t size)
{
	size_t n = 0;
	for (; *s && n + 6 < size; s++) {
		const char *e = *s == '&' ? "&amp;" : *s == '<' ? "&lt;" : *s == '>' ? "&gt;" : NULL;
		if (e) {
			memcpy(out + n, e, strlen(e));
			n += strlen(e);
		} else {
			out[n++] = *s;
		}
	}
	out[n] = '\0';
	return out;
}

static enum poro_status write_svg(const struct element_case *c, const struct element_result *r, const char *path,
				  struct poro_error *err)
{
	FILE *f = fopen(path, "w");
	if (!f)
		return poro_error_set(err, PORO_EIO, "cannot create '%s': %s", path, strerror(errno));
	double width = 2 * PANEL_WIDTH, height = PANEL_HEIGHT + 24;
	char title[4 * sizeof c->title];
	static const char *const tests[] = { "drained", "undrained" };
	fprintf(f, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
		   "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" viewBox=\"0 0 %.0f %.0f\" "
		   "font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n",
		width, height, width, height);
	fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">%s (%s triaxial, confining pressure %g kPa)</text>\n",
		width / 2, height - 6, c->title[0] ? xml_text(c->title, title, sizeof title) : "single element",
		tests[c->test], c->confining_pressure / 1e3);
	double *p = NULL, *q = NULL, *ea = NULL;
	size_t n = (size_t)r->rows;
	p = malloc(3 * n * sizeof *p);
	if (!p) {
		fclose(f);
		return poro_error_set(err, PORO_ENOMEM, "cannot allocate the element plot");
	}
	q = p + n, ea = q + n;
	for (size_t i = 0; i < n; i++) {
		p[i] = r->row[i].p / 1e3;
		q[i] = r->row[i].q / 1e3;
		ea[i] = r->row[i].axial_strain * 100;
	}
	plot(f, 0, "q against p", "p, mean effective stress (kPa)", "q, deviator stress (kPa)", p, q, r->rows);
	plot(f, PANEL_WIDTH, "q against axial strain", "axial strain (%, negative = compression)",
	     "q, deviator stress (kPa)", ea, q, r->rows);
	fprintf(f, "</svg>\n");
	free(p);
	if (fclose(f))
		return poro_error_set(err, PORO_EIO, "cannot write '%s': %s", path, strerror(errno));
	return PORO_OK;
}

enum poro_status element_write(const struct element_case *c, const struct element_result *r, const char *dir,
			       struct poro_error *err)
{
	char path[PATH_SIZE];
	if (mkdir(dir, 0777) && errno != EEXIST)
		return poro_error_set(err, PORO_EIO, "cannot create output directory '%s': %s", dir, strerror(errno));
	if (snprintf(path, sizeof path, "%s/element.csv", dir) >= (int)sizeof path)
		return poro_error_set(err, PORO_EIO, "output directory name too long: '%s'", dir);
	enum poro_status st = write_csv(r, path, err);
	if (st)
		return st;
	snprintf(path, sizeof path, "%s/element.svg", dir);
	return write_svg(c, r, path, err);
}
