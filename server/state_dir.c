/*
 * state_dir.c - lock, permissions and file-system checks of the state directory (state_dir.h).
 *
 * Why the server both sets umask 077 (main.c) and chmods what exists here: the umask governs
 * only files created from now on, so a database, results or a directory left world-readable by
 * an older binary or by a state directory made by hand stay readable; and SQLite gives a new -wal
 * and -shm the mode of the database file itself (it fchmods them, bypassing the umask), so a
 * poro.db left 0644 would go on producing world-readable write-ahead logs. The chmod pass fixes
 * the past; the umask keeps the future private.
 */
#define _XOPEN_SOURCE 700
#include "log.h"
#include "state_dir.h"
#include "store.h"

#include "fs.h"

#include <errno.h>
#include <fcntl.h>
#include <ftw.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <time.h>
#include <unistd.h>

#define STATE_PATH_MAX 4352
#define OWNER_ONLY 0700
#define PRIVATE_BITS 077              /* group and other permissions */
#define WALK_OPEN_FDS 32              /* descriptors nftw may hold while walking files/ */
#define LOCK_PID_TRIES 20             /* reads of the holder's pid while it may not be written yet */
#define LOCK_PID_WAIT_NS 10000000L    /* between those reads: 10 ms */

/* Files of the state directory itself (files/ is walked). */
static const char *const STATE_FILES[] = { "poro.db", "poro.db-wal", "poro.db-shm", "poro.db-journal",
					   "server.url", "server-tls.url", STATE_DIR_LOCK_NAME };

static int restrict_failures; /* nftw's callback has no argument: the one walk at start-up counts here */

/* Clears group and other bits of one file or directory; counts and reports a failure. */
static void restrict_one(const char *path, const struct stat *st)
{
	if (!(st->st_mode & PRIVATE_BITS))
		return;
	mode_t mode = S_ISDIR(st->st_mode) ? OWNER_ONLY : st->st_mode & OWNER_ONLY;
	if (chmod(path, mode) != 0) {
		log_say(LOG_PRIO_WARNING, "cannot make '%s' private to its owner: %s", path, strerror(errno));
		restrict_failures++;
	}
}

static int restrict_entry(const char *path, const struct stat *st, int type, struct FTW *ftw)
{
	if (type == FTW_F || type == FTW_D || type == FTW_DP)
		restrict_one(path, st);
	return 0;
}

int state_dir_restrict(const char *state)
{
	char path[STATE_PATH_MAX];
	struct stat st;
	restrict_failures = 0;
	if (lstat(state, &st) == 0 && S_ISDIR(st.st_mode))
		restrict_one(state, &st);
	for (size_t i = 0; i < sizeof STATE_FILES / sizeof STATE_FILES[0]; i++) {
		snprintf(path, sizeof path, "%s/%s", state, STATE_FILES[i]);
		if (lstat(path, &st) == 0 && S_ISREG(st.st_mode))
			restrict_one(path, &st);
	}
	snprintf(path, sizeof path, "%s/files", state);
	if (lstat(path, &st) == 0 && S_ISDIR(st.st_mode))
		nftw(path, restrict_entry, WALK_OPEN_FDS, FTW_PHYS);
	return restrict_failures;
}

int state_dir_open_store(const struct server_config *cfg, struct server *srv, struct store **store, char *msg,
			 size_t msg_size)
{
	char path[STATE_PATH_MAX];
	if (fs_make_dirs(cfg->state) != 0) {
		snprintf(msg, msg_size, "cannot create state directory '%s': %s", cfg->state, strerror(errno));
		return -1;
	}
	snprintf(path, sizeof path, "%s/poro.db", cfg->state);
	struct api_error err = { 0 };
	if (store_open(store, path, cfg, srv, &err) != API_OK) {
		snprintf(msg, msg_size, "%s", err.message);
		return -1;
	}
	return 0;
}

/* The pid the holder wrote into the lock file, or 0 when it cannot be read yet. */
static long lock_holder(int fd)
{
	for (int i = 0; i < LOCK_PID_TRIES; i++) {
		char text[32] = "";
		ssize_t n = pread(fd, text, sizeof text - 1, 0);
		long pid = n > 0 ? strtol(text, NULL, 10) : 0;
		if (pid > 0)
			return pid;
		/* the holder takes the lock before it writes its pid: give it a moment */
		struct timespec pause = { 0, LOCK_PID_WAIT_NS };
		nanosleep(&pause, NULL);
	}
	return 0;
}

int state_dir_lock(const char *state, char *msg, size_t msg_size)
{
	char path[STATE_PATH_MAX];
	snprintf(path, sizeof path, "%s/%s", state, STATE_DIR_LOCK_NAME);
	int fd = open(path, O_RDWR | O_CREAT | O_CLOEXEC, 0600);
	if (fd < 0) {
		snprintf(msg, msg_size, "cannot open the lock file '%s': %s", path, strerror(errno));
		return -1;
	}
	if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
		int e = errno;
		if (e == EWOULDBLOCK) {
			long pid = lock_holder(fd);
			if (pid > 0)
				snprintf(msg, msg_size, "state directory '%s' is in use by poro-server pid %ld", state, pid);
			else
				snprintf(msg, msg_size, "state directory '%s' is in use by another poro-server", state);
		} else {
			snprintf(msg, msg_size, "cannot lock '%s': %s", path, strerror(e));
		}
		close(fd);
		return -1;
	}
	char text[32];
	int n = snprintf(text, sizeof text, "%ld\n", (long)getpid());
	if (ftruncate(fd, 0) != 0 || pwrite(fd, text, (size_t)n, 0) != n) {
		/* the lock holds without the pid; only the second server's message loses it */
		log_say(LOG_PRIO_WARNING, "cannot write the pid into '%s': %s", path, strerror(errno));
	}
	return fd;
}

long long state_dir_free_bytes(const char *state)
{
	struct statvfs vfs;
	if (statvfs(state, &vfs) != 0)
		return -1;
	return (long long)vfs.f_bavail * (long long)vfs.f_frsize;
}

int state_dir_probe_files(const char *state, char *msg, size_t msg_size)
{
	static const char probe[] = "poro-server health probe\n";
	char path[STATE_PATH_MAX];
	snprintf(path, sizeof path, "%s/files/.healthz", state);
	int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
	if (fd < 0) {
		snprintf(msg, msg_size, "cannot create a file in files/: %s", strerror(errno));
		return -1;
	}
	int ok = write(fd, probe, sizeof probe - 1) == (ssize_t)(sizeof probe - 1);
	int e = errno;
	if (ok && fsync(fd) != 0) {
		ok = 0;
		e = errno;
	}
	close(fd);
	if (unlink(path) != 0 && ok) {
		ok = 0;
		e = errno;
	}
	if (!ok) {
		snprintf(msg, msg_size, "cannot write a file in files/: %s", strerror(e));
		return -1;
	}
	return 0;
}
