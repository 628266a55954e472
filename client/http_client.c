/*
 * http_client.c - the libcurl gateway of the service clients (see http_client.h). Each request
 * resets the one easy handle of its client (curl_easy_reset keeps the connection cache, so
 * keep-alive connections survive), sets the options it needs and performs. Bodies kept in memory
 * are bounded by HTTP_MAX_BODY; downloads and uploads stream through a FILE with SHA-256 computed
 * on the way. CURLOPT_NOSIGNAL is set everywhere because the clients are multi-threaded.
 */
#include "http_client.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

#include <curl/curl.h>

struct http_client {
	CURL *curl;
	char *server;         /* base URL without a trailing slash */
	char *auth;           /* "Authorization: Bearer TOKEN", or NULL */
	const atomic_int *abort_flag;
};

/* A growing in-memory body. */
struct buffer {
	char *data;
	size_t len, cap;
	int overflow;
};

/* What a transfer's callbacks share. */
struct transfer {
	struct http_client *client;
	struct http_response *r;
	struct buffer body;          /* JSON answers and error bodies */
	FILE *file;                  /* download target or NULL */
	struct digest *digest;       /* of downloaded bytes */
	long long bytes;             /* bytes written to file or passed to the line callback */
	http_line_fn line_fn;
	void *line_user;
	struct buffer line;          /* the incomplete line of a stream */
	int stopped;                 /* line_fn asked to stop */
	int write_failed;
};

int http_global_init(void)
{
	return curl_global_init(CURL_GLOBAL_DEFAULT) == CURLE_OK ? 0 : -1;
}

void http_global_cleanup(void)
{
	curl_global_cleanup();
}

static char ca_file_path[1024]; /* "" for the system's authorities; set before threads start */

void http_global_ca_file(const char *ca_file)
{
	snprintf(ca_file_path, sizeof ca_file_path, "%s", ca_file ? ca_file : "");
}

struct http_client *http_client_create(const char *server, const char *token)
{
	struct http_client *c = calloc(1, sizeof *c);
	if (!c)
		return NULL;
	c->curl = curl_easy_init();
	c->server = strdup(server);
	if (c->server) {
		size_t n = strlen(c->server);
		while (n > 0 && c->server[n - 1] == '/')
			c->server[--n] = '\0';
	}
	if (token && *token) {
		size_t n = strlen(token) + 32;
		c->auth = malloc(n);
		if (c->auth)
			snprintf(c->auth, n, "Authorization: Bearer %s", token);
	}
	if (!c->curl || !c->server || (token && *token && !c->auth)) {
		http_client_destroy(&c);
		return NULL;
	}
	return c;
}

void http_client_destroy(struct http_client **c)
{
	if (!c || !*c)
		return;
	if ((*c)->curl)
		curl_easy_cleanup((*c)->curl);
	free((*c)->server);
	free((*c)->auth);
	free(*c);
	*c = NULL;
}

void http_client_set_abort(struct http_client *c, const atomic_int *flag)
{
	c->abort_flag = flag;
}

void http_response_release(struct http_response *r)
{
	if (r->json)
		json_decref(r->json);
	memset(r, 0, sizeof *r);
}

int http_ok(const struct http_response *r)
{
	return r->status >= 200 && r->status < 300;
}

int http_transient(const struct http_response *r)
{
	/* an unverifiable certificate is a setting to fix: asking again gets the same answer */
	return (r->status == 0 && !r->tls_unverified) || r->status >= 500 || r->status == 408 || r->status == 429;
}

const char *http_describe(const struct http_response *r, char *buf, size_t size)
{
	if (r->code[0] && r->field[0])
		snprintf(buf, size, "%s (%s, field %s)", r->error, r->code, r->field);
	else if (r->code[0])
		snprintf(buf, size, "%s (%s)", r->error, r->code);
	else
		snprintf(buf, size, "%s", r->error[0] ? r->error : "no answer");
	return buf;
}

static int buffer_append(struct buffer *b, const char *data, size_t n)
{
	if (b->len + n + 1 > b->cap) {
		if (b->len + n + 1 > (size_t)HTTP_MAX_BODY) {
			b->overflow = 1;
			return -1;
		}
		size_t cap = b->cap ? b->cap : 4096;
		while (cap < b->len + n + 1)
			cap *= 2;
		char *p = realloc(b->data, cap);
		if (!p)
			return -1;
		b->data = p;
		b->cap = cap;
	}
	memcpy(b->data + b->len, data, n);
	b->len += n;
	b->data[b->len] = '\0';
	return 0;
}

static void buffer_release(struct buffer *b)
{
	free(b->data);
	memset(b, 0, sizeof *b);
}

static long response_code(struct http_client *c)
{
	long code = 0;
	curl_easy_getinfo(c->curl, CURLINFO_RESPONSE_CODE, &code);
	return code;
}

/* Lines of a stream go to the callback; everything else is kept in memory, and a 2xx download
 * goes to its file. An error answer of a download or stream is kept in memory to be parsed. */
static size_t on_write(char *data, size_t size, size_t nmemb, void *user)
{
	struct transfer *t = user;
	size_t n = size * nmemb;
	long code = response_code(t->client);
	int success = code >= 200 && code < 300;
	if (t->file && success) {
		if (fwrite(data, 1, n, t->file) != n) {
			t->write_failed = 1;
			return 0;
		}
		digest_update(t->digest, data, n);
		t->bytes += (long long)n;
		return n;
	}
	if (t->line_fn && success) {
		size_t start = 0;
		for (size_t i = 0; i < n; i++) {
			if (data[i] != '\n')
				continue;
			if (buffer_append(&t->line, data + start, i - start) < 0)
				return 0;
			/* the whole line: its start may have come in an earlier piece */
			t->bytes += (long long)t->line.len + 1;
			if (t->line_fn(t->line.data ? t->line.data : "", t->line.len, t->line_user)) {
				t->stopped = 1;
				return 0;
			}
			t->line.len = 0;
			start = i + 1;
		}
		if (start < n && buffer_append(&t->line, data + start, n - start) < 0)
			return 0;
		return n;
	}
	if (buffer_append(&t->body, data, n) < 0)
		return 0;
	return n;
}

static size_t on_header(char *data, size_t size, size_t nmemb, void *user)
{
	struct transfer *t = user;
	size_t n = size * nmemb;
	static const char name[] = "x-checksum-sha256:";
	size_t k = sizeof name - 1;
	if (n > k && !strncasecmp(data, name, k)) {
		size_t i = k, j = 0;
		while (i < n && (data[i] == ' ' || data[i] == '\t'))
			i++;
		while (i < n && j < DIGEST_HEX_SIZE - 1 && data[i] != '\r' && data[i] != '\n' && data[i] != ' ')
			t->r->sha256[j++] = data[i++];
		t->r->sha256[j] = '\0';
	}
	return n;
}

static int on_progress(void *user, curl_off_t dltotal, curl_off_t dlnow, curl_off_t ultotal, curl_off_t ulnow)
{
	struct transfer *t = user;
	return t->client->abort_flag && atomic_load(t->client->abort_flag) ? 1 : 0;
}

/* Copies the server's error object, if the body is one, into r. */
static void parse_error(struct http_response *r)
{
	json_t *e = r->json ? json_object_get(r->json, "error") : NULL;
	if (!json_is_object(e)) {
		snprintf(r->error, sizeof r->error, "server answered %ld", r->status);
		return;
	}
	const char *s = json_string_value(json_object_get(e, "message"));
	snprintf(r->error, sizeof r->error, "%s", s ? s : "error without a message");
	s = json_string_value(json_object_get(e, "code"));
	snprintf(r->code, sizeof r->code, "%s", s ? s : "");
	s = json_string_value(json_object_get(e, "field"));
	snprintf(r->field, sizeof r->field, "%s", s ? s : "");
}

/* Sets the options every request shares; the caller adds method, body and target. */
static void setup(struct http_client *c, struct transfer *t, const char *path, long timeout_seconds,
		  struct curl_slist **headers)
{
	CURL *h = c->curl;
	curl_easy_reset(h);
	size_t n = strlen(c->server) + strlen(path) + 1;
	char *url = malloc(n);
	if (url) {
		snprintf(url, n, "%s%s", c->server, path);
		curl_easy_setopt(h, CURLOPT_URL, url); /* libcurl copies the string */
		free(url);
	}
	curl_easy_setopt(h, CURLOPT_NOSIGNAL, 1L);
	curl_easy_setopt(h, CURLOPT_CONNECTTIMEOUT, (long)HTTP_CONNECT_TIMEOUT);
	if (timeout_seconds > 0)
		curl_easy_setopt(h, CURLOPT_TIMEOUT, timeout_seconds);
	curl_easy_setopt(h, CURLOPT_TCP_KEEPALIVE, 1L);
	if (ca_file_path[0])
		curl_easy_setopt(h, CURLOPT_CAINFO, ca_file_path);
	curl_easy_setopt(h, CURLOPT_WRITEFUNCTION, on_write);
	curl_easy_setopt(h, CURLOPT_WRITEDATA, t);
	curl_easy_setopt(h, CURLOPT_HEADERFUNCTION, on_header);
	curl_easy_setopt(h, CURLOPT_HEADERDATA, t);
	curl_easy_setopt(h, CURLOPT_XFERINFOFUNCTION, on_progress);
	curl_easy_setopt(h, CURLOPT_XFERINFODATA, t);
	curl_easy_setopt(h, CURLOPT_NOPROGRESS, 0L);
	if (c->auth)
		*headers = curl_slist_append(*headers, c->auth);
	/* No "Expect: 100-continue" round trip before bodies. */
	*headers = curl_slist_append(*headers, "Expect:");
}

/* Performs the prepared request and fills r from the outcome. */
static long perform(struct transfer *t, struct curl_slist *headers)
{
	struct http_client *c = t->client;
	struct http_response *r = t->r;
	char curl_error[CURL_ERROR_SIZE] = "";
	curl_easy_setopt(c->curl, CURLOPT_HTTPHEADER, headers);
	curl_easy_setopt(c->curl, CURLOPT_ERRORBUFFER, curl_error);
	CURLcode rc = curl_easy_perform(c->curl);
	long code = response_code(c);
	if (t->line_fn && rc == CURLE_OK && t->line.len > 0 && !t->stopped) {
		t->bytes += (long long)t->line.len;
		t->line_fn(t->line.data, t->line.len, t->line_user);
	}
	if (rc != CURLE_OK && !(t->stopped && rc == CURLE_WRITE_ERROR)) {
		/* A transfer that broke off has no trustworthy answer, whatever status line arrived. */
		r->status = t->stopped ? code : 0;
		if (rc == CURLE_ABORTED_BY_CALLBACK)
			snprintf(r->error, sizeof r->error, "request aborted");
		else if (t->write_failed)
			snprintf(r->error, sizeof r->error, "cannot write the download: %s", strerror(errno));
		else if (t->body.overflow)
			snprintf(r->error, sizeof r->error, "answer larger than %ld bytes", (long)HTTP_MAX_BODY);
		else if ((r->tls_unverified = rc == CURLE_PEER_FAILED_VERIFICATION || rc == CURLE_SSL_CACERT_BADFILE))
			snprintf(r->error, sizeof r->error, "cannot verify the server's TLS certificate against %s%.200s%s: %.200s",
				 ca_file_path[0] ? "the CA file '" : "the system's certificate authorities",
				 ca_file_path, ca_file_path[0] ? "'" : "", curl_error[0] ? curl_error : curl_easy_strerror(rc));
		else
			snprintf(r->error, sizeof r->error, "%s", curl_error[0] ? curl_error : curl_easy_strerror(rc));
		r->local = t->write_failed;
	} else {
		r->status = code;
	}
	curl_easy_setopt(c->curl, CURLOPT_ERRORBUFFER, NULL);
	curl_slist_free_all(headers);
	if (t->body.len > 0) {
		r->json = json_loadb(t->body.data, t->body.len, 0, NULL);
	}
	if (r->status != 0 && !http_ok(r))
		parse_error(r);
	buffer_release(&t->body);
	buffer_release(&t->line);
	return r->status;
}

static void transfer_init(struct transfer *t, struct http_client *c, struct http_response *r)
{
	memset(t, 0, sizeof *t);
	memset(r, 0, sizeof *r);
	t->client = c;
	t->r = r;
}

long http_json(struct http_client *c, const char *method, const char *path, const json_t *body,
	       const char *extra_header, long timeout_seconds, struct http_response *r)
{
	struct transfer t;
	struct curl_slist *headers = NULL;
	transfer_init(&t, c, r);
	setup(c, &t, path, timeout_seconds, &headers);
	char *text = NULL;
	if (body) {
		text = json_dumps(body, JSON_COMPACT);
		if (!text) {
			curl_slist_free_all(headers);
			r->local = 1;
			snprintf(r->error, sizeof r->error, "cannot encode the request body");
			return 0;
		}
		headers = curl_slist_append(headers, "Content-Type: application/json");
		curl_easy_setopt(c->curl, CURLOPT_POSTFIELDS, text);
		curl_easy_setopt(c->curl, CURLOPT_POSTFIELDSIZE, (long)strlen(text));
	}
	if (extra_header)
		headers = curl_slist_append(headers, extra_header);
	if (!strcmp(method, "POST") && !body)
		curl_easy_setopt(c->curl, CURLOPT_POSTFIELDS, "");
	if (strcmp(method, "GET"))
		curl_easy_setopt(c->curl, CURLOPT_CUSTOMREQUEST, method);
	headers = curl_slist_append(headers, "Accept: application/json");
	long status = perform(&t, headers);
	free(text);
	return status;
}

long http_download(struct http_client *c, const char *path, const char *dest, char sha256[DIGEST_HEX_SIZE],
		   long long *size, struct http_response *r)
{
	struct transfer t;
	struct curl_slist *headers = NULL;
	transfer_init(&t, c, r);
	t.file = fopen(dest, "wb");
	if (!t.file) {
		r->local = 1;
		snprintf(r->error, sizeof r->error, "cannot create '%s': %s", dest, strerror(errno));
		return 0;
	}
	t.digest = digest_create();
	if (!t.digest) {
		fclose(t.file);
		remove(dest);
		r->local = 1;
		snprintf(r->error, sizeof r->error, "out of memory");
		return 0;
	}
	setup(c, &t, path, 0, &headers);
	curl_easy_setopt(c->curl, CURLOPT_LOW_SPEED_LIMIT, 1L);
	curl_easy_setopt(c->curl, CURLOPT_LOW_SPEED_TIME, (long)HTTP_STALL_SECONDS);
	long status = perform(&t, headers);
	if (fclose(t.file) != 0 && http_ok(r)) {
		r->local = 1;
		snprintf(r->error, sizeof r->error, "cannot write '%s': %s", dest, strerror(errno));
		r->status = 0;
		status = 0;
	}
	char hex[DIGEST_HEX_SIZE];
	digest_final_hex(t.digest, hex);
	digest_destroy(&t.digest);
	if (!http_ok(r)) {
		remove(dest);
		return status;
	}
	if (sha256)
		memcpy(sha256, hex, DIGEST_HEX_SIZE);
	if (size)
		*size = t.bytes;
	return status;
}

long http_upload(struct http_client *c, const char *path, const char *src, const char *sha256,
		 struct http_response *r)
{
	struct transfer t;
	struct curl_slist *headers = NULL;
	transfer_init(&t, c, r);
	FILE *f = fopen(src, "rb");
	if (!f) {
		r->local = 1;
		snprintf(r->error, sizeof r->error, "cannot open '%s': %s", src, strerror(errno));
		return 0;
	}
	if (fseeko(f, 0, SEEK_END) != 0) {
		fclose(f);
		r->local = 1;
		snprintf(r->error, sizeof r->error, "cannot read '%s': %s", src, strerror(errno));
		return 0;
	}
	curl_off_t size = (curl_off_t)ftello(f);
	rewind(f);
	setup(c, &t, path, 0, &headers);
	curl_easy_setopt(c->curl, CURLOPT_LOW_SPEED_LIMIT, 1L);
	curl_easy_setopt(c->curl, CURLOPT_LOW_SPEED_TIME, (long)HTTP_STALL_SECONDS);
	curl_easy_setopt(c->curl, CURLOPT_UPLOAD, 1L);
	curl_easy_setopt(c->curl, CURLOPT_READDATA, f);
	curl_easy_setopt(c->curl, CURLOPT_INFILESIZE_LARGE, size);
	char checksum[128];
	snprintf(checksum, sizeof checksum, "X-Checksum-Sha256: %s", sha256);
	headers = curl_slist_append(headers, checksum);
	headers = curl_slist_append(headers, "Content-Type: application/octet-stream");
	long status = perform(&t, headers);
	fclose(f);
	return status;
}

long http_stream_lines(struct http_client *c, const char *path, http_line_fn fn, void *user,
		       long long *received, struct http_response *r)
{
	struct transfer t;
	struct curl_slist *headers = NULL;
	transfer_init(&t, c, r);
	t.line_fn = fn;
	t.line_user = user;
	setup(c, &t, path, 0, &headers);
	long status = perform(&t, headers);
	if (received)
		*received = t.bytes;
	return status;
}
