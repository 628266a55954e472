/*
 * hdf5_attr.h - the small HDF5 steps shared by the files that write and read HDF5 (output.c,
 * checkpoint.c): scalar attributes, variable-length UTF-8 strings, groups and whole datasets.
 * Each returns < 0 (or NULL) on failure with HDF5's reason left in hdf5_reason (hdf5_reason.h)
 * when the caller has installed hdf5_record_reason.
 */
#ifndef PORO_HDF5_ATTR_H
#define PORO_HDF5_ATTR_H

#include <hdf5.h>

/* Writes a scalar attribute, replacing one of the same name. */
int hdf5_attr_write(hid_t loc, const char *name, hid_t file_type, hid_t mem_type, const void *value);
/* Reads a scalar attribute into value (of mem_type). */
int hdf5_attr_read(hid_t loc, const char *name, hid_t mem_type, void *value);

/* The variable-length UTF-8 string type; the caller closes it with H5Tclose. */
hid_t hdf5_string_type(void);
int hdf5_attr_write_string(hid_t loc, const char *name, const char *value);
/* A string attribute as a malloc'ed copy the caller frees; NULL on failure. */
char *hdf5_attr_read_string(hid_t loc, const char *name);

/* Creates a group (heap_hint > 0: the local heap size hint for its member names, bytes). */
int hdf5_group_create(hid_t loc, const char *path, size_t heap_hint);

/* A contiguous dataset of n rows and width columns (width 1: 1-D) of file_type, written from data
 * in mem_type. */
int hdf5_dataset_write(hid_t loc, const char *path, hsize_t n, hsize_t width, hid_t file_type, hid_t mem_type,
		       const void *data);

/* The same, stored in chunks of whole rows of at most HDF5_CHUNK_BYTES, byte-shuffled and
 * deflated (gzip) at level 1-9; every HDF5 reader (h5py, ParaView, MATLAB) decodes it with the
 * zlib filter HDF5 is built with. level 0 or n = 0 writes a contiguous dataset. */
#define HDF5_CHUNK_BYTES (1 << 20)
int hdf5_dataset_write_compressed(hid_t loc, const char *path, hsize_t n, hsize_t width, hid_t file_type,
				  hid_t mem_type, const void *data, int level);

#endif
