/*
 * server.h - what every part of poro-server shares: the configuration (flags and config file,
 * docs/service.md §5), the one table of API error codes with their HTTP statuses and names
 * (STYLE rule 10), roles and the authenticated principal, and struct server, the context each
 * handler gets. Private to server/; the wire contract is docs/service.md and schemas/openapi.yaml.
 *
 * Errors are recorded once, where they happen, with api_fail(), which fills a struct api_error
 * (code, JSON pointer of the offending field or "", message, optional list of problems) and
 * returns the code; callers pass the code up and http.c turns the record into
 * {"error": {"code", "message", "field"}}.
 */
#ifndef PORO_SERVER_H
#define PORO_SERVER_H

#include <jansson.h>
#include <limits.h>
#include <pthread.h>
#include <stdatomic.h>

#define SERVER_NAME_MAX 128           /* user names, job names, worker ids, hosts: bytes */
#define SERVER_PATH_MAX 4096          /* paths built under the state directory */
#define SERVER_STATE_MAX 3072         /* the state directory itself, leaving room below it */
#define SERVER_FIELD_MAX 256          /* JSON pointer of the offending field */
#define SERVER_MESSAGE_MAX 1024

/* Configuration; defaults in main.c (CONFIG_DEFAULTS) and in `poro-server --help`. */
/* A job's wall time when its submission names none, s. A claim with seconds_left (a pilot) is given
 * a job only when the job's wall time fits, except a job with this default: it asked for no
 * particular time, so any pilot may start it and, when its time runs out first, hand it back with
 * a checkpoint for the next to resume (docs/slurm.md). */
#define JOB_WALL_TIME_DEFAULT 86400
/* The most memory a job may ask for, MB (16 TiB): more than any node the service runs on has, so
 * a larger memory_mb is a mistake (a size in bytes or kB given as MB) and is refused at submission
 * rather than left queued for a worker that never comes. */
#define JOB_MEMORY_MB_MAX (1LL << 24)

struct server_config {
	char listen[256];             /* HOST:PORT; port 0 picks a free one */
	char state[SERVER_STATE_MAX];  /* state directory: poro.db, files/, server.url */
	int max_connections;          /* connections of users and clients without a token (one thread each) */
	int max_worker_connections;   /* connections of worker tokens on /v1/worker/ routes, apart */
	int max_connections_per_client; /* user connections from one client address, waiting ones included */
	int max_waiting_connections;  /* connections whose first request head has not arrived yet */
	int header_timeout_seconds;   /* a request head must arrive within this; also idle keep-alive */
	int body_timeout_seconds;     /* a JSON request body must arrive within this */
	int max_requests_per_token;   /* requests in progress per user or admin token */
	int max_requests_per_worker_token; /* requests in progress per worker token */
	int max_concurrent_submissions; /* submissions being validated at once */
	long long max_body_values;    /* JSON values (keys included) in a submission's body */
	long long max_body_bytes;     /* JSON request bodies, bytes */
	long long max_upload_bytes;   /* one uploaded file, bytes */
	int lease_seconds;            /* lease length; each heartbeat renews it */
	int max_attempts;             /* attempts before an infrastructure failure is final */
	int user_max_queued;          /* default per-user cap on queued jobs */
	int user_max_running;         /* default per-user cap on running jobs; 0 = unlimited */
	int max_backoff_seconds;      /* cap of the retry backoff min(2^(attempt-1), cap) */
	int group_commit_max;         /* most write requests in one transaction */
	int max_job_threads;          /* most threads a job may ask for (1..256 on the wire) */
	char access_log[SERVER_STATE_MAX]; /* the log's request lines go here too, or "" for none */
	long long max_log_bytes;      /* log text kept per attempt: its first and last half, bytes */
	long long user_max_stored_bytes; /* default per-user cap on stored bytes; 0 = unlimited */
	int min_free_mb;              /* /healthz is degraded below this much free space on the state file system, MiB */
	char web_root[SERVER_STATE_MAX]; /* the dashboard's files (docs/web.md); "" until main.c finds them */
	char tls_listen[256];         /* HOST:PORT served over TLS (HTTPS), or "" for none */
	char tls_cert[SERVER_STATE_MAX]; /* PEM certificate chain of --tls-listen */
	char tls_key[SERVER_STATE_MAX];  /* PEM private key of --tls-listen */
	int allow_plain_http;         /* 1: --listen may be a non-loopback address (listen_socket.h) */
};

/*      code                        HTTP  name on the wire */
#define API_ERROR_MAP(X)                                                     \
	X(API_OK,                   200, "ok")                               \
	X(API_INVALID_JSON,         400, "invalid_json")                     \
	X(API_MALFORMED_REQUEST,    400, "malformed_request")                \
	X(API_INVALID_PARAMETER,    400, "invalid_parameter")                \
	X(API_INVALID_HEADER,       400, "invalid_header")                   \
	X(API_INVALID_FILE_NAME,    400, "invalid_file_name")                \
	X(API_CHECKSUM_MISMATCH,    400, "checksum_mismatch")                \
	X(API_UNAUTHORIZED,         401, "unauthorized")                     \
	X(API_FORBIDDEN,            403, "forbidden")                        \
	X(API_NOT_FOUND,            404, "not_found")                        \
	X(API_METHOD_NOT_ALLOWED,   405, "method_not_allowed")               \
	X(API_REQUEST_TIMEOUT,      408, "request_timeout")                  \
	X(API_IDEMPOTENCY_CONFLICT, 409, "idempotency_conflict")             \
	X(API_NOT_CANCELLABLE,      409, "not_cancellable")                  \
	X(API_NOT_DELETABLE,        409, "not_deletable")                    \
	X(API_STALE_ATTEMPT,        409, "stale_attempt")                    \
	X(API_LOG_GAP,              409, "log_gap")                          \
	X(API_ALREADY_EXISTS,       409, "already_exists")                   \
	X(API_ARTIFACT_MISSING,     409, "artifact_missing")                 \
	X(API_NOT_FINISHED,         409, "not_finished")                     \
	X(API_TOO_LARGE,            413, "body_too_large")                   \
	X(API_BODY_TOO_COMPLEX,     413, "body_too_complex")                 \
	X(API_URI_TOO_LONG,         414, "uri_too_long")                     \
	X(API_RANGE,                416, "range_not_satisfiable")            \
	X(API_INVALID_REQUEST,      422, "invalid_request")                  \
	X(API_INVALID_CASE,         422, "invalid_case")                     \
	X(API_INVALID_JSON_FILE,    422, "invalid_json_file")                \
	X(API_QUOTA_EXCEEDED,       429, "quota_exceeded")                   \
	X(API_TOO_MANY_REQUESTS,    429, "too_many_requests")                \
	X(API_TOO_MANY_CONNECTIONS, 429, "too_many_connections")             \
	X(API_HEADERS_TOO_LARGE,    431, "header_fields_too_large")          \
	X(API_INTERNAL,             500, "internal")                         \
	X(API_STORED_FILE_DAMAGED,  500, "stored_file_damaged")              \
	X(API_NOT_IMPLEMENTED,      501, "not_implemented")                  \
	X(API_UNAVAILABLE,          503, "unavailable")                      \
	X(API_INSUFFICIENT_STORAGE, 507, "insufficient_storage")             \
	X(API_VERSION_NOT_SUPPORTED, 505, "http_version_not_supported")

enum api_code {
#define API_ERROR_ENUM(code, status, name) code,
	API_ERROR_MAP(API_ERROR_ENUM)
#undef API_ERROR_ENUM
};

struct api_error {
	enum api_code code;
	char field[SERVER_FIELD_MAX];     /* JSON pointer, header or parameter name; "" for none */
	char message[SERVER_MESSAGE_MAX];
	json_t *problems;                 /* owned; [{"field", "message"}] for schema violations, or NULL */
	long long expected_offset;        /* log_gap: the offset the server expects, else -1 */
};

/* Records an error and returns its code: `return api_fail(err, API_NOT_FOUND, "", "no job %lld", id);` */
enum api_code api_fail(struct api_error *err, enum api_code code, const char *field, const char *fmt, ...)
	__attribute__((format(printf, 4, 5)));
void api_error_release(struct api_error *err);
/* The answer to a failed write, fsync or create on the state file system, by its errno: 507
 * insufficient_storage for a full disk or quota or a file-size limit (ENOSPC, EDQUOT, EFBIG),
 * else 503 unavailable (an I/O error). Both are the server's passing state: retry later. */
enum api_code api_storage_code(int e);
int api_code_status(enum api_code code);
const char *api_code_name(enum api_code code);

enum role { ROLE_USER = 1, ROLE_WORKER = 2, ROLE_ADMIN = 4 };
const char *role_name(enum role role);
int role_parse(const char *name, enum role *role);  /* 0, or -1 for an unknown name */

/* Who made a request: from the bearer token (auth.c). */
struct principal {
	long long user_id;
	char name[SERVER_NAME_MAX + 1];
	enum role role;
};

struct store;
struct metrics;

/* The running server: configuration, store, metrics and the wake-ups of blocked requests. */
struct server {
	struct server_config cfg;
	struct store *store;
	struct metrics *metrics;
	int access_log_fd;                /* -1 without --access-log */
	volatile int stopping;            /* set on SIGTERM: long-polls and follows end */
	pthread_mutex_t wake_lock;
	pthread_cond_t claim_cv;          /* broadcast when a job may have become claimable */
	unsigned long long claim_seq;     /* bumped with claim_cv, under wake_lock */
	pthread_cond_t log_cv;            /* broadcast when a log chunk or a job end was committed */
	unsigned long long log_seq;       /* bumped with log_cv, under wake_lock */
	/* What the server hears from workers, for why a queued job waits (store_jobs.c, "waiting"): */
	atomic_llong worker_seen_ms;      /* last claim or heartbeat of any worker, ms since the epoch; 0 = never */
	atomic_int claims_waiting;        /* claims long-polling for work right now */
};

/* Wake-ups (server.c): after a commit that queued a job, or appended a log / ended an attempt. */
void server_wake_claimers(struct server *srv);
void server_wake_log_readers(struct server *srv);

/* Workers: server_worker_seen() on every claim and heartbeat. server_workers() says whether a
 * claim is waiting for work right now (an idle worker long-polls one), else whether a worker was
 * heard from within the last --lease-seconds (a worker running jobs heartbeats at least every
 * lease / 3), else none is live. */
enum worker_presence { WORKERS_NONE, WORKERS_BUSY, WORKERS_WAITING };
void server_worker_seen(struct server *srv);
enum worker_presence server_workers(struct server *srv);

/* Wall-clock time in milliseconds since the epoch, and as RFC 3339 UTC ("...T...Z") into out[32]. */
long long now_ms(void);
void format_time(long long ms, char out[32]);

#endif
