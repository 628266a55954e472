/*
 * web.c - the dashboard's static files (docs/web.md): GET / answers WEB_ROOT/index.html and
 * GET /web/{name} any file below WEB_ROOT, with no token (the pages hold no data; every datum
 * comes from the API with the token the page keeps in session storage).
 *
 * WEB_ROOT is --web-root, else found beside the program: BINDIR/../share/poro/web (make install)
 * or BINDIR/../web (the build directory of a checkout), the first that holds index.html. Names
 * are checked before any file is opened: path elements of [A-Za-z0-9._-] that start with a letter
 * or digit (so no "..", no hidden file, no empty element), at most WEB_NAME_MAX bytes, and an
 * extension of the table below (anything else is 404), so a request can reach nothing but the
 * dashboard's own files. Symbolic links inside WEB_ROOT are followed: an operator's tree, like
 * a web server's document root.
 *
 * Headers: every file "Cache-Control: no-cache" (revalidated, so an upgrade shows at once) and
 * "X-Content-Type-Options: nosniff"; pages also a Content-Security-Policy that allows scripts,
 * styles, images and connections from this origin only (no inline script, no eval), and neither
 * framing nor a referrer.
 */
#define _DEFAULT_SOURCE /* readlink */
#include "api.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define WEB_NAME_MAX 256

static const struct {
	const char *ext, *type;
} TYPES[] = {
	{ ".html", "text/html; charset=utf-8" },  { ".js", "text/javascript; charset=utf-8" },
	{ ".css", "text/css; charset=utf-8" },    { ".json", "application/json" },
	{ ".svg", "image/svg+xml" },              { ".png", "image/png" },
	{ ".txt", "text/plain; charset=utf-8" },  { ".ico", "image/x-icon" },
};

static const char CSP[] = "default-src 'none'; script-src 'self'; style-src 'self' 'unsafe-inline'; "
			  "img-src 'self' data: blob:; connect-src 'self'; font-src 'self'; base-uri 'none'; "
			  "form-action 'self'; frame-ancestors 'none'";

static int exists(const char *dir, const char *file)
{
	char path[SERVER_PATH_MAX];
	struct stat st;
	snprintf(path, sizeof path, "%s/%s", dir, file);
	return stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

void web_root_default(char *out, size_t size)
{
	char exe[SERVER_STATE_MAX];
	out[0] = '\0';
	ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
	if (n <= 0)
		return;
	exe[n] = '\0';
	char *slash = strrchr(exe, '/');
	if (!slash)
		return;
	*slash = '\0';
	static const char *const below[] = { "/../share/poro/web", "/../web" };
	for (size_t i = 0; i < sizeof below / sizeof *below; i++) {
		char dir[SERVER_STATE_MAX + 32];
		snprintf(dir, sizeof dir, "%s%s", exe, below[i]);
		char *real = realpath(dir, NULL);
		if (real && exists(real, "index.html") && strlen(real) < size) {
			snprintf(out, size, "%s", real);
			free(real);
			return;
		}
		free(real);
	}
}

/* The type of a checked name, or NULL: the name is refused. */
static const char *checked_type(const char *name)
{
	size_t n = strlen(name);
	if (n == 0 || n > WEB_NAME_MAX)
		return NULL;
	for (const char *p = name; *p; p++) {
		int start = p == name || p[-1] == '/';
		int alnum = (*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') || (*p >= '0' && *p <= '9');
		if (start && !alnum)
			return NULL; /* no empty element, "..", hidden file or leading dash */
		if (!alnum && *p != '.' && *p != '_' && *p != '-' && *p != '/')
			return NULL;
	}
	const char *dot = strrchr(name, '.');
	for (size_t i = 0; dot && !strchr(dot, '/') && i < sizeof TYPES / sizeof *TYPES; i++)
		if (strcmp(dot, TYPES[i].ext) == 0)
			return TYPES[i].type;
	return NULL;
}

static void serve(struct request *r, const char *name)
{
	const char *type = checked_type(name);
	const char *root = r->srv->cfg.web_root;
	if (!root[0]) {
		reply_fail(r, API_NOT_FOUND, "", "the dashboard is not installed: no --web-root with an index.html");
		return;
	}
	if (!type) {
		reply_fail(r, API_NOT_FOUND, "", "no file '%s' in the dashboard", name);
		return;
	}
	char path[SERVER_PATH_MAX];
	snprintf(path, sizeof path, "%s/%s", root, name);
	int fd = open(path, O_RDONLY | O_CLOEXEC);
	struct stat st;
	if (fd < 0 || fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
		if (fd >= 0)
			close(fd);
		reply_fail(r, API_NOT_FOUND, "", "no file '%s' in the dashboard", name);
		return;
	}
	reply_fd(r, 200, fd, 0, (long long)st.st_size);
	r->reply.content_type = type;
	reply_header(r, "Cache-Control", "no-cache");
	reply_header(r, "X-Content-Type-Options", "nosniff");
	if (strcmp(type, TYPES[0].type) == 0) {
		reply_header(r, "Content-Security-Policy", CSP);
		reply_header(r, "X-Frame-Options", "DENY");
		reply_header(r, "Referrer-Policy", "no-referrer");
	}
}

void web_index(struct request *r)
{
	serve(r, "index.html");
}

void web_file(struct request *r)
{
	char name[WEB_NAME_MAX + 2];
	if (http_decode(r->name, name, sizeof name) != 0) {
		reply_fail(r, API_NOT_FOUND, "", "no such file in the dashboard");
		return;
	}
	serve(r, name);
}
