/*
 * backoff.h - capped exponential backoff with jitter for retried HTTP calls: the first retry waits
 * about BACKOFF_FIRST seconds, each further failure doubles the delay up to BACKOFF_MAX, and every
 * delay is drawn uniformly from [d/2, d] so that many workers that lost the server at once do not
 * come back in step.
 */
#ifndef PORO_BACKOFF_H
#define PORO_BACKOFF_H

#define BACKOFF_FIRST 0.2
#define BACKOFF_MAX 10.0

struct backoff {
	double delay;    /* the undrawn delay of the next failure, seconds; 0 before the first */
	double next_at;  /* worker_now() before which no retry is due; 0 when not failing */
	int failures;    /* consecutive failures */
};

/* Records a failure at time now; returns the drawn delay and sets next_at. */
double backoff_fail(struct backoff *b, double now);

/* Records a success: the next failure starts again from BACKOFF_FIRST. */
void backoff_reset(struct backoff *b);

/* 1 when a call may be made at time now. */
int backoff_due(const struct backoff *b, double now);

#endif
