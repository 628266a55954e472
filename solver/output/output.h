/*
 * output.h - results of a run as one HDF5 file, result.h5, plus result.xdmf for ParaView.
 * The layout is the contract documented in schemas/results.md (DESIGN §4):
 *   /case                  attribute "json": the case as given
 *   /run                   attributes: solver_version, start_time, end_time (ISO 8601 UTC),
 *                          wall_seconds, steps, particles, status ("running", "succeeded", "failed")
 *   /probes/<name>/time    1-D, s;  /probes/<name>/value 1-D, attribute "units"
 *   /frames/<NNNNNN>/      attribute "time" (s), "step"; groups soil/ and (double point) water/ with
 *                          x (N x 2), v (N x 2), displacement (N x 2), pore_pressure (N, Pa,
 *                          positive in compression), porosity (N), volume (N), mass (N);
 *                          soil/ also stress (N x 4: xx, yy, xy, zz, Pa, tension positive),
 *                          plastic_strain (N)
 *
 * Crash safety: after every frame the file is flushed (H5Fflush) and result.xdmf is rewritten
 * atomically (write to a temporary name, rename), so a run killed at any moment leaves every
 * completed frame readable. Probes are buffered in memory and written at each frame and at close.
 *
 * HDF5 enters only through output*.c, checkpoint.c and results_read.c (STYLE rule 5).
 */
#ifndef PORO_OUTPUT_H
#define PORO_OUTPUT_H

#include "error.h"
#include "particles.h"

struct output;

/* The read-only view of a frame the writer needs. water may be NULL (single point: the pore
 * pressure lives on the soil set and is written there). */
struct output_frame {
	double time;
	long step;
	const struct particles *soil;
	const struct particles *water;   /* NULL for single point */
};

/* Creates DIR/result.h5 (and later DIR/result.xdmf); DIR must exist. case_json is stored as /case.
 * probe_names/probe_units: probe_count names and unit strings. */
enum poro_status output_create(struct output **out, const char *dir, const char *case_json,
			       const char *solver_version, int probe_count, const char *const *probe_names,
			       const char *const *probe_units, struct poro_error *err);

/* Continues an existing DIR/result.h5 for a run resumed at a checkpoint: keeps the frames and
 * probe samples at times <= keep_until, deletes later ones (and a frame a killed run left half
 * written), sets /run status back to "running" with attribute resumed_from_time, rewrites
 * result.xdmf to list the kept frames; new frames and samples are then appended after them.
 * PORO_EINVAL when the file holds another case (case_json_difference) or inconsistent probe
 * series; PORO_EIO when it cannot be opened or changed. */
enum poro_status output_reopen(struct output **out, const char *dir, const char *case_json,
			       const char *solver_version, int probe_count, const char *const *probe_names,
			       const char *const *probe_units, double keep_until, struct poro_error *err);

/* Writes the buffered probe samples and makes the file durable (flush and fsync), so a copy taken
 * now holds every frame and sample so far: done before each checkpoint. */
enum poro_status output_flush(struct output *o, struct poro_error *err);

/* Appends one sample to each probe (values[probe_count]). Buffered; no I/O. */
enum poro_status output_probe_sample(struct output *o, double time, const double *values, struct poro_error *err);

/* Writes one frame, flushes, and rewrites result.xdmf. */
enum poro_status output_frame_write(struct output *o, const struct output_frame *f, struct poro_error *err);

/* Writes /run attributes (status "succeeded" or "failed", steps, particles, wall seconds), the
 * probe series, closes the file. Safe to call once; output_destroy() after it. */
enum poro_status output_finish(struct output *o, const char *status, long steps, long particles,
			       double wall_seconds, struct poro_error *err);

void output_destroy(struct output **o);

#endif
