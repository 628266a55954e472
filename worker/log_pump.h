/*
 * log_pump.h - reads a solver's stdout and stderr (one pipe) on its own thread, so the solver never
 * blocks on a full pipe while the worker waits on the network. Complete lines are checked as UTF-8
 * (invalid bytes become '?', keeping byte counts), kept in memory until the server has them, copied
 * to a local log file, and parsed for what poro-solve reports (cli/poro_solve.c):
 *   "step N/M  t = T s  wall = W s  U us per material-point step"   progress
 *   "checkpoint step=N time=T"                                       a checkpoint is complete
 *   "poro-solve: ..." and the lines after it                         the error message
 * Log offsets count bytes of the text as sent; the text between acked and total is unsent.
 */
#ifndef PORO_LOG_PUMP_H
#define PORO_LOG_PUMP_H

#include <pthread.h>
#include <stdio.h>

/* A line longer than this is passed on in pieces. */
#define LOG_PUMP_LINE_MAX (64 * 1024)
/* Length kept of the solver's error message. */
#define LOG_PUMP_ERROR_MAX 1000

struct log_progress {
	int valid;          /* a progress line has been seen */
	long step;          /* steps done */
	long steps_total;   /* steps the run will take */
	double time;        /* simulated time, s */
	double us_per_mp_step; /* microseconds per material-point step */
};

struct log_pump {
	pthread_t thread;
	int fd;                  /* read end of the solver's pipe; closed by the thread at EOF */
	FILE *file;              /* local copy of the log, or NULL */
	pthread_mutex_t lock;    /* guards every field below */
	char *text;              /* unsent text: bytes acked .. total */
	size_t len, cap;
	long long acked;         /* log offset of text[0]: the server holds everything before */
	long long total;         /* log offset after the last byte read */
	int eof;                 /* the pipe is closed (the solver and its children are gone) */
	struct log_progress progress;
	int checkpoints;         /* "checkpoint" lines seen */
	char error[LOG_PUMP_ERROR_MAX + 1]; /* the last "poro-solve: ..." line and those after it */
	char partial[LOG_PUMP_LINE_MAX]; /* an incomplete line, owned by the thread */
	size_t partial_len;
};

/* Starts the thread reading fd, copying to log_path (NULL: no copy). 0, or -1 with errno. */
int log_pump_start(struct log_pump *p, int fd, const char *log_path);

/* Waits for EOF and the thread's end, then frees the buffers. */
void log_pump_release(struct log_pump *p);

/* Copies up to max unsent bytes, ending at a line end when one is within reach, into dst.
 * Returns the byte count and the log offset of dst[0] in *offset. */
size_t log_pump_peek(struct log_pump *p, char *dst, size_t max, long long *offset);

/* The server holds every byte before offset: drop them from memory. */
void log_pump_ack(struct log_pump *p, long long offset);

/* Unsent byte count, and whether the pipe has closed. */
long long log_pump_unsent(struct log_pump *p, int *eof);

/* Copies of the parsed state. */
struct log_progress log_pump_progress(struct log_pump *p);
int log_pump_checkpoints(struct log_pump *p);
void log_pump_error(struct log_pump *p, char *dst, size_t size);

#endif
