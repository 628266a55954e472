/*
 * output_xdmf.c - result.xdmf, the XDMF 3 index through which ParaView opens result.h5 (see
 * output_xdmf.h; the layout for users is schemas/results.md).
 *
 * Shape of the file: one Temporal collection; each frame is a Spatial collection carrying the
 * frame's <Time> and one Uniform grid per point set, "soil" and, in double point, "water". A grid
 * is a Polyvertex topology (n one-point cells, connectivity /xdmf/points_<n>), XY geometry from
 * <set>/x, and point attributes read straight from result.h5.
 *
 * ParaView's XDMF 3 reader makes an attribute a vector only when it has 3 components, and it does
 * not read HyperSlab data items, so the grids read the copies that output.c writes for this
 * purpose: displacement3 and v3 (N x 3, z = 0) as Vectors, and stress9 (N x 9, the full 3 x 3
 * tensor row-major) as a Tensor named "stress". Not a Tensor6: ParaView 5.11's XDMF 3 reader takes
 * its components in VTK's order (xx, yy, zz, xy, yz, xz) and its XDMF 2 reader in upper-triangle
 * order (xx, xy, xz, yy, yz, zz), so a 6-component stress would read differently in each.
 *
 * The whole index is rewritten after every frame (about 3.5 kB per double-point frame), into a
 * temporary file that is fsync'ed and renamed over the old one: a reader sees the old index or
 * the new one, never a torn one, and never a frame that is not yet flushed into result.h5. Each
 * frame's XML is formatted once and kept in memory, so a rewrite costs one write of the file.
 */
#include "output_xdmf.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* A point attribute as ParaView shows it, read from a whole dataset of the set's group. */
struct xdmf_attribute {
	const char *name;     /* name shown in ParaView */
	const char *type;     /* XDMF AttributeType */
	const char *dataset;  /* dataset in the set's group */
	int width;            /* columns of the dataset (1: a 1-D dataset) */
	int soil_only;        /* skeleton fields exist in soil/ only */
};

static const struct xdmf_attribute xdmf_attributes[] = {
	{"pore_pressure", "Scalar", "pore_pressure", 1, 0},
	{"porosity", "Scalar", "porosity", 1, 0},
	{"displacement", "Vector", "displacement3", 3, 0},
	{"v", "Vector", "v3", 3, 0},
	{"stress", "Tensor", "stress9", 9, 1},
	{"plastic_strain", "Scalar", "plastic_strain", 1, 1},
};

/* An HDF5 data item: "n" or "n width" doubles of a dataset in result.h5. */
static void put_item(FILE *f, const char *path, long n, int width)
{
	if (width == 1)
		fprintf(f, "            <DataItem Dimensions=\"%ld\"", n);
	else
		fprintf(f, "            <DataItem Dimensions=\"%ld %d\"", n, width);
	fprintf(f, " NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">" OUTPUT_H5_NAME ":%s</DataItem>\n",
		path);
}

static void put_attribute(FILE *f, const char *set_path, const struct xdmf_attribute *a, long n)
{
	char path[128];
	snprintf(path, sizeof path, "%s/%s", set_path, a->dataset);
	fprintf(f, "          <Attribute Name=\"%s\" AttributeType=\"%s\" Center=\"Node\">\n", a->name,
		a->type);
	put_item(f, path, n, a->width);
	fprintf(f, "          </Attribute>\n");
}

static void put_grid(FILE *f, long index, const char *set, long n)
{
	char set_path[64];
	snprintf(set_path, sizeof set_path, OUTPUT_FRAME_FORMAT "/%s", index, set);
	fprintf(f, "        <Grid Name=\"%s\" GridType=\"Uniform\">\n", set);
	fprintf(f, "          <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"%ld\""
		   " NodesPerElement=\"1\">\n", n);
	fprintf(f, "            <DataItem Dimensions=\"%ld\" NumberType=\"Int\" Precision=\"4\" Format=\"HDF\">"
		   OUTPUT_H5_NAME ":" OUTPUT_POINTS_FORMAT "</DataItem>\n", n, n);
	fprintf(f, "          </Topology>\n");
	fprintf(f, "          <Geometry GeometryType=\"XY\">\n");
	char x_path[80];
	snprintf(x_path, sizeof x_path, "%s/x", set_path);
	put_item(f, x_path, n, 2);
	fprintf(f, "          </Geometry>\n");
	int soil = strcmp(set, "soil") == 0;
	for (size_t i = 0; i < sizeof xdmf_attributes / sizeof xdmf_attributes[0]; i++)
		if (soil || !xdmf_attributes[i].soil_only)
			put_attribute(f, set_path, &xdmf_attributes[i], n);
	fprintf(f, "        </Grid>\n");
}

/* A set without points is left out of the index: ParaView has no use for an empty grid. */
static void put_frame(FILE *f, const struct xdmf_frame *fr)
{
	fprintf(f, "      <Grid Name=\"%06ld\" GridType=\"Collection\" CollectionType=\"Spatial\">\n",
		fr->index);
	fprintf(f, "        <Time Value=\"%.17g\"/>\n", fr->time);
	if (fr->soil_n > 0)
		put_grid(f, fr->index, "soil", fr->soil_n);
	if (fr->water_n > 0)
		put_grid(f, fr->index, "water", fr->water_n);
	fprintf(f, "      </Grid>\n");
}

/* The file around the frames. */
static const char xdmf_head[] =
	"<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
	"<Xdmf Version=\"3.0\">\n  <Domain>\n"
	"    <Grid Name=\"frames\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
static const char xdmf_tail[] = "    </Grid>\n  </Domain>\n</Xdmf>\n";

enum poro_status xdmf_index_add(struct xdmf_index *x, const struct xdmf_frame *frame, struct poro_error *err)
{
	char *text = NULL;
	size_t len = 0;
	FILE *m = open_memstream(&text, &len);
	if (m) {
		put_frame(m, frame);
		if (fclose(m) != 0) {
			free(text);
			text = NULL;
		}
	}
	if (text && x->len + len > x->cap) {
		size_t cap = x->cap ? 2 * x->cap : 64 * 1024;
		while (cap < x->len + len)
			cap *= 2;
		char *grown = realloc(x->text, cap);
		if (grown) {
			x->text = grown;
			x->cap = cap;
		}
	}
	if (!text || x->len + len > x->cap) {
		free(text);
		return poro_error_set(err, PORO_ENOMEM, "cannot allocate the xdmf index");
	}
	memcpy(x->text + x->len, text, len);
	x->len += len;
	x->frames++;
	free(text);
	return PORO_OK;
}

static char *join(const char *dir, const char *name)
{
	size_t len = strlen(dir) + 1 + strlen(name) + 1;
	char *path = malloc(len);
	if (path)
		snprintf(path, len, "%s/%s", dir, name);
	return path;
}

enum poro_status xdmf_index_write(const struct xdmf_index *x, const char *dir, struct poro_error *err)
{
	char *tmp = join(dir, OUTPUT_XDMF_TMP_NAME);
	char *path = join(dir, OUTPUT_XDMF_NAME);
	enum poro_status st = PORO_OK;
	if (!tmp || !path) {
		st = poro_error_set(err, PORO_ENOMEM, "cannot allocate the path of '%s'", OUTPUT_XDMF_NAME);
		goto out;
	}
	FILE *f = fopen(tmp, "w");
	if (!f) {
		st = poro_error_set(err, PORO_EIO, "cannot create '%s': %s", tmp, strerror(errno));
		goto out;
	}
	fputs(xdmf_head, f);
	if (x->len)
		fwrite(x->text, 1, x->len, f);
	fputs(xdmf_tail, f);
	/* fflush + fsync before rename: the new name must never point at data still in flight */
	int failed = ferror(f) || fflush(f) != 0 || fsync(fileno(f)) != 0;
	int saved = errno;
	if (fclose(f) != 0 && !failed) {
		failed = 1;
		saved = errno;
	}
	if (failed) {
		st = poro_error_set(err, PORO_EIO, "cannot write '%s': %s", tmp, strerror(saved));
		remove(tmp);
		goto out;
	}
	if (rename(tmp, path) != 0) {
		st = poro_error_set(err, PORO_EIO, "cannot rename '%s' to '%s': %s", tmp, path,
				    strerror(errno));
		remove(tmp);
	}
out:
	free(tmp);
	free(path);
	return st;
}

void xdmf_index_release(struct xdmf_index *x)
{
	free(x->text);
	*x = (struct xdmf_index){0};
}
