/* hdf5_reason.c - keeps HDF5's reason for the first failure (see hdf5_reason.h). */
#include "hdf5_reason.h"

#include <stdio.h>
#include <string.h>

char hdf5_reason[HDF5_REASON_MAX];

/* The innermost description, shortened: a system call's failure becomes its strerror text, which
 * HDF5 embeds as "error message = '...'" among a timestamp, addresses and sizes. */
static herr_t innermost(unsigned n, const H5E_error2_t *e, void *data)
{
	if (n != 0 || !e->desc)
		return 0;
	const char *key = "error message = '";
	const char *from = strstr(e->desc, key);
	from = from ? from + strlen(key) : e->desc;
	size_t len = strcspn(from, from == e->desc ? "\n" : "'\n");
	if (len >= HDF5_REASON_MAX)
		len = HDF5_REASON_MAX - 1;
	snprintf(data, HDF5_REASON_MAX, "%.*s", (int)len, from);
	return 0;
}

herr_t hdf5_record_reason(hid_t stack, void *unused)
{
	(void)unused;
	if (!hdf5_reason[0])
		H5Ewalk2(stack, H5E_WALK_UPWARD, innermost, hdf5_reason);
	return 0;
}
