/*
 * results_read.h - reading a run's result.h5 back: the frames, their times and datasets, and the
 * case that produced them. For tools and tests; the layout is the contract in schemas/results.md,
 * written by output.c.
 *
 * Typical use:
 *
 *     struct results *r; struct poro_error err = {0};
 *     if (results_open(&r, "runs/terzaghi/result.h5", &err)) ...report err.message...
 *     long last = results_frame_count(r) - 1;
 *     double *p; long n;
 *     if (results_frame_read(r, last, "soil", "pore_pressure", &p, &n, NULL, &err)) ...
 *     ...use p[0 .. n-1]...; free(p); results_close(&r);
 *
 * Which frames count. A file whose /run status is still "running" may end in a frame that was
 * being written when the run was killed; the writer lists a frame in result.xdmf only once it is
 * flushed, so for such a file the frames are those result.xdmf (next to result.h5) lists. In a
 * finished file ("succeeded" or "failed") every frame group counts.
 *
 * HDF5 enters the solver only through output*.c (the writer) and results_read.c (this reader)
 * (STYLE rule 5). Like the rest of the library the reader never prints: HDF5's own error reports
 * are caught and put into the message. Not thread-safe (neither is the serial HDF5 library).
 *
 * Errors: PORO_EIO for a file or object that cannot be opened or read, the message naming the
 * file and the object ("cannot read '/frames/000003/water/x' in 'DIR/result.h5': ..."); PORO_EINVAL
 * for a bad argument (a frame out of range, an unknown set name); PORO_ENOMEM.
 */
#ifndef PORO_RESULTS_READ_H
#define PORO_RESULTS_READ_H

#include "error.h"

struct results;

/* Opens a result file read-only and reads its /case and frame count. The file is not locked, so
 * it may be read while a run is still writing it (schemas/results.md, "Reading while a run is
 * going"). On failure *r is NULL. Close with results_close(). */
enum poro_status results_open(struct results **r, const char *path, struct poro_error *err);

/* Whether path is a result file, for callers that treat a wrong file as invalid input rather than
 * an I/O error (results_open() reports both as PORO_EIO). Opens nothing it keeps. Returns PORO_OK
 * for an HDF5 file with the /case "json" attribute and the /run group, which a result.h5 has from
 * its creation; PORO_EINVAL naming the file and what it lacks when it can be read but is no result
 * file (a directory, not HDF5 at all, or HDF5 without them, such as a checkpoint.h5); PORO_EIO
 * naming the file when it cannot be opened (missing, no permission). */
enum poro_status results_check_file(const char *path, struct poro_error *err);

/* Closes the file and frees r; accepts NULL and clears the pointer. */
void results_close(struct results **r);

/* Frames in the file (see "Which frames count" above); frames are numbered 0 .. count - 1. */
long results_frame_count(const struct results *r);

/* Simulated time of a frame, s (its "time" attribute). */
enum poro_status results_frame_time(struct results *r, long frame, double *time, struct poro_error *err);

/* Whether a frame has a point set: "soil" always, "water" in the double-point formulation only.
 * Returns 1 or 0, or -1 (with err set) when the frame cannot be inspected. */
int results_frame_has_set(struct results *r, long frame, const char *set, struct poro_error *err);

/* Reads dataset `name` of point set `set` ("soil" or "water") of a frame, e.g. "x" (N x 2),
 * "pore_pressure" (N), "stress" (N x 4), as a newly allocated row-major array of rows * width
 * doubles the caller frees with free(). *rows gets N and *width (may be NULL) the columns, 1 for
 * a 1-D dataset. N may be 0 (a water set that has drained out): *values is then still a valid
 * pointer to free. On failure *values is NULL. */
enum poro_status results_frame_read(struct results *r, long frame, const char *set, const char *name,
				    double **values, long *rows, int *width, struct poro_error *err);

/* Reads probe `name` (a name from the case's "probes"): its sample times (s) and values, each
 * [*count], malloc'd and owned by the caller, and its "units" attribute (the caller frees *units).
 * A probe the file does not hold is PORO_EINVAL naming it. */
enum poro_status results_probe_read(struct results *r, const char *name, double **time, double **value,
				    long *count, char **units, struct poro_error *err);

/* The case the run was given (/case attribute "json"), exactly as given; owned by r, valid until
 * results_close(). */
const char *results_case_json(const struct results *r);

#endif
