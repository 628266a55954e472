/*
 * request_gate.h - what one caller may hold of the server at once (docs/service.md §1
 * "Admission"): requests in progress per bearer token, and submissions being validated at once.
 *
 * Per token: a user or admin token may have --max-requests-per-token requests in progress (long
 * polls, followed logs and downloads included), a worker token --max-requests-per-worker-token
 * (one token often serves many slots on many hosts). Over the limit a request is refused at once
 * with 429 too_many_requests; it costs nothing but its head.
 *
 * Submissions: validating a case builds its tree and runs the solver's loader, the most costly
 * thing a request can ask; at most --max-concurrent-submissions run at once, and a submission that
 * cannot start within SUBMISSION_WAIT_SECONDS gets 503 with Retry-After. With the per-route body
 * limits and the JSON shape limits this bounds the memory all requests together can take.
 */
#ifndef PORO_REQUEST_GATE_H
#define PORO_REQUEST_GATE_H

#include "server.h"

#define SUBMISSION_WAIT_SECONDS 10

struct request_gate;

/* NULL when out of memory. token_capacity bounds the distinct tokens with requests in progress. */
struct request_gate *request_gate_create(int per_token, int per_worker_token, int submissions,
					 int token_capacity);
void request_gate_destroy(struct request_gate **g);

/* Counts a request of the token whose SHA-256 hex is hash: 0, or -1 when the token already has its
 * limit in progress (*limit gets the limit). Every 0 is matched by one request_gate_leave. */
int request_gate_enter(struct request_gate *g, const char *hash, enum role role, int *limit);
void request_gate_leave(struct request_gate *g, const char *hash);

/* Waits up to SUBMISSION_WAIT_SECONDS for a submission's turn: 0, or -1 (*running gets the count). */
int request_gate_submission_enter(struct request_gate *g, int *running);
void request_gate_submission_leave(struct request_gate *g);

#endif
