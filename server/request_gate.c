/*
 * request_gate.c - per-token counts of requests in progress and the submissions' turnstile
 * (request_gate.h). Tokens are counted by their SHA-256 hex (key_counts.h).
 */
#include "request_gate.h"

#include "key_counts.h"

#include <errno.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define HASH_HEX 64

struct request_gate {
	pthread_mutex_t lock;
	pthread_cond_t turn;          /* a submission left */
	int per_token, per_worker_token, submissions, running;
	struct key_counts tokens;
};

struct request_gate *request_gate_create(int per_token, int per_worker_token, int submissions, int token_capacity)
{
	struct request_gate *g = calloc(1, sizeof *g);
	if (!g || key_counts_init(&g->tokens, HASH_HEX, (size_t)token_capacity) != 0) {
		free(g);
		return NULL;
	}
	g->per_token = per_token;
	g->per_worker_token = per_worker_token;
	g->submissions = submissions;
	pthread_mutex_init(&g->lock, NULL);
	pthread_cond_init(&g->turn, NULL);
	return g;
}

void request_gate_destroy(struct request_gate **gp)
{
	struct request_gate *g = gp ? *gp : NULL;
	if (!g)
		return;
	pthread_mutex_destroy(&g->lock);
	pthread_cond_destroy(&g->turn);
	key_counts_release(&g->tokens);
	free(g);
	*gp = NULL;
}

int request_gate_enter(struct request_gate *g, const char *hash, enum role role, int *limit)
{
	int max = role == ROLE_WORKER ? g->per_worker_token : g->per_token;
	*limit = max;
	pthread_mutex_lock(&g->lock);
	/* a full table refuses a new token rather than lose count: it holds as many tokens as there
	 * can be connections, so this cannot happen while every request holds a connection */
	int ok = key_counts_get(&g->tokens, hash) < max && key_counts_add(&g->tokens, hash, 1) > 0;
	pthread_mutex_unlock(&g->lock);
	return ok ? 0 : -1;
}

void request_gate_leave(struct request_gate *g, const char *hash)
{
	pthread_mutex_lock(&g->lock);
	key_counts_add(&g->tokens, hash, -1);
	pthread_mutex_unlock(&g->lock);
}

int request_gate_submission_enter(struct request_gate *g, int *running)
{
	struct timespec until;
	clock_gettime(CLOCK_REALTIME, &until);
	until.tv_sec += SUBMISSION_WAIT_SECONDS;
	pthread_mutex_lock(&g->lock);
	int rc = 0;
	while (g->running >= g->submissions && rc != ETIMEDOUT)
		rc = pthread_cond_timedwait(&g->turn, &g->lock, &until);
	int ok = g->running < g->submissions;
	if (ok)
		g->running++;
	*running = g->running;
	pthread_mutex_unlock(&g->lock);
	return ok ? 0 : -1;
}

void request_gate_submission_leave(struct request_gate *g)
{
	pthread_mutex_lock(&g->lock);
	g->running--;
	pthread_cond_signal(&g->turn);
	pthread_mutex_unlock(&g->lock);
}
