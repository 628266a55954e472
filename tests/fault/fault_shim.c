/*
 * fault_shim.c - an LD_PRELOAD library for the fault and power-loss tests (docs/hardening.md):
 * it makes writes and fsyncs under one directory fail on request, and it keeps the image of that
 * directory that a power loss would leave: only what was fsynced.
 *
 * Failures. PORO_FAULT_ROOT names the directory (the server's state directory) and
 * PORO_FAULT_CONTROL a file of rules, read again whenever it changes (its size, time or inode),
 * so a test turns faults on and off while the process runs. One rule a line:
 *
 *     OP ERRNO MATCH [COUNT]      e.g.  write EIO poro.db-wal   fsync EIO *   write ENOSPC files/ 3
 *
 * OP is `write` (write, pwrite, pwrite64, writev, pwritev, fallocate) or `fsync` (fsync,
 * fdatasync); ERRNO one of EIO, ENOSPC, EDQUOT, EFBIG; MATCH a substring of the file's path
 * relative to the root (ending in `$`: a suffix of it), or `*` for every file under it; COUNT, when given, how many calls fail
 * before the rule is spent. A failing call does nothing and returns -1 with that errno, as the
 * kernel does for a full disk or a device error. An empty file injects nothing.
 *
 * Power loss. PORO_CRASH_ROOT names the directory and PORO_CRASH_IMAGE where its durable image is
 * kept. The image follows the rules a POSIX file system promises and no more:
 *   - a file's bytes become durable when fsync or fdatasync on it returns 0: the shim then copies
 *     the blocks that differ from the image into IMAGE/.data/KEY (KEY: inode and birth time);
 *   - a directory's entries (names and the files or directories they point to) become durable
 *     when fsync on the directory returns 0: IMAGE/.dirs/KEY is then rewritten;
 *   - nothing else is: writes never fsynced, a rename or a new file whose directory was not
 *     fsynced afterwards.
 * tests/fault/crash_image.py turns IMAGE into the directory the machine would find after the power
 * came back. The copy is made inside the fsync, before it returns, so whatever the process
 * acknowledged after an fsync is in the image; a process killed in the middle of a copy leaves
 * some of that fsync's blocks in the image and not others, as a disk may keep any part of writes
 * whose fsync had not returned. Updates hold a lock on IMAGE/.lock, so several processes
 * (the server, `poro-server token create`) may share one image.
 *
 * Only the calls that reach the dynamic linker are seen (not the C library's own writes from
 * stdio, which the fsync copy still catches, since it reads the file). Threads are safe.
 */
#define _GNU_SOURCE
#include <dirent.h>
#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/uio.h>
#include <unistd.h>

#define RULES_MAX 16
#define BLOCK 65536

struct rule {
	int is_fsync, err, count;     /* count < 0: unlimited */
	char match[PATH_MAX];
};

static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
static char fault_root[PATH_MAX], control[PATH_MAX], crash_root[PATH_MAX], image[PATH_MAX];
static struct rule rules[RULES_MAX];
static int rule_count;
static struct stat control_seen;

static ssize_t (*real_write)(int, const void *, size_t);
static ssize_t (*real_pwrite)(int, const void *, size_t, off_t);
static ssize_t (*real_pwrite64)(int, const void *, size_t, off_t);
static ssize_t (*real_writev)(int, const struct iovec *, int);
static ssize_t (*real_pwritev)(int, const struct iovec *, int, off_t);
static int (*real_fallocate)(int, int, off_t, off_t);
static int (*real_fsync)(int);
static int (*real_fdatasync)(int);

__attribute__((constructor)) static void shim_init(void)
{
	real_write = dlsym(RTLD_NEXT, "write");
	real_pwrite = dlsym(RTLD_NEXT, "pwrite");
	real_pwrite64 = dlsym(RTLD_NEXT, "pwrite64");
	real_writev = dlsym(RTLD_NEXT, "writev");
	real_pwritev = dlsym(RTLD_NEXT, "pwritev");
	real_fallocate = dlsym(RTLD_NEXT, "fallocate");
	real_fsync = dlsym(RTLD_NEXT, "fsync");
	real_fdatasync = dlsym(RTLD_NEXT, "fdatasync");
	const char *v;
	if ((v = getenv("PORO_FAULT_ROOT")) && !realpath(v, fault_root))
		fault_root[0] = '\0';
	if ((v = getenv("PORO_FAULT_CONTROL")))
		snprintf(control, sizeof control, "%s", v);
	if ((v = getenv("PORO_CRASH_ROOT")) && !realpath(v, crash_root))
		crash_root[0] = '\0';
	if ((v = getenv("PORO_CRASH_IMAGE")))
		snprintf(image, sizeof image, "%s", v);
}

/* The path of fd relative to root, or NULL when it is not under root. */
static const char *relative_path(int fd, const char *root, char *buf, size_t size)
{
	char link[64];
	snprintf(link, sizeof link, "/proc/self/fd/%d", fd);
	ssize_t n = readlink(link, buf, size - 1);
	if (n <= 0 || !root[0])
		return NULL;
	buf[n] = '\0';
	size_t r = strlen(root);
	if (strncmp(buf, root, r) != 0 || (buf[r] != '/' && buf[r] != '\0'))
		return NULL;
	return buf[r] == '/' ? buf + r + 1 : buf + r;
}

static int errno_named(const char *name)
{
	static const struct { const char *name; int value; } names[] = {
		{ "EIO", EIO }, { "ENOSPC", ENOSPC }, { "EDQUOT", EDQUOT }, { "EFBIG", EFBIG },
	};
	for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
		if (strcmp(name, names[i].name) == 0)
			return names[i].value;
	return 0;
}

/* Reads the rules again when the control file changed. Called with lock held. */
static void reload_rules(void)
{
	struct stat st;
	if (stat(control, &st) != 0) {
		rule_count = 0;
		memset(&control_seen, 0, sizeof control_seen);
		return;
	}
	if (st.st_ino == control_seen.st_ino && st.st_size == control_seen.st_size &&
	    st.st_mtim.tv_sec == control_seen.st_mtim.tv_sec && st.st_mtim.tv_nsec == control_seen.st_mtim.tv_nsec)
		return;
	control_seen = st;
	rule_count = 0;
	FILE *f = fopen(control, "r");
	if (!f)
		return;
	char line[PATH_MAX + 64], op[16], err[16], match[PATH_MAX];
	while (rule_count < RULES_MAX && fgets(line, sizeof line, f)) {
		int count = -1;
		if (sscanf(line, "%15s %15s %4095s %d", op, err, match, &count) < 3)
			continue;
		struct rule *r = &rules[rule_count];
		r->is_fsync = strcmp(op, "fsync") == 0;
		r->err = errno_named(err);
		r->count = count;
		snprintf(r->match, sizeof r->match, "%s", match);
		if (r->err && (r->is_fsync || strcmp(op, "write") == 0))
			rule_count++;
	}
	fclose(f);
}

/* The errno a call of this kind on fd must fail with, or 0. */
static int injected(int fd, int is_fsync)
{
	if (!control[0] || !fault_root[0])
		return 0;
	int e = 0;
	pthread_mutex_lock(&lock);
	reload_rules();
	char buf[PATH_MAX];
	const char *rel = rule_count ? relative_path(fd, fault_root, buf, sizeof buf) : NULL;
	for (int i = 0; rel && i < rule_count && !e; i++) {
		struct rule *r = &rules[i];
		if (r->is_fsync != is_fsync || r->count == 0)
			continue;
		size_t m = strlen(r->match), n = strlen(rel);
		int anchored = m > 0 && r->match[m - 1] == '$';
		if (strcmp(r->match, "*") == 0 || (anchored ? n >= m - 1 && strncmp(rel + n - (m - 1), r->match, m - 1) == 0
							    : strstr(rel, r->match) != NULL)) {
			e = r->err;
			if (r->count > 0)
				r->count--;
		}
	}
	pthread_mutex_unlock(&lock);
	return e;
}

#define FAIL_IF_INJECTED(fd, is_fsync)                  \
	do {                                            \
		int e_ = injected((fd), (is_fsync));    \
		if (e_) {                               \
			errno = e_;                     \
			return -1;                      \
		}                                       \
	} while (0)

/* ---- the durable image ---- */

static int image_key(const struct stat *st, char *key, size_t size, int fd)
{
	struct statx sx;
	long long birth = 0;
	if (statx(fd, "", AT_EMPTY_PATH, STATX_BTIME, &sx) == 0 && (sx.stx_mask & STATX_BTIME))
		birth = (long long)sx.stx_btime.tv_sec * 1000000000LL + sx.stx_btime.tv_nsec;
	return snprintf(key, size, "%llx-%llx", (unsigned long long)st->st_ino, (unsigned long long)birth) < (int)size
		       ? 0
		       : -1;
}

static int key_of_path_at(int dirfd, const char *name, char *key, size_t size, mode_t *mode)
{
	int fd = openat(dirfd, name, O_PATH | O_NOFOLLOW | O_CLOEXEC);
	if (fd < 0)
		return -1;
	struct stat st;
	int rc = fstat(fd, &st) == 0 ? image_key(&st, key, size, fd) : -1;
	*mode = st.st_mode;
	close(fd);
	return rc;
}

/* Copies the blocks of fd's file that differ from IMAGE/.data/KEY, then sets the image's size. */
static void image_file(int fd, const char *key)
{
	char path[PATH_MAX + 128], link[64];
	snprintf(path, sizeof path, "%s/.data/%s", image, key);
	snprintf(link, sizeof link, "/proc/self/fd/%d", fd);
	int in = open(link, O_RDONLY | O_CLOEXEC); /* fd may be open for writing only */
	int out = open(path, O_RDWR | O_CREAT | O_CLOEXEC, 0600);
	static char a[BLOCK], b[BLOCK]; /* under lock */
	off_t at = 0;
	ssize_t n;
	while (in >= 0 && out >= 0 && (n = pread(in, a, BLOCK, at)) > 0) {
		ssize_t m = pread(out, b, (size_t)n, at);
		if (m != n || memcmp(a, b, (size_t)n) != 0)
			real_pwrite(out, a, (size_t)n, at);
		at += n;
	}
	/* a file that shrank since its last fsync shrinks in the image; should that fail, the old
	 * length stays, as if the truncation had not reached the disk */
	if (out >= 0 && ftruncate(out, at) != 0) {
	}
	if (in >= 0)
		close(in);
	if (out >= 0)
		close(out);
}

/* Rewrites IMAGE/.dirs/KEY: one line per entry, "f|d HEX-NAME KEY". */
static void image_dir(int fd, const char *key)
{
	char path[PATH_MAX + 128], tmp[PATH_MAX + 160];
	snprintf(path, sizeof path, "%s/.dirs/%s", image, key);
	snprintf(tmp, sizeof tmp, "%s.tmp-%d", path, (int)getpid());
	int dfd = openat(fd, ".", O_RDONLY | O_DIRECTORY | O_CLOEXEC);
	DIR *d = dfd >= 0 ? fdopendir(dfd) : NULL;
	FILE *f = d ? fopen(tmp, "w") : NULL;
	struct dirent *e;
	while (f && (e = readdir(d))) {
		if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
			continue;
		char k[64];
		mode_t mode;
		if (key_of_path_at(dfd, e->d_name, k, sizeof k, &mode) != 0 || !(S_ISREG(mode) || S_ISDIR(mode)))
			continue;
		fputs(S_ISDIR(mode) ? "d " : "f ", f);
		for (const unsigned char *c = (const unsigned char *)e->d_name; *c; c++)
			fprintf(f, "%02x", *c);
		fprintf(f, " %s\n", k);
	}
	if (f && fclose(f) == 0)
		rename(tmp, path);
	if (d)
		closedir(d);
	else if (dfd >= 0)
		close(dfd);
}

static void image_record(int fd)
{
	if (!image[0] || !crash_root[0])
		return;
	char buf[PATH_MAX];
	if (!relative_path(fd, crash_root, buf, sizeof buf))
		return;
	struct stat st;
	char key[64];
	if (fstat(fd, &st) != 0 || image_key(&st, key, sizeof key, fd) != 0)
		return;
	pthread_mutex_lock(&lock);
	char p[PATH_MAX + 128];
	snprintf(p, sizeof p, "%s/.lock", image);
	int lk = open(p, O_RDWR | O_CREAT | O_CLOEXEC, 0600);
	if (lk >= 0)
		flock(lk, LOCK_EX);
	snprintf(p, sizeof p, "%s/.data", image);
	mkdir(p, 0700);
	snprintf(p, sizeof p, "%s/.dirs", image);
	mkdir(p, 0700);
	/* the root directory itself is taken as durable: the test made it before the run */
	snprintf(p, sizeof p, "%s/.root", image);
	if (access(p, F_OK) != 0) {
		int rfd = open(crash_root, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
		struct stat rst;
		char rkey[64];
		FILE *f;
		if (rfd >= 0 && fstat(rfd, &rst) == 0 && image_key(&rst, rkey, sizeof rkey, rfd) == 0 &&
		    (f = fopen(p, "w"))) {
			fprintf(f, "%s\n", rkey);
			fclose(f);
		}
		if (rfd >= 0)
			close(rfd);
	}
	if (S_ISREG(st.st_mode))
		image_file(fd, key);
	else if (S_ISDIR(st.st_mode))
		image_dir(fd, key);
	if (lk >= 0)
		close(lk); /* drops the flock */
	pthread_mutex_unlock(&lock);
}

/* ---- the calls ---- */

ssize_t write(int fd, const void *buf, size_t n)
{
	FAIL_IF_INJECTED(fd, 0);
	return real_write(fd, buf, n);
}

ssize_t pwrite(int fd, const void *buf, size_t n, off_t at)
{
	FAIL_IF_INJECTED(fd, 0);
	return real_pwrite(fd, buf, n, at);
}

ssize_t pwrite64(int fd, const void *buf, size_t n, off_t at)
{
	FAIL_IF_INJECTED(fd, 0);
	return real_pwrite64(fd, buf, n, at);
}

ssize_t writev(int fd, const struct iovec *iov, int count)
{
	FAIL_IF_INJECTED(fd, 0);
	return real_writev(fd, iov, count);
}

ssize_t pwritev(int fd, const struct iovec *iov, int count, off_t at)
{
	FAIL_IF_INJECTED(fd, 0);
	return real_pwritev(fd, iov, count, at);
}

int fallocate(int fd, int mode, off_t at, off_t len)
{
	FAIL_IF_INJECTED(fd, 0);
	return real_fallocate(fd, mode, at, len);
}

int fsync(int fd)
{
	FAIL_IF_INJECTED(fd, 1);
	int rc = real_fsync(fd);
	if (rc == 0)
		image_record(fd);
	return rc;
}

int fdatasync(int fd)
{
	FAIL_IF_INJECTED(fd, 1);
	int rc = real_fdatasync(fd);
	if (rc == 0)
		image_record(fd);
	return rc;
}
