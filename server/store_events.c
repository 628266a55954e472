/*
 * store_events.c - a line in the server's log for every row of `events` (a job's change of state,
 * or a cancel request), once the transaction that wrote it has committed (store_internal.h):
 *
 *   level=info msg=job_state job=12 from=queued to=running attempt=1 worker=node3:4711 actor=node3:4711 reason="claimed on host 'node3'"
 *
 * How the rows are seen: a TEMP trigger on the writer's connection calls the SQL function
 * poro_event_note() for every row inserted into events, wherever in the store it is written
 * (job_transition, job_event), with the row and the worker id then holding the job's lease
 * (jobs.worker). The notes wait in the store until the batch ends: a write that fails is rolled
 * back to its SAVEPOINT and its notes are dropped with it (store_events_rollback), a batch whose
 * COMMIT fails logs nothing, and a committed batch logs its notes in the order they were written.
 * So the log says only what the database holds, and says it after it is durable. A TEMP trigger
 * lives in the connection, not in the database file: nothing of it is stored or migrated.
 *
 * The worker is named when the job was or became running (the lease's worker: the claiming one
 * on queued -> running, the one that held it on running -> anything); the actor is who did it
 * (a user, a worker id, "reaper"); the reason is the event's detail (a finish's message, "lease
 * expired", ...). A note whose memory cannot be had is counted and one warning says how many
 * lines were lost.
 */
#include "log.h"
#include "store_internal.h"

#include <stdlib.h>
#include <string.h>

#define STATE_NAME_MAX 16

struct event_note {
	long long job;
	int attempt;
	int has_from; /* 0 for the row of a submission (no state before) */
	char from[STATE_NAME_MAX], to[STATE_NAME_MAX];
	char worker[SERVER_NAME_MAX + 1]; /* "" when no worker held the job */
	char actor[SERVER_NAME_MAX + 1];
	char *detail; /* owned; NULL for none */
};

static void copy_text(char *out, size_t size, sqlite3_value *v)
{
	const unsigned char *t = sqlite3_value_text(v);
	snprintf(out, size, "%s", t ? (const char *)t : "");
}

static struct event_note *note_slot(struct store *s)
{
	if (s->note_count == s->note_cap) {
		int cap = s->note_cap ? 2 * s->note_cap : 16;
		struct event_note *grown = realloc(s->notes, (size_t)cap * sizeof *grown);
		if (!grown)
			return NULL;
		s->notes = grown;
		s->note_cap = cap;
	}
	return &s->notes[s->note_count++];
}

/* poro_event_note(job_id, from_state, to_state, attempt, actor, detail, worker): called by the
 * trigger in the writer thread, inside the write's transaction. */
static void note_event(sqlite3_context *ctx, int argc, sqlite3_value **argv)
{
	struct store *s = sqlite3_user_data(ctx);
	struct event_note *n = note_slot(s);
	if (!n) {
		s->notes_lost++;
		return;
	}
	memset(n, 0, sizeof *n);
	n->job = sqlite3_value_int64(argv[0]);
	n->has_from = sqlite3_value_type(argv[1]) != SQLITE_NULL;
	copy_text(n->from, sizeof n->from, argv[1]);
	copy_text(n->to, sizeof n->to, argv[2]);
	n->attempt = sqlite3_value_int(argv[3]);
	copy_text(n->actor, sizeof n->actor, argv[4]);
	const unsigned char *detail = sqlite3_value_text(argv[5]);
	n->detail = detail ? strdup((const char *)detail) : NULL;
	copy_text(n->worker, sizeof n->worker, argv[6]);
}

int store_events_watch(struct store *s, char *msg, size_t msg_size)
{
	sqlite3 *db = s->writer.db;
	if (sqlite3_create_function_v2(db, "poro_event_note", 7, SQLITE_UTF8, s, note_event, NULL, NULL, NULL) !=
		    SQLITE_OK ||
	    conn_exec(&s->writer, "CREATE TEMP TRIGGER IF NOT EXISTS poro_event_log AFTER INSERT ON main.events BEGIN"
				  " SELECT poro_event_note(NEW.job_id, NEW.from_state, NEW.to_state, NEW.attempt,"
				  " NEW.actor, NEW.detail, (SELECT worker FROM main.jobs WHERE id = NEW.job_id));"
				  " END") != SQLITE_OK) {
		snprintf(msg, msg_size, "cannot watch job events: %s", sqlite3_errmsg(db));
		return -1;
	}
	return 0;
}

int store_events_mark(const struct store *s)
{
	return s->note_count;
}

void store_events_rollback(struct store *s, int mark)
{
	while (s->note_count > mark)
		free(s->notes[--s->note_count].detail);
}

static int is_running(const char *state)
{
	return strcmp(state, "running") == 0;
}

static void log_note(const struct event_note *n)
{
	struct log_line l;
	log_line_begin(&l, LOG_PRIO_INFO, "job_state");
	log_line_int(&l, "job", n->job);
	log_line_str(&l, "from", n->has_from ? n->from : NULL);
	log_line_str(&l, "to", n->to);
	log_line_int(&l, "attempt", n->attempt);
	int leased = (n->has_from && is_running(n->from)) || is_running(n->to);
	log_line_str(&l, "worker", leased && n->worker[0] ? n->worker : NULL);
	log_line_str(&l, "actor", n->actor);
	log_line_str(&l, "reason", n->detail);
	log_line_end(&l);
}

void store_events_flush(struct store *s, int committed)
{
	for (int i = 0; committed && i < s->note_count; i++)
		log_note(&s->notes[i]);
	if (committed && s->notes_lost)
		log_say(LOG_PRIO_WARNING, "%d job state changes were committed but not logged: out of memory",
			s->notes_lost);
	store_events_rollback(s, 0);
	s->notes_lost = 0;
}

void store_events_release(struct store *s)
{
	store_events_rollback(s, 0);
	free(s->notes);
	s->notes = NULL;
	s->note_cap = 0;
}
