/*
 * job.c - one running job, see job.h. The job's thread supervises in a poll loop every
 * JOB_TICK seconds while the solver's output is read on the log pump's thread; so the solver keeps
 * running while a call to the server waits or fails. Each kind of write (log, heartbeat,
 * checkpoint upload) has its own backoff, so one failing call type neither blocks the others nor
 * hammers the server. Outcomes (docs/service.md §2):
 *   exit 0 -> succeeded; exit 2 or 3 (invalid input, solver failure) -> failed with the solver's
 *   error message; exit 6 or a signal after a cancel -> cancelled; wall time exceeded -> failed;
 *   exit 4 or 5, a signal the worker did not send, a failure to start, a second SIGTERM to the
 *   worker -> infrastructure (the server re-queues the job and it resumes from its checkpoint).
 *
 * A success needs its files on the server (settle): the finish declares every file the final
 * uploads stored ("artifacts", which the server checks against its index), and a file that did not
 * get there turns "succeeded" into "failed" when the server refused it (413, 422: a retry would end
 * the same way) or "infrastructure" when it kept failing until WORKER_FINISH_PATIENCE ran out; the
 * job directory is then kept, whatever --keep-work says, and the message says where. Each staged
 * result.h5 gets its probes.json, and the dashboard's frames.bin and frames.json, from a
 * `poro-solve probes` child (probes.h), uploaded right after it; a failed extraction costs only
 * those derived files.
 */
#define _GNU_SOURCE
#include "job.h"

#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "backoff.h"
#include "child.h"
#include "job_files.h"
#include "json_get.h"
#include "log_pump.h"
#include "probes.h"
#include "worker.h"

/* Supervision period, seconds. */
#define JOB_TICK 0.05
/* Attempts at downloading a checkpoint before the job is handed back as infrastructure. */
#define JOB_FETCH_TRIES 5
/* Seconds the finish call still gets when the final uploads used up WORKER_FINISH_PATIENCE: an
 * attempt whose files could not be sent is reported, not left to expire. */
#define JOB_REPORT_PATIENCE 60.0
/* Files a finish declares: result.h5, probes.json, frames.bin, frames.json, metrics.json,
 * result.xdmf, checkpoint.h5. */
#define JOB_ARTIFACTS_MAX 7
#define JOB_PROBES_NAME "probes.json"
#define JOB_FRAMES_BIN "frames.bin"      /* the frames in the dashboard's compact form (probes.h) */
#define JOB_FRAMES_INDEX "frames.json"   /* their index, uploaded after frames.bin */
#define JOB_TEXT_MAX 8192   /* bytes of a message about the files, as the server's MESSAGE_MAX */

enum stop_reason { STOP_NONE, STOP_CANCEL, STOP_WALL, STOP_SHUTDOWN, STOP_LOST, STOP_RETIRE };
enum send_result { SEND_OK, SEND_RETRY, SEND_REFUSED, SEND_LOST };

/* A result file staged for upload: a snapshot path and its checksum. */
struct staged {
	int pending;
	char path[4400];
	char sha256[DIGEST_HEX_SIZE];
	long long size;          /* bytes */
};

/* A file the final uploads stored, as the finish declares it. */
struct artifact {
	char name[32];
	long long size;
	char sha256[DIGEST_HEX_SIZE];
};

struct job {
	long long id;
	int attempt;
	int threads;
	long wall_time;          /* seconds, 0: no limit */
	double heartbeat_every;  /* seconds */
	char tag[64];            /* "job 12 attempt 1" for messages */
	char dir[4200];          /* WORK/job-<id>-<attempt> */
	struct http_client *http;

	pid_t pid;
	int running;             /* the child has not been reaped */
	int wait_status;
	double started, exited_at, term_at;
	int term_sent, kill_sent;
	enum stop_reason stop;

	struct log_pump pump;
	char *chunk;             /* WORKER_LOG_CHUNK bytes for log sends */
	int log_broken;          /* the server lost log text we no longer hold: stop sending */
	double last_log_at;
	struct backoff log_b, hb_b, up_b;
	double next_heartbeat_at;
	int checkpoints_seen;
	/* result.h5 goes first, so it is never older; its probes.json follows once extracted */
	struct staged up_result, up_checkpoint, up_probes, up_frames_bin, up_frames_index;
	struct probes_run probes;
	char upload_why[700];    /* the answer (or transport error) of the last failed upload */

	struct artifact declared[JOB_ARTIFACTS_MAX]; /* what the final uploads stored */
	int declared_count;
	char problem[JOB_TEXT_MAX]; /* the first final upload that did not reach the server, and why */
	int problem_permanent;   /* ... because the server refused it: a retry would end the same way */
	char result_missing[300]; /* why out/result.h5 could not be staged, "" when it was */
	char probes_note[JOB_TEXT_MAX]; /* why the final result has no probes.json, "" when it has */
	int keep;                /* keep the directory: a file of the attempt is not on the server */
};

static void say_job(const struct job *j, const char *what, const struct http_response *r)
{
	char why[700];
	worker_say("%s: %s: %s", j->tag, what, http_describe(r, why, sizeof why));
}

/* Sorts an answer into ok / retry later / refused / lease lost, and says what happened. */
static enum send_result classify(struct job *j, const char *what, const struct http_response *r,
				 struct backoff *b)
{
	char why[700];
	if (http_ok(r)) {
		backoff_reset(b);
		return SEND_OK;
	}
	/* artifact_missing is a finish the server could not accept; log_gap is sorted out by send_log */
	if (r->status == 404 || (r->status == 409 && strcmp(r->code, "log_gap") && strcmp(r->code, "artifact_missing"))) {
		worker_say("%s: %s refused, the lease is gone: %s", j->tag, what, http_describe(r, why, sizeof why));
		j->stop = STOP_LOST;
		return SEND_LOST;
	}
	double wait = backoff_fail(b, worker_now());
	if (http_transient(r)) {
		worker_say("%s: %s failed, retrying in %.1f s: %s", j->tag, what, wait,
			   http_describe(r, why, sizeof why));
		return SEND_RETRY;
	}
	say_job(j, what, r);
	return SEND_REFUSED;
}

static void terminate(struct job *j, double now)
{
	if (j->term_sent || !j->running)
		return;
	child_signal(j->pid, SIGTERM);
	j->term_sent = 1;
	j->term_at = now;
}

static enum send_result send_log(struct job *j)
{
	long long offset;
	size_t n = log_pump_peek(&j->pump, j->chunk, WORKER_LOG_CHUNK, &offset);
	if (n == 0 || j->log_broken)
		return SEND_OK;
	json_t *body = json_pack("{s:i, s:I, s:s%}", "attempt", j->attempt, "offset", (json_int_t)offset, "text",
				 j->chunk, n);
	char path[128];
	snprintf(path, sizeof path, "/v1/worker/jobs/%lld/log", j->id);
	struct http_response r;
	http_json(j->http, "POST", path, body, NULL, 30, &r);
	json_decref(body);
	enum send_result s = classify(j, "log chunk", &r, &j->log_b);
	if (s == SEND_OK) {
		log_pump_ack(&j->pump, offset + (long long)n);
	} else if (r.status == 409) {
		/* log_gap: the server expects another offset; accept it if we sent past it */
		json_t *e = json_object_get(r.json, "error");
		long long want = json_get_int(r.json, "expected_offset",
					      json_get_int(e, "expected_offset", json_get_int(r.json, "next_offset", -1)));
		if (want > offset) {
			log_pump_ack(&j->pump, want);
			backoff_reset(&j->log_b);
		} else {
			worker_say("%s: the server lost log text before offset %lld; no more log is sent", j->tag, offset);
			j->log_broken = 1;
		}
	}
	http_response_release(&r);
	return s;
}

static enum send_result send_heartbeat(struct job *j)
{
	struct log_progress g = log_pump_progress(&j->pump);
	json_t *progress = json_null();
	if (g.valid)
		progress = json_pack("{s:I, s:f, s:f, s:f}", "step", (json_int_t)g.step, "time", g.time,
				     "us_per_mp_step", g.us_per_mp_step, "fraction",
				     g.steps_total > 0 ? (double)g.step / (double)g.steps_total : 0.0);
	json_t *body = json_pack("{s:i, s:o, s:s, s:s}", "attempt", j->attempt, "progress", progress, "solver_version",
				 worker_opt.solver_version, "worker", worker_opt.name);
	char path[128];
	snprintf(path, sizeof path, "/v1/worker/jobs/%lld/heartbeat", j->id);
	struct http_response r;
	http_json(j->http, "POST", path, body, NULL, 30, &r);
	json_decref(body);
	enum send_result s = classify(j, "heartbeat", &r, &j->hb_b);
	if (s == SEND_OK && json_get_bool(r.json, "cancel", 0) && j->stop == STOP_NONE && j->running) {
		worker_say("%s: cancel requested, stopping the solver", j->tag);
		j->stop = STOP_CANCEL;
		terminate(j, worker_now());
	}
	http_response_release(&r);
	return s;
}

/* Uploads one file; a refusal other than a lost lease drops the file (it is not retried). */
static enum send_result upload(struct job *j, const char *name, struct staged *f)
{
	struct http_response r;
	char what[160];
	snprintf(what, sizeof what, "upload of '%s'", name);
	job_files_upload(j->http, j->id, j->attempt, name, f->path, f->sha256, &r);
	enum send_result s = classify(j, what, &r, &j->up_b);
	if (s != SEND_OK)
		http_describe(&r, j->upload_why, sizeof j->upload_why);
	if (s == SEND_OK || s == SEND_REFUSED)
		f->pending = 0;
	http_response_release(&r);
	return s;
}

/* Stages src of the output directory as a snapshot in upload/ for name; 0 when the file exists. */
static int stage(struct job *j, const char *name, struct staged *f, int snapshot)
{
	char src[4400];
	snprintf(src, sizeof src, "%s/out/%s", j->dir, name);
	if (!snapshot) {
		snprintf(f->path, sizeof f->path, "%s", src);
		if (digest_file_hex(src, f->sha256, &f->size) < 0)
			return -1;
	} else {
		snprintf(f->path, sizeof f->path, "%s/upload/%s", j->dir, name);
		if (job_files_snapshot(src, f->path, f->sha256, &f->size) < 0) {
			if (errno != ENOENT)
				worker_say("%s: cannot copy '%s' for upload: %s", j->tag, name, strerror(errno));
			return -1;
		}
	}
	f->pending = 1;
	return 0;
}

/* Starts extracting the probes of result (relative to the job directory); a failure to start is
 * said, and kept in note when note is not NULL. */
static void start_probes(struct job *j, const char *result, char *note, size_t note_size)
{
	char err[700];
	j->up_probes.pending = j->up_frames_bin.pending = j->up_frames_index.pending = 0;
	if (probes_start(&j->probes, j->dir, result, j->id, j->attempt, err, sizeof err) == 0)
		return;
	worker_say("%s: no probes.json for '%s': cannot start poro-solve probes: %s", j->tag, result, err);
	if (note)
		snprintf(note, note_size, "no probes.json: cannot start poro-solve probes: %s", err);
}

/* Stages the frames the extraction wrote beside probes.json, when it wrote them (derived data:
 * a job without them only has no field viewer). */
static void stage_frames(struct job *j)
{
	struct staged *f[2] = { &j->up_frames_bin, &j->up_frames_index };
	const char *name[2] = { PROBES_FRAMES_BIN, PROBES_FRAMES_INDEX };
	for (int i = 0; i < 2; i++) {
		snprintf(f[i]->path, sizeof f[i]->path, "%s/%s", j->dir, name[i]);
		f[i]->pending = digest_file_hex(f[i]->path, f[i]->sha256, &f[i]->size) == 0;
	}
	if (!f[1]->pending)   /* an index without its frames, or frames without an index, is of no use */
		f[0]->pending = 0;
}

/* Polls the extraction: PROBES_DONE with probes.json staged in f; PROBES_FAILED said, and kept in
 * note when note is not NULL; PROBES_RUNNING or PROBES_NONE. */
static enum probes_state collect_probes(struct job *j, struct staged *f, double now, char *note, size_t note_size)
{
	char why[5000];
	enum probes_state st = probes_poll(&j->probes, now, why, sizeof why);
	if (st == PROBES_DONE) {
		snprintf(f->path, sizeof f->path, "%s/%s", j->dir, PROBES_OUT);
		stage_frames(j);
		if (digest_file_hex(f->path, f->sha256, &f->size) == 0) {
			f->pending = 1;
		} else {
			snprintf(why, sizeof why, "cannot read '%s': %s", f->path, strerror(errno));
			st = PROBES_FAILED;
		}
	}
	if (st == PROBES_FAILED) {
		snprintf(f->path, sizeof f->path, "%s/%s", j->dir, PROBES_OUT);
		if (digest_file_hex(f->path, f->sha256, &f->size) == 0) {   /* whole (probes.h): the frames failed */
			worker_say("%s: no frames for this result.h5: %s", j->tag, why);
			f->pending = 1;
			return PROBES_DONE;
		}
		worker_say("%s: no probes.json for this result.h5: %s", j->tag, why);
		if (note)
			snprintf(note, note_size, "no probes.json: %s", why);
	}
	return st;
}

/* After a "checkpoint" line: snapshot checkpoint.h5 and result.h5, extract the probes of the
 * snapshot, then upload result.h5, probes.json (once extracted) and checkpoint.h5 in turn. */
static void checkpoint_uploads(struct job *j, double now)
{
	int seen = log_pump_checkpoints(&j->pump);
	if (seen > j->checkpoints_seen) {
		j->checkpoints_seen = seen;
		if (stage(j, "checkpoint.h5", &j->up_checkpoint, 1) == 0) {
			if (stage(j, "result.h5", &j->up_result, 1) == 0)
				start_probes(j, "upload/result.h5", NULL, 0);
			backoff_reset(&j->up_b);
		}
	}
	collect_probes(j, &j->up_probes, now, NULL, 0);
	if (!backoff_due(&j->up_b, now))
		return;
	if (j->up_result.pending && upload(j, "result.h5", &j->up_result) != SEND_OK)
		return;
	if (j->up_probes.pending && upload(j, JOB_PROBES_NAME, &j->up_probes) != SEND_OK)
		return;
	if (j->up_frames_bin.pending && upload(j, JOB_FRAMES_BIN, &j->up_frames_bin) != SEND_OK)
		return;
	if (j->up_frames_index.pending && upload(j, JOB_FRAMES_INDEX, &j->up_frames_index) != SEND_OK)
		return;
	if (j->up_checkpoint.pending && upload(j, "checkpoint.h5", &j->up_checkpoint) == SEND_OK)
		worker_say("%s: checkpoint uploaded", j->tag);
}

static void heartbeat_if_due(struct job *j, double now)
{
	if (now >= j->next_heartbeat_at && backoff_due(&j->hb_b, now)) {
		if (send_heartbeat(j) != SEND_RETRY)
			j->next_heartbeat_at = now + j->heartbeat_every;
	}
}

/* The worker's allocation ends soon (worker_retire_due): the solver is asked for a checkpoint of
 * its current step and to stop (SIGUSR1), so the job goes back to the queue as an infrastructure
 * failure and another worker resumes it from that checkpoint. A solver still running at half the
 * margin is stopped without one (the last periodic checkpoint stands). */
static void retire_if_due(struct job *j, double now)
{
	if (!j->running || !worker_retire_due(now, 1.0))
		return;
	if (j->stop == STOP_NONE) {
		worker_say("%s: the allocation ends in %.0f s: checkpointing the job and handing it back", j->tag,
			   worker_opt.end_at - now);
		j->stop = STOP_RETIRE;
		child_signal(j->pid, SIGUSR1);
	} else if (j->stop == STOP_RETIRE && worker_retire_due(now, 0.5)) {
		terminate(j, now);
	}
}

/* Runs until the solver is reaped and its output drained, or the lease is lost. */
static void supervise(struct job *j)
{
	for (;;) {
		double now = worker_now();
		if (j->stop == STOP_LOST)
			return;
		if (j->running && atomic_load(&worker_stopping) && j->stop == STOP_NONE) {
			worker_say("%s: worker stopping, terminating the solver", j->tag);
			j->stop = STOP_SHUTDOWN;
			terminate(j, now);
		}
		retire_if_due(j, now);
		if (j->running && j->wall_time > 0 && now - j->started >= (double)j->wall_time && j->stop == STOP_NONE) {
			worker_say("%s: wall time of %ld s reached, terminating the solver", j->tag, j->wall_time);
			j->stop = STOP_WALL;
			terminate(j, now);
		}
		if (j->term_sent && !j->kill_sent && now - j->term_at >= WORKER_KILL_GRACE) {
			child_signal(j->pid, SIGKILL);
			j->kill_sent = 1;
		}
		if (j->running && child_reap(j->pid, &j->wait_status)) {
			j->running = 0;
			j->exited_at = now;
		}
		int eof;
		long long unsent = log_pump_unsent(&j->pump, &eof);
		if (!j->running && eof)
			return;
		if (!j->running && now - j->exited_at > WORKER_KILL_GRACE) {
			/* something the solver started still holds the pipe: end its group */
			child_signal(j->pid, SIGKILL);
		}
		if (unsent > 0 && now - j->last_log_at >= WORKER_LOG_INTERVAL && backoff_due(&j->log_b, now)) {
			j->last_log_at = now;
			send_log(j);
		}
		if (j->stop != STOP_LOST)
			heartbeat_if_due(j, now);
		if (j->stop != STOP_LOST)
			checkpoint_uploads(j, now);
		usleep((useconds_t)(JOB_TICK * 1e6));
	}
}

/* Decides the outcome from the wait status and why the worker stopped the solver. */
static const char *outcome(struct job *j, char *message, size_t size, int *exit_code)
{
	char err[LOG_PUMP_ERROR_MAX + 1];
	log_pump_error(&j->pump, err, sizeof err);
	int st = j->wait_status;
	int exited = WIFEXITED(st), code = exited ? WEXITSTATUS(st) : 0, sig = exited ? 0 : WTERMSIG(st);
	*exit_code = exited ? code : 128 + sig;
	if (exited && code == 0) {
		snprintf(message, size, "%s", "");
		return "succeeded";
	}
	switch (j->stop) {
	case STOP_CANCEL:
		snprintf(message, size, "cancelled on request");
		return "cancelled";
	case STOP_WALL:
		snprintf(message, size, "wall time limit of %ld s exceeded", j->wall_time);
		return "failed";
	case STOP_SHUTDOWN:
		snprintf(message, size, "worker '%s' was stopped while the job ran", worker_opt.name);
		return "infrastructure";
	case STOP_RETIRE:
		snprintf(message, size, "handed back with a checkpoint: the allocation of worker '%s' was about to end",
			 worker_opt.name);
		return "infrastructure";
	default:
		break;
	}
	if (!exited) {
		snprintf(message, size, "solver killed by signal %d (%s)%s%s", sig, strsignal(sig), err[0] ? ": " : "",
			 err);
		return "infrastructure";
	}
	if (code == CHILD_EXEC_FAILED) {
		snprintf(message, size, "cannot start the solver '%s'", worker_opt.solver);
		return "infrastructure";
	}
	if (code == 5 && worker_opt.memory_limit_mb > 0) {
		/* the job needs more than the memory it is given: every retry would end the same way */
		snprintf(message, size, "out of memory within the worker's limit of %ld MB%s%s", worker_opt.memory_limit_mb,
			 err[0] ? ": " : "", err);
		return "failed";
	}
	if (err[0])
		snprintf(message, size, "%s", err);
	else
		snprintf(message, size, "solver exited with status %d", code);
	if (code == 4 || code == 5 || code == 6)
		return "infrastructure";
	return "failed";
}

/* Deadline for the work after the solver ended: shorter once the worker is told to stop. */
static int before_deadline(double deadline)
{
	double now = worker_now();
	static _Thread_local double stop_seen;
	if (atomic_load(&worker_stopping)) {
		if (stop_seen == 0)
			stop_seen = now;
		if (now > stop_seen + WORKER_STOP_PATIENCE)
			return 0;
	}
	return now < deadline;
}

/* Waits out the backoff b while keeping the lease renewed; 0 when the job must give up. */
static int wait_retry(struct job *j, struct backoff *b, double deadline)
{
	while (!backoff_due(b, worker_now())) {
		if (!before_deadline(deadline) || j->stop == STOP_LOST)
			return 0;
		heartbeat_if_due(j, worker_now());
		usleep(50000);
	}
	return before_deadline(deadline) && j->stop != STOP_LOST;
}

static void flush_log(struct job *j, double deadline)
{
	while (!j->log_broken && log_pump_unsent(&j->pump, NULL) > 0 && wait_retry(j, &j->log_b, deadline))
		send_log(j);
}

/* "5.2 GB", "857.7 kB", "312 bytes": a size for messages, in SI units. */
static void format_size(long long bytes, char *out, size_t size)
{
	static const char *const units[] = { "kB", "MB", "GB", "TB" };
	double v = (double)bytes;
	int u = -1;
	while (v >= 1000 && u < 3) {
		v /= 1000;
		u++;
	}
	if (u < 0)
		snprintf(out, size, "%lld bytes", bytes);
	else
		snprintf(out, size, "%.1f %s", v, units[u]);
}

/* One file of the final uploads, retried while the failures are transient. A stored file is
 * declared in the finish; the first other file that did not get there is the attempt's problem
 * (probes.json only loses the probes: it is derived, not a result). */
static void upload_final(struct job *j, const char *name, struct staged *f, double deadline)
{
	enum send_result s = SEND_RETRY;
	j->upload_why[0] = '\0';
	while (f->pending && wait_retry(j, &j->up_b, deadline))
		s = upload(j, name, f);
	if (j->stop == STOP_LOST)
		return;
	if (s == SEND_OK) {
		struct artifact *a = &j->declared[j->declared_count++];
		snprintf(a->name, sizeof a->name, "%s", name);
		a->size = f->size;
		memcpy(a->sha256, f->sha256, DIGEST_HEX_SIZE);
		return;
	}
	char bytes[32], text[JOB_TEXT_MAX - 64];
	format_size(f->size, bytes, sizeof bytes);
	if (s == SEND_REFUSED)
		snprintf(text, sizeof text, "%s (%s) was refused by the server: %s", name, bytes, j->upload_why);
	else
		snprintf(text, sizeof text, "%s (%s) did not reach the server within the worker's %.0f s of retries: %s",
			 name, bytes, WORKER_FINISH_PATIENCE, j->upload_why[0] ? j->upload_why : "no time was left to send it");
	worker_say("%s: %s", j->tag, text);
	if (!strcmp(name, JOB_PROBES_NAME)) {
		snprintf(j->probes_note, sizeof j->probes_note, "no probes.json: %s", text);
		return;
	}
	if (!strcmp(name, JOB_FRAMES_BIN) || !strcmp(name, JOB_FRAMES_INDEX))
		return;   /* the dashboard's frames: derived, like the probes; said in the worker's line above */
	j->keep = 1;
	if (!j->problem[0]) {
		snprintf(j->problem, sizeof j->problem, "%s", text);
		j->problem_permanent = s == SEND_REFUSED;
	}
}

/* Waits, heartbeats going, for the probes of the final result; 0 with probes.json staged in f. */
static int final_probes(struct job *j, struct staged *f, double deadline)
{
	enum probes_state st;
	while ((st = collect_probes(j, f, worker_now(), j->probes_note, sizeof j->probes_note)) == PROBES_RUNNING) {
		if (!before_deadline(deadline) || j->stop == STOP_LOST) {
			probes_stop(&j->probes);
			snprintf(j->probes_note, sizeof j->probes_note, "no probes.json: no time was left to extract them");
			return -1;
		}
		heartbeat_if_due(j, worker_now());
		usleep(20000);
	}
	return st == PROBES_DONE ? 0 : -1;
}

static void final_uploads(struct job *j, double deadline)
{
	/* declared[] has room for each of them */
	static const char *const names[JOB_ARTIFACTS_MAX] = {"result.h5", JOB_PROBES_NAME, JOB_FRAMES_BIN,
							     JOB_FRAMES_INDEX, "metrics.json", "result.xdmf",
							     "checkpoint.h5"};
	/* a checkpoint announced but not yet sent goes first, as during the run */
	while ((j->up_result.pending || j->up_checkpoint.pending) && wait_retry(j, &j->up_b, deadline))
		checkpoint_uploads(j, worker_now());
	probes_stop(&j->probes);   /* the final result supersedes a snapshot's extraction */
	j->up_probes.pending = j->up_frames_bin.pending = j->up_frames_index.pending = 0;
	for (size_t i = 0; i < sizeof names / sizeof *names && j->stop != STOP_LOST; i++) {
		struct staged f = {0};
		if (!strcmp(names[i], JOB_PROBES_NAME)) {
			if (final_probes(j, &f, deadline) < 0)
				continue;
		} else if (!strcmp(names[i], JOB_FRAMES_BIN) || !strcmp(names[i], JOB_FRAMES_INDEX)) {
			f = i == 2 ? j->up_frames_bin : j->up_frames_index;   /* staged with the probes */
			if (!f.pending)
				continue;
		} else if (stage(j, names[i], &f, 0) < 0) {
			if (i == 0)
				snprintf(j->result_missing, sizeof j->result_missing, "%s", strerror(errno));
			continue;
		}
		if (i == 0)   /* extracted while result.h5 is sent */
			start_probes(j, "out/result.h5", j->probes_note, sizeof j->probes_note);
		upload_final(j, names[i], &f, deadline);
	}
}

static int is_declared(const struct job *j, const char *name)
{
	for (int i = 0; i < j->declared_count; i++)
		if (!strcmp(j->declared[i].name, name))
			return 1;
	return 0;
}

/* Appends "; text" to message (or sets it when empty), cut to size. */
static void append(char *message, size_t size, const char *text)
{
	size_t n = strlen(message), sep = n ? 2 : 0;
	if (n + sep + 1 >= size)
		return;
	memcpy(message + n, "; ", sep);
	n += sep;
	size_t take = strlen(text);
	if (take > size - 1 - n)
		take = size - 1 - n;
	memcpy(message + n, text, take);
	message[n + take] = '\0';
}

/* The outcome once the final uploads are known (see the top of this file); says when the
 * directory is kept. */
static const char *settle(struct job *j, const char *result, char *message, size_t size)
{
	int succeeded = !strcmp(result, "succeeded");
	if (succeeded && !j->problem[0] && !is_declared(j, "result.h5") && j->result_missing[0]) {
		snprintf(j->problem, sizeof j->problem, "the solver exited 0 but result.h5 cannot be read in '%s/out': %s",
			 j->dir, j->result_missing);
		j->problem_permanent = 1;
		j->keep = 1;
	}
	if (j->problem[0] && succeeded) {
		result = j->problem_permanent ? "failed" : "infrastructure";
		snprintf(message, size, "%s", j->problem);
	} else if (j->problem[0]) {
		append(message, size, j->problem);
	} else if (succeeded && j->probes_note[0]) {
		snprintf(message, size, "%s", j->probes_note);
	}
	if (j->keep) {
		char kept[4700];
		snprintf(kept, sizeof kept, "the files are kept in %s on host %s", j->dir, worker_opt.host);
		append(message, size, kept);
		worker_say("%s: keeping %s: not every file of the attempt reached the server", j->tag, j->dir);
	}
	return result;
}

/* The finish body, with the declared artifacts. */
static json_t *finish_body(const struct job *j, const char *result, const char *message, int exit_code)
{
	json_t *artifacts = json_array();
	for (int i = 0; i < j->declared_count; i++)
		json_array_append_new(artifacts, json_pack("{s:s, s:I, s:s}", "name", j->declared[i].name, "size",
							   (json_int_t)j->declared[i].size, "sha256", j->declared[i].sha256));
	/* an empty message is sent as null: the server takes strings of 1 byte or more */
	return json_pack("{s:i, s:s, s:o, s:i, s:s, s:o}", "attempt", j->attempt, "outcome", result, "message",
			 message[0] ? json_string(message) : json_null(), "exit_code", exit_code, "solver_version",
			 worker_opt.solver_version, "artifacts", artifacts);
}

/* Sends the finish until it is answered; SEND_REFUSED leaves the server's code and message in
 * code and why. */
static enum send_result finish(struct job *j, const char *result, const char *message, int exit_code,
			       double deadline, char code[64], char *why, size_t why_size)
{
	json_t *body = finish_body(j, result, message, exit_code);
	char path[128];
	snprintf(path, sizeof path, "/v1/worker/jobs/%lld/finish", j->id);
	struct backoff b = {0};
	enum send_result s = SEND_RETRY;
	while (s == SEND_RETRY && wait_retry(j, &b, deadline)) {
		struct http_response r;
		http_json(j->http, "POST", path, body, NULL, 30, &r);
		s = classify(j, "finish", &r, &b);
		if (s == SEND_OK)
			worker_say("%s: finished %s%s%s", j->tag, result, message[0] ? ": " : "", message);
		snprintf(code, 64, "%s", r.code);
		http_describe(&r, why, why_size);
		http_response_release(&r);
	}
	if (s == SEND_RETRY && j->stop != STOP_LOST)
		worker_say("%s: gave up reporting '%s'; the lease will expire", j->tag, result);
	json_decref(body);
	return s;
}

/* Reports the outcome. A success the server cannot match with its files (artifact_missing) is
 * reported again as an infrastructure failure, the directory kept: the job is retried. */
static void report(struct job *j, const char *result, char *message, size_t size, int exit_code, double deadline)
{
	char code[64] = "", why[800] = "";
	if (worker_now() + JOB_REPORT_PATIENCE > deadline)
		deadline = worker_now() + JOB_REPORT_PATIENCE;
	if (finish(j, result, message, exit_code, deadline, code, why, sizeof why) != SEND_REFUSED ||
	    strcmp(code, "artifact_missing"))
		return;
	snprintf(message, size, "the server does not hold the files the worker uploaded: %s; the files are kept in %s "
		 "on host %s", why, j->dir, worker_opt.host);
	j->keep = 1;
	worker_say("%s: keeping %s: the server does not hold the declared files", j->tag, j->dir);
	finish(j, "infrastructure", message, exit_code, deadline, code, why, sizeof why);
}

/* Fills j from the claim and creates the job directory with case.json. 0, or -1 with err. */
static int prepare(struct job *j, const json_t *claim, char *err, size_t err_size)
{
	j->id = json_get_int(claim, "id", -1);
	j->attempt = (int)json_get_int(claim, "attempt", 0);
	j->threads = (int)json_get_int(claim, "threads", 1);
	j->wall_time = (long)json_get_int(claim, "wall_time_seconds", 0);
	double lease = json_get_real(claim, "lease_seconds", 30);
	j->heartbeat_every = worker_opt.lease_renew > 0 ? worker_opt.lease_renew : lease / 3;
	if (j->heartbeat_every > WORKER_HEARTBEAT_MAX && worker_opt.lease_renew <= 0)
		j->heartbeat_every = WORKER_HEARTBEAT_MAX;
	if (j->heartbeat_every < 0.2)
		j->heartbeat_every = 0.2;
	snprintf(j->tag, sizeof j->tag, "job %lld attempt %d", j->id, j->attempt);
	snprintf(j->dir, sizeof j->dir, "%s/job-%lld-%d", worker_opt.work, j->id, j->attempt);
	json_t *c = json_object_get(claim, "case");
	if (j->id < 0 || !json_is_object(c)) {
		snprintf(err, err_size, "claim answer without a job id or case");
		return -1;
	}
	job_files_remove_tree(j->dir);
	char sub[4400];
	if (mkdir(j->dir, 0755) < 0) {
		snprintf(err, err_size, "cannot create '%s': %s", j->dir, strerror(errno));
		return -1;
	}
	snprintf(sub, sizeof sub, "%s/out", j->dir);
	mkdir(sub, 0755);
	snprintf(sub, sizeof sub, "%s/upload", j->dir);
	mkdir(sub, 0755);
	snprintf(sub, sizeof sub, "%s/case.json", j->dir);
	if (json_dump_file(c, sub, JSON_INDENT(1)) < 0) {
		snprintf(err, err_size, "cannot write '%s'", sub);
		return -1;
	}
	return 0;
}

/* An exclusive job starts its solver only when no other job of this worker runs, any other job
 * only when no exclusive job runs or waits (slot_try_start, docs/benchmarks.md "Exclusive
 * jobs"); meanwhile the lease is renewed. 0 when it may start, -1 with err when the worker stops
 * or the lease is lost first. */
static int wait_turn(struct job *j, int exclusive, char *err, size_t err_size)
{
	int said = 0;
	while (!slot_try_start(exclusive)) {
		if (atomic_load(&worker_stopping) || j->stop == STOP_LOST) {
			snprintf(err, err_size, "the worker stopped before the job's turn to run came");
			return -1;
		}
		if (!said++)
			worker_say("%s: waits to start: %s", j->tag, exclusive ? "an exclusive job runs alone, and other "
				   "jobs of this worker are running" : "an exclusive job runs, or waits to run alone");
		heartbeat_if_due(j, worker_now());
		usleep(50000);
	}
	return 0;
}

/* Downloads the checkpoint of an earlier attempt; 0, or -1 with err. */
static int fetch_checkpoint(struct job *j, const json_t *checkpoint, char *err, size_t err_size)
{
	char out[4400];
	snprintf(out, sizeof out, "%s/out", j->dir);
	const char *sha = json_get_str(checkpoint, "sha256", "");
	struct backoff b = {0};
	for (int i = 0; i < JOB_FETCH_TRIES && !atomic_load(&worker_stopping); i++) {
		int rc = job_files_fetch_resume(j->http, j->id, j->attempt, out, sha, err, err_size);
		if (rc <= 0)
			return rc;
		double wait = backoff_fail(&b, worker_now());
		worker_say("%s: %s, retrying in %.1f s", j->tag, err, wait);
		worker_sleep(wait, 0);
	}
	return -1;
}

/* Starts the solver; 0, or -1 with err. */
static int start_solver(struct job *j, int resume, char *err, size_t err_size)
{
	char wall[32];
	char *argv[12];
	int n = 0;
	argv[n++] = worker_opt.solver;
	argv[n++] = "run";
	argv[n++] = "case.json";
	argv[n++] = "--out";
	argv[n++] = "out";
	if (resume) {
		argv[n++] = "--resume";
		argv[n++] = "out/checkpoint.h5";
	}
	if (worker_opt.checkpoint_flag && worker_opt.checkpoint_wall > 0) {
		snprintf(wall, sizeof wall, "%ld", worker_opt.checkpoint_wall);
		argv[n++] = (char *)worker_opt.checkpoint_flag;
		argv[n++] = wall;
	}
	argv[n] = NULL;
	/* a job asking more threads than this slot offers runs with the slot's share, and says so */
	char note[256] = "";
	int threads = j->threads > worker_opt.threads ? worker_opt.threads : j->threads;
	if (threads < j->threads)
		snprintf(note, sizeof note, "running with %d thread%s of the %d asked: this worker gives each of its %d "
			 "slot%s %d thread%s (--threads %d)\n", threads, threads == 1 ? "" : "s", j->threads,
			 worker_opt.slots, worker_opt.slots == 1 ? "" : "s", threads, threads == 1 ? "" : "s",
			 worker_opt.thread_budget);
	struct child_spec spec = { .dir = j->dir, .argv = argv, .memory_limit_mb = worker_opt.memory_limit_mb,
				   .threads = threads, .note = note, .secret = worker_opt.token };
	int fd;
	if (child_start(&spec, &j->pid, &fd, err, err_size) < 0)
		return -1;
	j->running = 1;
	j->started = worker_now();
	char log_path[4400];
	snprintf(log_path, sizeof log_path, "%s/log.txt", j->dir);
	if (log_pump_start(&j->pump, fd, log_path) < 0) {
		/* cannot read its output: end it, the job goes back to the queue */
		snprintf(err, err_size, "cannot start the log thread: %s", strerror(errno));
		child_signal(j->pid, SIGKILL);
		waitpid(j->pid, &j->wait_status, 0);
		close(fd);
		j->running = 0;
		return -1;
	}
	worker_say("%s: solver started (pid %d%s)", j->tag, (int)j->pid, resume ? ", resuming from the checkpoint" : "");
	return 0;
}

int job_run(struct http_client *c, const json_t *claim)
{
	struct job j = {0};
	char err[10000];
	j.http = c;
	probes_init(&j.probes);
	j.chunk = malloc(WORKER_LOG_CHUNK);
	int prepared = prepare(&j, claim, err, sizeof err) == 0 && j.chunk;
	const json_t *checkpoint = json_object_get(claim, "checkpoint");
	int resume = json_is_object(checkpoint), exclusive = json_is_true(json_object_get(claim, "exclusive"));
	worker_say("%s: claimed (%d thread%s, wall time %ld s%s%s)", j.tag, j.threads, j.threads == 1 ? "" : "s",
		   j.wall_time, resume ? ", from a checkpoint" : "", exclusive ? ", exclusive" : "");
	int started = 0, turn = 0;
	if (prepared && resume && fetch_checkpoint(&j, checkpoint, err, sizeof err) < 0)
		prepared = 0;
	if (prepared) {
		turn = wait_turn(&j, exclusive, err, sizeof err) == 0;
		prepared = turn;
	}
	if (prepared && start_solver(&j, resume, err, sizeof err) == 0)
		started = 1;
	double deadline;
	if (!started) {
		worker_say("%s: cannot run: %s", j.tag, err);
		if (j.id >= 0)
			report(&j, "infrastructure", err, sizeof err, -1, worker_now() + WORKER_FINISH_PATIENCE);
	} else {
		supervise(&j);
		if (j.stop == STOP_LOST) {
			child_signal(j.pid, SIGKILL);
			if (j.running)
				waitpid(j.pid, &j.wait_status, 0);
		} else {
			char message[8192];
			int exit_code;
			const char *result = outcome(&j, message, sizeof message, &exit_code);
			deadline = worker_now() + WORKER_FINISH_PATIENCE;
			flush_log(&j, deadline);
			if (strcmp(result, "infrastructure") || !atomic_load(&worker_stopping))
				final_uploads(&j, deadline);
			if (j.stop != STOP_LOST) {
				result = settle(&j, result, message, sizeof message);
				report(&j, result, message, sizeof message, exit_code, deadline);
			}
		}
		probes_stop(&j.probes);
		log_pump_release(&j.pump);
	}
	free(j.chunk);
	/* kept for inspection with --keep-work (what the solver wrote, byte for byte), and whenever a
	 * file of the attempt is not on the server: then it is the only copy */
	if (!worker_opt.keep_work && !j.keep)
		job_files_remove_tree(j.dir);
	return turn;
}
