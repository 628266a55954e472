/*
 * api_json.c - checks of request bodies, query parameters and file names shared by the handlers
 * (api.h). Each check replies with the error itself (400 for malformed input, 422 naming the JSON
 * pointer of a schema violation) and returns -1, so handlers read `if (check(...)) return;`.
 */
#include "api.h"
#include "store.h"

#include <stdlib.h>
#include <string.h>

json_t *api_body_object(struct request *r)
{
	/* jansson sets the error's code only where it reports an error: when it runs out of memory
	 * before reading (its lexer's buffer), it returns NULL with the code left as it found it, so
	 * an uninitialised one read as a client's error and answered 400 under memory pressure.
	 * Zeroed, the code is json_error_unknown there, which answers 503 below. */
	json_error_t je;
	memset(&je, 0, sizeof je);
	if (!r->body || r->body_size == 0) {
		reply_fail(r, API_INVALID_JSON, "", "request body is empty: expected a JSON object");
		return NULL;
	}
	json_t *v = json_loadb(r->body, r->body_size, JSON_REJECT_DUPLICATES, &je);
	if (!v) {
		/* http.c has already checked the body's syntax while it streamed in (json_scan.h). What
		 * the scan does not check is the client's error: UTF-8, \u escapes of lone surrogates,
		 * \u0000, duplicate keys, numbers beyond 64 bits. Any other failure is jansson running
		 * out of memory midway, which it reports as whatever syntax error the half-read token
		 * makes ("invalid token", "string or '}' expected", line -1). */
		enum json_error_code code = json_error_code(&je);
		int clients = je.text[0] != '\0' && (code == json_error_invalid_utf8 || code == json_error_null_character ||
			      code == json_error_duplicate_key || code == json_error_numeric_overflow ||
			      (code == json_error_invalid_syntax && strncmp(je.text, "invalid Unicode", 15) == 0));
		if (!clients) {
			reply_header(r, "Retry-After", "1");
			reply_fail(r, API_UNAVAILABLE, "", "no memory to read a request body of %zu bytes: retry later",
				   r->body_size);
			return NULL;
		}
		reply_fail(r, API_INVALID_JSON, "", "request body is not valid JSON: line %d column %d: %s", je.line,
			   je.column, je.text);
		return NULL;
	}
	if (!json_is_object(v)) {
		json_decref(v);
		reply_fail(r, API_INVALID_JSON, "", "request body must be a JSON object");
		return NULL;
	}
	return v;
}

int api_known_keys(struct request *r, json_t *obj, const char *const *keys)
{
	const char *key;
	json_t *value;
	json_object_foreach(obj, key, value) {
		int known = 0;
		for (const char *const *k = keys; *k && !known; k++)
			known = strcmp(*k, key) == 0;
		if (!known) {
			/* keys are JSON text: show at most a short, safe prefix */
			char field[SERVER_FIELD_MAX];
			snprintf(field, sizeof field, "/%.100s", key);
			reply_fail(r, API_INVALID_REQUEST, field, "unknown key '%.100s'", key);
			return -1;
		}
	}
	return 0;
}

int api_int_member(struct request *r, json_t *obj, const char *key, long long min, long long max, long long def,
		   long long *out)
{
	json_t *v = json_object_get(obj, key);
	char field[SERVER_FIELD_MAX];
	snprintf(field, sizeof field, "/%s", key);
	if (!v || json_is_null(v)) {
		*out = def;
		return 0;
	}
	if (!json_is_integer(v)) {
		reply_fail(r, API_INVALID_REQUEST, field, "'%s' must be an integer", key);
		return -1;
	}
	*out = json_integer_value(v);
	if (*out < min || *out > max) {
		reply_fail(r, API_INVALID_REQUEST, field, "'%s' must be in %lld..%lld, got %lld", key, min, max, *out);
		return -1;
	}
	return 0;
}

int api_string_member(struct request *r, json_t *obj, const char *key, size_t max, int required, const char **out)
{
	json_t *v = json_object_get(obj, key);
	char field[SERVER_FIELD_MAX];
	snprintf(field, sizeof field, "/%s", key);
	*out = NULL;
	if (!v || json_is_null(v)) {
		if (required) {
			reply_fail(r, API_INVALID_REQUEST, field, "missing required key '%s'", key);
			return -1;
		}
		return 0;
	}
	if (!json_is_string(v)) {
		reply_fail(r, API_INVALID_REQUEST, field, "'%s' must be a string", key);
		return -1;
	}
	const char *s = json_string_value(v);
	size_t n = json_string_length(v);
	if (n == 0 || n > max || strlen(s) != n) {
		reply_fail(r, API_INVALID_REQUEST, field, "'%s' must be 1..%zu bytes without NUL", key, max);
		return -1;
	}
	for (size_t i = 0; i < n; i++)
		if ((unsigned char)s[i] < 0x20 && s[i] != '\t') {
			reply_fail(r, API_INVALID_REQUEST, field, "'%s' must not contain control characters", key);
			return -1;
		}
	*out = s;
	return 0;
}

int api_query_int(struct request *r, const char *name, long long min, long long max, long long def, long long *out)
{
	char text[32];
	int have = http_query(r, name, text, sizeof text);
	*out = def;
	if (have == 0)
		return 0;
	char *end = NULL;
	long long v = have > 0 && text[0] ? strtoll(text, &end, 10) : 0;
	if (have < 0 || !text[0] || *end || v < min || v > max) {
		reply_fail(r, API_INVALID_PARAMETER, name, "query parameter '%s' must be an integer in %lld..%lld", name,
			   min, max);
		return -1;
	}
	*out = v;
	return 0;
}

#define FILE_NAME_MAX 128

int api_file_name_valid(const char *name)
{
	int ok = name[0] && strlen(name) <= FILE_NAME_MAX && strstr(name, "..") == NULL;
	for (size_t i = 0; ok && name[i]; i++) {
		char c = name[i];
		int alnum = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9');
		ok = alnum || (i > 0 && (c == '.' || c == '_' || c == '-'));
	}
	return ok;
}

int api_file_name(struct request *r, const char *raw, char out[FILE_NAME_MAX + 1])
{
	int ok = raw && http_decode(raw, out, FILE_NAME_MAX + 1) == 0 && api_file_name_valid(out);
	if (!ok) {
		reply_fail(r, API_INVALID_FILE_NAME, "name",
			   "file name must match ^[A-Za-z0-9][A-Za-z0-9._-]{0,127}$ and not contain '..'");
		return -1;
	}
	return 0;
}

int api_job_visible(struct request *r)
{
	json_t *job = NULL;
	struct api_error err = { 0 };
	if (store_job_get(r->srv->store, &r->who, r->id, 0, &job, &err) != API_OK) {
		reply_error(r, &err);
		return -1;
	}
	json_decref(job);
	return 0;
}
