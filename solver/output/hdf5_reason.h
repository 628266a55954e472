/*
 * hdf5_reason.h - HDF5's reason for a failure, for error messages (private to the HDF5 files:
 * output.c, checkpoint.c and results_read.c, the only ones that include hdf5.h).
 *
 * HDF5 prints its error stack by default and clears it in the cleanup calls that follow a failure,
 * before the failure can be reported. hdf5_record_reason is installed with H5Eset_auto2 in place
 * of the printer: it keeps the innermost (most specific) description of the first failure since
 * hdf5_reason was last cleared, shortened to the strerror text for a failed system call.
 */
#ifndef PORO_HDF5_REASON_H
#define PORO_HDF5_REASON_H

#include <hdf5.h>

#define HDF5_REASON_MAX 256

/* The recorded reason, "" if none since the last clear. */
extern char hdf5_reason[HDF5_REASON_MAX];

/* An H5E_auto2_t: records the reason and prints nothing. */
herr_t hdf5_record_reason(hid_t stack, void *unused);

#endif
