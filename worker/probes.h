/*
 * probes.h - the probe series of a result.h5 the worker is about to upload, extracted into
 * upload/probes.json by `poro-solve probes` in a child process (docs/service.md §3, "Probes").
 *
 * A result file is untrusted input for whoever parses it: libhdf5 can crash or loop on a damaged
 * one. So the file is parsed neither by the server nor by the worker itself, but by a child with
 * its own process group, the job's memory limit (--memory-limit-mb) and PROBES_SECONDS of wall
 * time, after which its group is killed. The job's thread only polls it, so heartbeats and log
 * chunks go on while it runs. A failed extraction costs the job nothing but its probes.json.
 */
#ifndef PORO_PROBES_H
#define PORO_PROBES_H

#include <stddef.h>
#include <sys/types.h>

/* Wall time one extraction may take, seconds. The probe datasets take well under a second even
 * for long runs; the frames, written after them, take longer for large runs, and a time-out
 * there costs only the frames (the probes are already whole on disk). */
#define PROBES_SECONDS 60.0
/* What the child printed (its error message) that is kept, bytes. */
#define PROBES_MESSAGE_MAX 512
/* The files it writes, relative to the job directory: the probes, and the frames in the
 * dashboard's compact form with their index (poro-solve probes --frames upload). */
#define PROBES_OUT "upload/probes.json"
#define PROBES_FRAMES_DIR "upload"
#define PROBES_FRAMES_BIN "upload/frames.bin"
#define PROBES_FRAMES_INDEX "upload/frames.json"

struct probes_run {
	pid_t pid;                          /* the running child, 0 for none */
	int fd;                             /* read end of its output, -1 for none */
	double started;                     /* worker_now() when it started */
	char message[PROBES_MESSAGE_MAX];   /* its output so far, NUL-terminated */
	size_t message_len;
};

enum probes_state { PROBES_NONE, PROBES_RUNNING, PROBES_DONE, PROBES_FAILED };

/* A run with nothing started; probes_stop() releases it. */
void probes_init(struct probes_run *p);

/* Starts `poro-solve probes RESULT --job ID --attempt N --out upload/probes.json --frames upload`
 * in dir, after removing what an earlier extraction wrote there. probes.json appears only whole
 * (written and renamed), before the frames are written: when the child fails or is killed later,
 * a probes.json present is this extraction's and complete, and only the frames are lost., result
 * being relative to dir; an extraction still running is stopped first. 0, or -1 with err. */
int probes_start(struct probes_run *p, const char *dir, const char *result, long long id, int attempt, char *err,
		 size_t err_size);

/* Where the run is, without blocking: PROBES_RUNNING; PROBES_DONE once it exited 0 (the file is
 * complete); PROBES_FAILED with why in err (its exit status or signal, or the time limit, and what
 * it printed); PROBES_NONE when nothing runs. DONE and FAILED are reported once. */
enum probes_state probes_poll(struct probes_run *p, double now, char *err, size_t err_size);

/* Kills and reaps a running extraction; nothing happens when none runs. */
void probes_stop(struct probes_run *p);

#endif
