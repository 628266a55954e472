/*
 * fs.c - small file-system helpers (fs.h).
 */
#include "fs.h"

#include <errno.h>
#include <fcntl.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define FS_PATH_MAX 4096

/* Copies path into buf[FS_PATH_MAX]: 0, or -1 with ENAMETOOLONG. */
static int path_copy(char *buf, const char *path)
{
	size_t n = strlen(path);
	if (n >= FS_PATH_MAX) {
		errno = ENAMETOOLONG;
		return -1;
	}
	memcpy(buf, path, n + 1);
	return 0;
}

int fs_make_dirs(const char *path)
{
	char buf[FS_PATH_MAX];
	if (path_copy(buf, path) != 0)
		return -1;
	for (char *p = buf + 1; *p; p++) {
		if (*p != '/')
			continue;
		*p = '\0';
		if (mkdir(buf, 0755) != 0 && errno != EEXIST)
			return -1;
		*p = '/';
	}
	return mkdir(buf, 0755) != 0 && errno != EEXIST ? -1 : 0;
}

int fs_sync_parents(const char *path, int levels)
{
	char buf[FS_PATH_MAX];
	if (path_copy(buf, path) != 0)
		return -1;
	for (int i = 0; i < levels; i++) {
		char *slash = strrchr(buf, '/');
		if (!slash)
			return 0;
		*slash = '\0';
		int fd = open(slash == buf ? "/" : buf, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
		if (fd < 0)
			return -1;
		int rc = fsync(fd);
		int e = errno;
		close(fd);
		if (rc != 0) {
			errno = e;
			return -1;
		}
	}
	return 0;
}
