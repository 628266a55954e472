/*
 * fs_test.c - common/fs.c: fs_make_dirs makes every missing level and accepts what exists;
 * fs_sync_parents fsyncs the directories above a path, stops at the root, and reports a missing
 * directory (ENOENT) and an overlong path (ENAMETOOLONG) without touching anything.
 * (That a file below such directories survives a power loss is tests/fault/power_loss_test.sh.)
 */
#include "../harness.h"
#include "fs.h"

#include <errno.h>
#include <sys/stat.h>
#include <unistd.h>

static int is_dir(const char *path)
{
	struct stat st;
	return stat(path, &st) == 0 && S_ISDIR(st.st_mode);
}

int main(void)
{
	char *root = harness_temp_dir("fs_test");
	if (!root) {
		printf("FAIL fs_test_temp_dir: cannot make a directory in /tmp\n");
		return 1;
	}
	char deep[512], mid[512], top[512];
	snprintf(top, sizeof top, "%s/files", root);
	snprintf(mid, sizeof mid, "%s/files/17", root);
	snprintf(deep, sizeof deep, "%s/files/17/3", root);
	CHECK(fs_make_dirs(deep) == 0 && is_dir(deep), "make_dirs_makes_every_level", "errno %d", errno);
	CHECK(fs_make_dirs(deep) == 0, "make_dirs_accepts_existing", "errno %d", errno);
	CHECK(fs_sync_parents(deep, 2) == 0, "sync_parents_two_levels", "errno %d", errno);
	CHECK(fs_sync_parents(deep, 64) == 0, "sync_parents_stops_at_the_root", "errno %d", errno);
	char missing[600];
	snprintf(missing, sizeof missing, "%s/gone/17/3", root);
	errno = 0;
	CHECK(fs_sync_parents(missing, 2) == -1 && errno == ENOENT, "sync_parents_missing_directory_is_enoent",
	      "errno %d", errno);
	char longer[5000];
	memset(longer, 'a', sizeof longer - 1);
	longer[0] = '/';
	longer[sizeof longer - 1] = '\0';
	errno = 0;
	CHECK(fs_sync_parents(longer, 1) == -1 && errno == ENAMETOOLONG, "sync_parents_overlong_path",
	      "errno %d", errno);
	rmdir(deep);
	rmdir(mid);
	rmdir(top);
	rmdir(root);
	HARNESS_EXIT();
}
