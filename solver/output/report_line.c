/*
 * report_line.c - the pore pressure along a path at one frame (report.h): the path parsed from
 * "x0,y0,x1,y1[,x2,y2 ...][,n]" (a polyline, so that a curved shear band can be followed), the
 * frame nearest the asked time, and at each of n samples evenly spaced along the path's length the
 * mean pore pressure of the points that carry it (water points in double point, soil points in
 * single point) within REPORT_LINE_RADIUS cells. The points are searched by brute force, n times
 * N distance tests: a report is run once, and 50 samples over the 20,000 points of the paper's
 * slope take a millisecond.
 */
#include "report_internal.h"

#include <stdlib.h>

#define LINE_NUMBERS_MAX (2 * REPORT_LINE_VERTICES_MAX + 1)   /* the corners, then n */

/* ---- parsing ----------------------------------------------------------------------------------- */

static enum poro_status malformed(const char *text, const char *why, struct poro_error *err)
{
	return poro_error_set(err, PORO_EINVAL, "malformed line '%s': %s; expected x0,y0,x1,y1[,x2,y2 ...][,n]",
			      text, why);
}

enum poro_status report_line_parse(const char *text, struct report_line *line, struct poro_error *err)
{
	double v[LINE_NUMBERS_MAX];
	int count = 0;
	text = text ? text : "";
	for (const char *p = text;; count++) {
		char *end;
		if (count == LINE_NUMBERS_MAX)
			return poro_error_set(err, PORO_EINVAL, "line '%s': more than %d corners", text,
					      REPORT_LINE_VERTICES_MAX);
		v[count] = strtod(p, &end);
		if (end == p || !isfinite(v[count]))
			return malformed(text, "an item is not a finite number", err);
		if (!*end) {
			count++;
			break;
		}
		if (*end != ',')
			return malformed(text, "the numbers must be separated by commas", err);
		p = end + 1;
	}
	if (count < 4)
		return malformed(text, "fewer than 4 numbers", err);
	/* An odd count ends with n; "x0,y0,x1,y1,n" keeps the meaning it had for a straight line. */
	double n = count % 2 ? v[count - 1] : REPORT_LINE_SAMPLES;
	if (n != floor(n) || n < 2 || n > REPORT_LINE_SAMPLES_MAX)
		return poro_error_set(err, PORO_EINVAL, "line '%s': n = %g samples, expected an integer from 2 to %d",
				      text, n, REPORT_LINE_SAMPLES_MAX);
	line->vertices = count / 2;
	line->samples = (int)n;
	for (int c = 0; c < line->vertices; c++) {
		line->vertex[c][0] = v[2 * c];
		line->vertex[c][1] = v[2 * c + 1];
		if (c > 0 && v[2 * c] == v[2 * c - 2] && v[2 * c + 1] == v[2 * c - 1])
			return poro_error_set(err, PORO_EINVAL, "line '%s': corner %d coincides with corner %d", text,
					      c + 1, c);
	}
	return PORO_OK;
}

/* ---- sampling ---------------------------------------------------------------------------------- */

/* The frame nearest `at` (NAN: the last), or PORO_EINVAL when `at` lies outside the run. */
static enum poro_status nearest_frame(struct report *rep, double at, long *frame, double *time,
				      struct poro_error *err)
{
	double first, last;
	enum poro_status st = results_frame_time(rep->results, 0, &first, err);
	if (!st)
		st = results_frame_time(rep->results, rep->frames - 1, &last, err);
	if (st)
		return st;
	*frame = rep->frames - 1;
	*time = last;
	if (isnan(at))
		return PORO_OK;
	const double slack = REPORT_TIME_SLACK * fmax(last - first, fabs(last));
	if (!isfinite(at) || at < first - slack || at > last + slack)
		return poro_error_set(err, PORO_EINVAL, "time %g s is outside the run: the frames of '%s' span %g to %g s",
				      at, rep->path, first, last);
	double best = INFINITY;
	for (long k = 0; k < rep->frames; k++) {
		double t;
		if ((st = results_frame_time(rep->results, k, &t, err)))
			return st;
		if (fabs(t - at) < best)
			best = fabs(t - at), *frame = k, *time = t;
	}
	return PORO_OK;
}

/* Mean of p over the points x[n] within radius r of (sx, sy). */
static void sample_at(const double *x, const double *p, long n, double r, struct report_sample *s)
{
	double sum = 0.0;
	s->points = 0;
	for (long i = 0; i < n; i++) {
		double dx = x[2 * i] - s->x, dy = x[2 * i + 1] - s->y;
		if (dx * dx + dy * dy <= r * r)
			sum += p[i], s->points++;
	}
	s->pore_pressure = s->points ? sum / s->points : NAN;
}

/* Length of the polyline, m. */
static double path_length(const struct report_line *line)
{
	double length = 0.0;
	for (int c = 1; c < line->vertices; c++)
		length += hypot(line->vertex[c][0] - line->vertex[c - 1][0], line->vertex[c][1] - line->vertex[c - 1][1]);
	return length;
}

/* Puts sample s at distance d along the path: on the segment where the corners' running length
 * passes d (the last corner exactly at the full length, whatever the round-off of the sum). */
static void place_sample(const struct report_line *line, double d, struct report_sample *s)
{
	const double (*v)[2] = line->vertex;
	int last = line->vertices - 1;
	double start = 0.0;
	s->distance = d;
	for (int c = 1; c <= last; c++) {
		double length = hypot(v[c][0] - v[c - 1][0], v[c][1] - v[c - 1][1]);
		if (d <= start + length || c == last) {
			double f = fmin(fmax((d - start) / length, 0.0), 1.0);
			s->x = v[c - 1][0] + f * (v[c][0] - v[c - 1][0]);
			s->y = v[c - 1][1] + f * (v[c][1] - v[c - 1][1]);
			return;
		}
		start += length;
	}
}

void report_line_sample_points(const struct report_line *line, const double *x, const double *p, long n,
				double radius, struct report_sample *samples)
{
	const double length = path_length(line);
	for (int k = 0; k < line->samples; k++) {
		place_sample(line, length * k / (line->samples - 1), &samples[k]);
		sample_at(x, p, n, radius, &samples[k]);
	}
}

enum poro_status report_line_sample(struct report *rep, const struct report_line *line, double at,
				    struct report_sample **out, double *frame_time, struct poro_error *err)
{
	*out = NULL;
	long frame, n = 0, np = 0;
	double *x = NULL, *p = NULL;
	const char *carrier = rep->double_point ? "water" : "soil";
	enum poro_status st = nearest_frame(rep, at, &frame, frame_time, err);
	if (!st)
		st = report_read(rep, frame, carrier, "x", 2, &x, &n, err);
	if (!st)
		st = report_read(rep, frame, carrier, "pore_pressure", 1, &p, &np, err);
	if (!st && np != n)
		st = poro_error_set(err, PORO_EIO, "frame %ld of '%s': %ld %s positions but %ld pore pressures", frame,
				    rep->path, n, carrier, np);
	struct report_sample *s = st ? NULL : malloc(sizeof *s * (size_t)line->samples);
	if (!st && !s)
		st = poro_error_set(err, PORO_ENOMEM, "cannot allocate %d line samples", line->samples);
	if (!st)
		report_line_sample_points(line, x, p, n, REPORT_LINE_RADIUS * rep->h, s);
	free(x);
	free(p);
	if (st)
		return st;
	*out = s;
	return PORO_OK;
}
