/*
 * report_line.c - the pore pressure along a line at one frame (report.h): the line parsed from
 * "x0,y0,x1,y1[,n]", the frame nearest the asked time, and at each of n evenly spaced samples the
 * mean pore pressure of the points that carry it (water points in double point, soil points in
 * single point) within REPORT_LINE_RADIUS cells. The points are searched by brute force, n times
 * N distance tests: a report is run once, and 50 samples over the 20,000 points of the paper's
 * slope take a millisecond.
 */
#include "report_internal.h"

#include <stdlib.h>

#define LINE_NUMBERS_MAX 5   /* x0, y0, x1, y1, n */

/* ---- parsing ----------------------------------------------------------------------------------- */

static enum poro_status malformed(const char *text, const char *why, struct poro_error *err)
{
	return poro_error_set(err, PORO_EINVAL, "malformed line '%s': %s; expected x0,y0,x1,y1[,n]", text, why);
}

enum poro_status report_line_parse(const char *text, struct report_line *line, struct poro_error *err)
{
	double v[LINE_NUMBERS_MAX];
	int count = 0;
	text = text ? text : "";
	for (const char *p = text;; count++) {
		char *end;
		if (count == LINE_NUMBERS_MAX)
			return malformed(text, "more than 5 numbers", err);
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
	double n = count == 5 ? v[4] : REPORT_LINE_SAMPLES;
	if (n != floor(n) || n < 2 || n > REPORT_LINE_SAMPLES_MAX)
		return poro_error_set(err, PORO_EINVAL, "line '%s': n = %g samples, expected an integer from 2 to %d",
				      text, n, REPORT_LINE_SAMPLES_MAX);
	if (v[0] == v[2] && v[1] == v[3])
		return poro_error_set(err, PORO_EINVAL, "line '%s': its two ends coincide", text);
	*line = (struct report_line){.from = {v[0], v[1]}, .to = {v[2], v[3]}, .samples = (int)n};
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
	const double dx = line->to[0] - line->from[0], dy = line->to[1] - line->from[1];
	for (int k = 0; !st && k < line->samples; k++) {
		double f = (double)k / (line->samples - 1);
		s[k].distance = f * hypot(dx, dy);
		s[k].x = line->from[0] + f * dx;
		s[k].y = line->from[1] + f * dy;
		sample_at(x, p, n, REPORT_LINE_RADIUS * rep->h, &s[k]);
	}
	free(x);
	free(p);
	if (st)
		return st;
	*out = s;
	return PORO_OK;
}
