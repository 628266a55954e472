/*
 * report.h - what a user wants from a large-deformation run, derived from its result.h5 (000 §5.3,
 * slope failure; §5.4, landslides): per frame the toe and run-out of the sliding soil, the crest
 * settlement, the largest gap between the soil and the water surfaces, the oscillation index of
 * the mean effective stress and the two-cell pattern index of the pore pressure; at one frame the pore pressure along a line. `poro-solve report` is
 * its command line; docs/report.md gives the definitions with the reasons for them.
 *
 * Typical use:
 *
 *     struct report *rep; struct report_settings set = REPORT_SETTINGS_DEFAULT;
 *     if (report_open(&rep, "runs/slope/result.h5", &set, &err)) ...report err.message...
 *     struct report_row *rows; long n;
 *     if (report_frames(rep, &rows, &n, &err)) ...
 *     report_frames_write(stdout, "stdout", rows, n, &err); free(rows); report_close(&rep);
 *
 * Definitions (h = the case's grid cell_size; "soil points" are the rows of a frame's soil set):
 *   toe_x        largest x of the soil points with y > ground + tolerance; NaN when there is none.
 *   runout       front_x(t) - front_x(first frame): how far the soil that came from the slope
 *                travelled. (It was toe_x(t) - toe_x(first frame), which counted foundation soil
 *                heaved in front of the toe: 6.80 m on tests/cases/mc_slope_k1e-3_double_point.json,
 *                where no soil point moved more than 1.09 m; 0.55 m by the slope's own soil.)
 *   front_x      largest x of the soil points seeded above the ground, those whose reference
 *                position y - displacement_y > ground + tolerance: the front of the soil that
 *                came from the slope, blind to foundation soil heaved in front of the toe (which
 *                toe_x counts); NaN when there is none.
 *   bulk_front_x the x beyond which lies REPORT_BULK_FRACTION (1%) of the mass of those same
 *                points: the front of the debris' bulk, which one or a few points running ahead
 *                (a sheet one point thick, or points stopped at a wall) do not move; NaN when there
 *                is no such point.
 *   crest_settlement  s(first frame) - s(t), positive down, with s the surface height at x = crest:
 *                the largest y of the soil points with |x - crest| <= h/2; NaN when there is none.
 *   max_gap, max_gap_x  double point only (NaN in single point): the grid is cut into columns
 *                [origin_x + i h, origin_x + (i + 1) h); in every column holding both soil and
 *                water points, gap = top soil y - top water y; max_gap is the largest gap and
 *                max_gap_x the centre of its column (the leftmost on a tie); NaN when no column
 *                holds both.
 *   oscillation_index  oscillation_index() (oscillation.h) of the soil points, their reference
 *                positions x - displacement, at the seeding spacing h / particles_per_cell of the
 *                case's first body; NaN where that function finds it undefined (zero stress, as
 *                before gravity acts, or no point with two lattice neighbours).
 *   pressure_pattern_index  oscillation_index_pattern() (oscillation.h) of the pore pressure over
 *                the points that carry it (water points in double point, soil points in single
 *                point), at their reference positions on the same lattice, blocks of one cell
 *                (particles_per_cell sites): a pattern of period two cells, which the point and
 *                cell indices score 0 when it is centred on the nodes (docs/numerics.md); NaN
 *                where undefined (zero pressure everywhere, or no full cell between two others).
 *   line sample  the mean pore pressure of the points that carry it (water points in double
 *                point, soil points in single point) within distance h of the sample; NaN when
 *                none is. A line is a polyline (a curved shear band is followed corner by
 *                corner), its samples evenly spaced along its length.
 *
 * Defaults derived from the case stored in the file (struct report_settings, field NAN): they need
 * every body to be a polygon (the slope of tests/cases/mc_slope_*.json and landslide_*.json);
 * otherwise report_open() refuses to guess and asks for the value.
 *   ground     the lowest y of the polygon vertices that are not on the grid's bottom edge: the
 *              foundation's top, the level of the slope's toe.
 *   crest      the x of the highest vertex, the largest x among equally high ones: the crest edge
 *              of a slope facing +x, the direction the toe is measured in.
 *   tolerance  a quarter of the finest seeding spacing, h / (4 max particles_per_cell): below the
 *              lowest row of points seeded above the ground (half a spacing up), well above the
 *              highest row below it (half a spacing down).
 *
 * Ownership: report_open() returns a heap object closed with report_close(); arrays returned
 * through pointers are malloc'd and freed by the caller with free().
 *
 * Errors: PORO_EIO when the file cannot be read (missing, unreadable; the message names it) or a
 * stream cannot be written; PORO_EINVAL for invalid input: a file that is not a result file
 * (results_check_file()), a stored case that does not load, a result without frames, a setting
 * that is not finite, a default that cannot be derived, a malformed line, a time outside the
 * run; PORO_ENOMEM. Like the rest of the library it never prints.
 */
#ifndef PORO_REPORT_H
#define PORO_REPORT_H

#include <math.h>
#include <stdio.h>

#include "error.h"

#define REPORT_CREST_HALF_WIDTH 0.5    /* crest window half-width, in cells */
#define REPORT_LINE_RADIUS 1.0         /* radius a line sample averages over, in cells */
#define REPORT_LINE_SAMPLES 50         /* samples along a line when not given */
#define REPORT_LINE_SAMPLES_MAX 100000
#define REPORT_LINE_VERTICES_MAX 64    /* corners of a sampled path: enough to follow a curved shear band */
#define REPORT_TOLERANCE_SPACINGS 0.25 /* default tolerance, in finest seeding spacings */
#define REPORT_TIME_SLACK 1e-9         /* a time may lie outside the frames by this much of the run's span */
#define REPORT_BULK_FRACTION 0.01      /* bulk_front_x: the share of the slope's soil mass ahead of it */

/* The choices a user may override; NAN asks for the default derived from the case. */
struct report_settings {
	double ground;                /* m: y of the ground level the toe is measured above */
	double crest;                 /* m: x at which the crest settles */
	double tolerance;             /* m, >= 0: a soil point is above the ground when y > ground + tolerance */
};
#define REPORT_SETTINGS_DEFAULT {NAN, NAN, NAN}

/* One frame's quantities (definitions above); NAN where a quantity is undefined. */
struct report_row {
	double time;                  /* s */
	double toe_x;                 /* m */
	double runout;                /* m */
	double front_x;               /* m */
	double bulk_front_x;          /* m */
	double crest_settlement;      /* m, positive down */
	double max_gap;               /* m, soil surface above water surface */
	double max_gap_x;             /* m, centre of the column of max_gap */
	double oscillation_index;     /* 1 */
	double pressure_pattern_index;  /* 1 */
};

/* A path to sample: the polyline through `vertices` corners, with `samples` points evenly spaced
 * along its length, both ends included (a straight line is the path of two corners). */
struct report_line {
	double vertex[REPORT_LINE_VERTICES_MAX][2];  /* m, the corners in order */
	int vertices;                 /* 2 .. REPORT_LINE_VERTICES_MAX */
	int samples;                  /* 2 .. REPORT_LINE_SAMPLES_MAX */
};

struct report_sample {
	double distance;              /* m along the path from its first corner */
	double x, y;                  /* m */
	double pore_pressure;         /* Pa, positive in compression; NAN when no point is in reach */
	int points;                   /* points averaged */
};

struct report;

/* Opens result file `path` (results_read.h), loads the case stored in it and settles the settings:
 * the given ones checked, the NAN ones derived (above). On failure *rep is NULL. */
enum poro_status report_open(struct report **rep, const char *path, const struct report_settings *settings,
			     struct poro_error *err);

/* Closes the file and frees rep; accepts NULL and clears the pointer. */
void report_close(struct report **rep);

/* The settings in effect, every field finite; valid until report_close(). */
const struct report_settings *report_settings_used(const struct report *rep);

/* Computes one row per frame into *rows (malloc'd, *count = the frame count). */
enum poro_status report_frames(struct report *rep, struct report_row **rows, long *count, struct poro_error *err);

/* Parses "x0,y0,x1,y1[,x2,y2 ...][,n]": an even count of numbers is the corners alone (n defaults
 * to REPORT_LINE_SAMPLES), an odd count ends with n. Finite numbers, 2 to REPORT_LINE_VERTICES_MAX
 * corners, no corner equal to the one before it, n an integer in range. PORO_EINVAL naming the text
 * and what is wrong. */
enum poro_status report_line_parse(const char *text, struct report_line *line, struct poro_error *err);

/* Samples the pore pressure along line at the frame nearest to time `at` (NAN: the last frame;
 * the earlier frame on a tie) into *samples (malloc'd, line->samples of them); *frame_time gets
 * that frame's time. PORO_EINVAL when `at` lies outside the frames' times by more than
 * REPORT_TIME_SLACK of their span. */
enum poro_status report_line_sample(struct report *rep, const struct report_line *line, double at,
				    struct report_sample **samples, double *frame_time, struct poro_error *err);

/* The sampling itself, on points of one's own: line->samples samples into samples[], each the mean
 * of p over the n points x[2n] within `radius` (m) of it (report_line_sample passes the frame's
 * carriers and REPORT_LINE_RADIUS cells). For a caller that holds the points, such as a test
 * stepping a simulation; p in whatever sign the caller keeps. */
void report_line_sample_points(const struct report_line *line, const double *x, const double *p, long n,
				double radius, struct report_sample *samples);

/* Write the rows, or the samples, as CSV with a header line ("nan" for NaN) to f; `name` names f
 * in the PORO_EIO message when writing fails. */
enum poro_status report_frames_write(FILE *f, const char *name, const struct report_row *rows, long count,
				     struct poro_error *err);
enum poro_status report_line_write(FILE *f, const char *name, const struct report_sample *samples, int count,
				   struct poro_error *err);

#endif
