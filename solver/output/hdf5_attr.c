/* hdf5_attr.c - small HDF5 steps shared by the HDF5 files (see hdf5_attr.h). */
#include "hdf5_attr.h"

#include <stdlib.h>
#include <string.h>

int hdf5_attr_write(hid_t loc, const char *name, hid_t file_type, hid_t mem_type, const void *value)
{
	htri_t exists = H5Aexists(loc, name);
	if (exists < 0 || (exists > 0 && H5Adelete(loc, name) < 0))
		return -1;
	hid_t space = H5Screate(H5S_SCALAR);
	if (space < 0)
		return -1;
	hid_t a = H5Acreate2(loc, name, file_type, space, H5P_DEFAULT, H5P_DEFAULT);
	int rc = a < 0 || H5Awrite(a, mem_type, value) < 0 ? -1 : 0;
	if (a >= 0 && H5Aclose(a) < 0)
		rc = -1;
	H5Sclose(space);
	return rc;
}

int hdf5_attr_read(hid_t loc, const char *name, hid_t mem_type, void *value)
{
	hid_t a = H5Aopen(loc, name, H5P_DEFAULT);
	if (a < 0)
		return -1;
	int rc = H5Aread(a, mem_type, value) < 0 ? -1 : 0;
	return H5Aclose(a) < 0 ? -1 : rc;
}

hid_t hdf5_string_type(void)
{
	hid_t t = H5Tcopy(H5T_C_S1);
	if (t >= 0 && (H5Tset_size(t, H5T_VARIABLE) < 0 || H5Tset_cset(t, H5T_CSET_UTF8) < 0)) {
		H5Tclose(t);
		return -1;
	}
	return t;
}

int hdf5_attr_write_string(hid_t loc, const char *name, const char *value)
{
	hid_t t = hdf5_string_type();
	int rc = t < 0 ? -1 : hdf5_attr_write(loc, name, t, t, &value);
	if (t >= 0)
		H5Tclose(t);
	return rc;
}

char *hdf5_attr_read_string(hid_t loc, const char *name)
{
	hid_t t = hdf5_string_type();
	char *value = NULL, *copy = NULL;
	if (t >= 0 && hdf5_attr_read(loc, name, t, &value) == 0 && value) {
		copy = malloc(strlen(value) + 1);
		if (copy)
			strcpy(copy, value);
		H5free_memory(value);
	}
	if (t >= 0)
		H5Tclose(t);
	return copy;
}

int hdf5_group_create(hid_t loc, const char *path, size_t heap_hint)
{
	hid_t gcpl = H5Pcreate(H5P_GROUP_CREATE);
	if (gcpl < 0)
		return -1;
	int rc = heap_hint && H5Pset_local_heap_size_hint(gcpl, heap_hint) < 0 ? -1 : 0;
	hid_t g = rc ? -1 : H5Gcreate2(loc, path, H5P_DEFAULT, gcpl, H5P_DEFAULT);
	if (g < 0 || H5Gclose(g) < 0)
		rc = -1;
	H5Pclose(gcpl);
	return rc;
}

/* The dataset creation properties of hdf5_dataset_write_compressed: chunks of whole rows, at most
 * HDF5_CHUNK_BYTES each, shuffled and deflated at `level`. */
static hid_t compressed_layout(hsize_t n, hsize_t width, size_t element, int level)
{
	hsize_t rows = HDF5_CHUNK_BYTES / (width * element);
	hsize_t chunk[2] = {rows < 1 ? 1 : rows < n ? rows : n, width};
	hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
	if (dcpl >= 0 && (H5Pset_chunk(dcpl, width == 1 ? 1 : 2, chunk) < 0 || H5Pset_shuffle(dcpl) < 0 ||
			  H5Pset_deflate(dcpl, (unsigned)level) < 0)) {
		H5Pclose(dcpl);
		return -1;
	}
	return dcpl;
}

/* A dataset of n rows x width with creation properties dcpl (H5P_DEFAULT: contiguous). */
static int dataset_write(hid_t loc, const char *path, hsize_t n, hsize_t width, hid_t file_type, hid_t mem_type,
			 const void *data, hid_t dcpl)
{
	hsize_t dims[2] = {n, width};
	hid_t space = H5Screate_simple(width == 1 ? 1 : 2, dims, NULL);
	if (space < 0)
		return -1;
	hid_t ds = H5Dcreate2(loc, path, file_type, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
	int rc = ds < 0 || (n > 0 && H5Dwrite(ds, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0) ? -1 : 0;
	if (ds >= 0 && H5Dclose(ds) < 0)
		rc = -1;
	H5Sclose(space);
	return rc;
}

int hdf5_dataset_write(hid_t loc, const char *path, hsize_t n, hsize_t width, hid_t file_type, hid_t mem_type,
		       const void *data)
{
	return dataset_write(loc, path, n, width, file_type, mem_type, data, H5P_DEFAULT);
}

int hdf5_dataset_write_compressed(hid_t loc, const char *path, hsize_t n, hsize_t width, hid_t file_type,
				  hid_t mem_type, const void *data, int level)
{
	if (n == 0 || level <= 0)   /* a chunk cannot be empty; level 0 asks for none */
		return hdf5_dataset_write(loc, path, n, width, file_type, mem_type, data);
	hid_t dcpl = compressed_layout(n, width, H5Tget_size(file_type), level);
	if (dcpl < 0)
		return -1;
	int rc = dataset_write(loc, path, n, width, file_type, mem_type, data, dcpl);
	H5Pclose(dcpl);
	return rc;
}
