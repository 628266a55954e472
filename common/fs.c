/*
 * fs.c - small file-system helpers (fs.h).
 */
#include "fs.h"

#include <errno.h>
#include <string.h>
#include <sys/stat.h>

#define FS_PATH_MAX 4096

int fs_make_dirs(const char *path)
{
	char buf[FS_PATH_MAX];
	size_t n = strlen(path);
	if (n >= sizeof buf) {
		errno = ENAMETOOLONG;
		return -1;
	}
	memcpy(buf, path, n + 1);
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
