/*
 * backoff.c - capped exponential backoff with jitter, see backoff.h. The jitter uses a per-thread
 * rand_r state seeded from the clock and the thread, which is plenty for spreading retries.
 */
#include "backoff.h"

#include <pthread.h>
#include <stdlib.h>
#include <time.h>

static double uniform01(void)
{
	static _Thread_local unsigned seed;
	if (!seed) {
		struct timespec ts;
		clock_gettime(CLOCK_REALTIME, &ts);
		seed = (unsigned)ts.tv_nsec ^ (unsigned)(size_t)pthread_self() ^ 0x9e3779b9u;
	}
	return rand_r(&seed) / ((double)RAND_MAX + 1.0);
}

double backoff_fail(struct backoff *b, double now)
{
	b->delay = b->delay <= 0 ? BACKOFF_FIRST : b->delay * 2;
	if (b->delay > BACKOFF_MAX)
		b->delay = BACKOFF_MAX;
	b->failures++;
	double wait = b->delay * (0.5 + 0.5 * uniform01());
	b->next_at = now + wait;
	return wait;
}

void backoff_reset(struct backoff *b)
{
	b->delay = 0;
	b->next_at = 0;
	b->failures = 0;
}

int backoff_due(const struct backoff *b, double now)
{
	return now >= b->next_at;
}
