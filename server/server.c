/*
 * server.c - the small pieces every part of poro-server uses (server.h): the error table's
 * lookups and api_fail(), role names, wall-clock time in RFC 3339, the wake-ups of blocked
 * long-polls and log followers, and whether any worker is live.
 */
#include "server.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

static const struct {
	int status;
	const char *name;
} CODES[] = {
#define API_ERROR_ROW(code, status, name) { status, name },
	API_ERROR_MAP(API_ERROR_ROW)
#undef API_ERROR_ROW
};

int api_code_status(enum api_code code)
{
	return CODES[code].status;
}

const char *api_code_name(enum api_code code)
{
	return CODES[code].name;
}

enum api_code api_fail(struct api_error *err, enum api_code code, const char *field, const char *fmt, ...)
{
	if (!err)
		return code;
	err->code = code;
	snprintf(err->field, sizeof err->field, "%s", field);
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(err->message, sizeof err->message, fmt, ap);
	va_end(ap);
	return code;
}

enum api_code api_storage_code(int e)
{
	return e == ENOSPC || e == EDQUOT || e == EFBIG ? API_INSUFFICIENT_STORAGE : API_UNAVAILABLE;
}

void api_error_release(struct api_error *err)
{
	json_decref(err->problems);
	err->problems = NULL;
}

static const char *const ROLE_NAMES[] = { "user", "worker", "admin" };

const char *role_name(enum role role)
{
	return role == ROLE_ADMIN ? ROLE_NAMES[2] : role == ROLE_WORKER ? ROLE_NAMES[1] : ROLE_NAMES[0];
}

int role_parse(const char *name, enum role *role)
{
	static const enum role values[] = { ROLE_USER, ROLE_WORKER, ROLE_ADMIN };
	for (int i = 0; i < 3; i++)
		if (name && strcmp(name, ROLE_NAMES[i]) == 0) {
			*role = values[i];
			return 0;
		}
	return -1;
}

long long now_ms(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_REALTIME, &ts);
	return (long long)ts.tv_sec * 1000 + ts.tv_nsec / 1000000;
}

void format_time(long long ms, char out[32])
{
	time_t secs = (time_t)(ms / 1000);
	struct tm tm;
	gmtime_r(&secs, &tm);
	char date[24];
	strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%S", &tm);
	snprintf(out, 32, "%.19s.%03uZ", date, (unsigned)(ms % 1000) % 1000u);
}

void server_wake_claimers(struct server *srv)
{
	pthread_mutex_lock(&srv->wake_lock);
	srv->claim_seq++;
	pthread_cond_broadcast(&srv->claim_cv);
	pthread_mutex_unlock(&srv->wake_lock);
}

void server_wake_log_readers(struct server *srv)
{
	pthread_mutex_lock(&srv->wake_lock);
	srv->log_seq++;
	pthread_cond_broadcast(&srv->log_cv);
	pthread_mutex_unlock(&srv->wake_lock);
}

void server_worker_seen(struct server *srv)
{
	atomic_store(&srv->worker_seen_ms, now_ms());
}

enum worker_presence server_workers(struct server *srv)
{
	if (atomic_load(&srv->claims_waiting) > 0)
		return WORKERS_WAITING;
	long long seen = atomic_load(&srv->worker_seen_ms);
	return seen > 0 && now_ms() - seen <= 1000LL * srv->cfg.lease_seconds ? WORKERS_BUSY : WORKERS_NONE;
}
