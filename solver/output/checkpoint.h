/*
 * checkpoint.h - saving a running simulation to DIR/checkpoint.h5 and continuing it from there,
 * so a job whose worker is lost resumes from its last checkpoint instead of from t = 0
 * (docs/service.md §2 "Checkpoints and resume"; the layout is in schemas/results.md).
 *
 * A checkpoint holds everything a step reads that is not rebuilt from the case by sim_create():
 * time and step count, every per-point array of the soil set and (double point) of the water set,
 * including the state frames do not carry (deformation gradient F, elastic left Cauchy-Green
 * tensor Be, model state variables, initial volumes and porosities, body and load indices), the
 * water mass that drained out, the point each point probe follows, and the case JSON as given.
 * Shape-function caches and the deformation-gradient increment are not saved: step 1 and step 8
 * of every step recompute them before they are read.
 *
 * Use (what poro-solve run --resume does):
 *
 *     case_load_file(case_path, &c, &err); sim_create(&s, c, &err);
 *     if (checkpoint_load(s, "DIR/checkpoint.h5")) ...report sim_error(s)->message...
 *     sim_run(s, "DIR", ...);    continues from the checkpoint's step, appending to DIR/result.h5
 *
 * A resumed run ends in the state an uninterrupted run ends in, except that the first pressure
 * solve after a resume factorises the matrix afresh where the uninterrupted run may use
 * conjugate gradients on the previous factor (spd_solve.h), which agree to a relative residual of
 * 1e-12; tests/solver/checkpoint_test.c states the agreement measured.
 *
 * HDF5 enters here through checkpoint.c, one of the solver's HDF5 files (with output*.c and
 * results_read.c). Errors go to sim_error(s); the library prints nothing.
 */
#ifndef PORO_CHECKPOINT_H
#define PORO_CHECKPOINT_H

#include "poro.h"

#define CHECKPOINT_NAME "checkpoint.h5"
#define CHECKPOINT_TMP_NAME "checkpoint.h5.tmp"
#define CHECKPOINT_FORMAT "poro-checkpoint/1"   /* root attribute "format"; changes with the layout */

/* Writes the current state to DIR/checkpoint.h5.tmp, flushes and fsyncs it, renames it to
 * DIR/checkpoint.h5 and fsyncs DIR, so DIR/checkpoint.h5 is always either the previous complete
 * checkpoint or this one. DIR must exist. Returns PORO_EIO (message naming the file and the HDF5
 * object) or PORO_ENOMEM; the previous checkpoint is then left in place. */
enum poro_status checkpoint_write(struct sim *s, const char *dir);

/* Loads a checkpoint into s, a simulation just created from the case the checkpoint was written
 * for. Errors: PORO_EIO when the file cannot be opened or read (missing, truncated, not HDF5);
 * PORO_EINVAL when it is not a checkpoint, was written for another case (the message names the
 * JSON pointer of the first difference), or holds sizes or indices that do not fit the
 * simulation. After a failure s is only fit for sim_destroy(). */
enum poro_status checkpoint_load(struct sim *s, const char *path);

/* 1 when s was loaded from a checkpoint (sim_run then continues its result file), else 0. */
int checkpoint_resumed(const struct sim *s);

#endif
