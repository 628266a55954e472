/*
 * output_xdmf.c - result.xdmf, the XDMF 3 index through which ParaView opens result.h5 (see
 * output_xdmf.h; the layout for users is schemas/results.md).
 *
 * Shape of the file: one Temporal collection per point set, "soil" and, in double point, "water";
 * each holds one Uniform grid per frame, named after its set and carrying the frame's <Time>. So
 * ParaView shows one block per set whose name is the same at every frame: with one Temporal
 * collection of Spatial frames (the layout before) its readers named the blocks of later frames
 * "soil[1]", "soil[2]", ..., and a block selection made at frame 0 came up empty after it. A grid
 * is a Polyvertex topology (n one-point cells, connectivity /xdmf/points_<n>), XY geometry from
 * <set>/x, and point attributes read straight from result.h5.
 *
 * Times are written with 15 significant digits: the frame at step k has t = k dt, which in binary
 * is often a hair above its decimal value (9810 x 1e-4 = 0.9810000000000001), and ParaView, asked
 * for t = 0.981, then showed the frame before. 15 digits give back the decimal time of any
 * frame whose time has fewer, and result.h5 keeps the exact double.
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
	int water_carried;    /* in double point the water points carry it, and soil/ has none */
};

static const struct xdmf_attribute xdmf_attributes[] = {
	{"pore_pressure", "Scalar", "pore_pressure", 1, 0, 1},
	{"porosity", "Scalar", "porosity", 1, 0, 0},
	{"displacement", "Vector", "displacement3", 3, 0, 0},
	{"v", "Vector", "v3", 3, 0, 0},
	{"stress", "Tensor", "stress9", 9, 1, 0},
	{"plastic_strain", "Scalar", "plastic_strain", 1, 1, 0},
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

/* One set's grid at one frame: double_point leaves out of the soil grid the attributes the water
 * points carry (output.c writes no soil/pore_pressure in double point). */
static void put_grid(FILE *f, long index, const char *set, long n, double time, int double_point)
{
	char set_path[64];
	snprintf(set_path, sizeof set_path, OUTPUT_FRAME_FORMAT "/%s", index, set);
	fprintf(f, "        <Grid Name=\"%s\" GridType=\"Uniform\">\n", set);
	fprintf(f, "          <Time Value=\"%.15g\"/>\n", time);
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
		if ((soil || !xdmf_attributes[i].soil_only) && !(soil && double_point && xdmf_attributes[i].water_carried))
			put_attribute(f, set_path, &xdmf_attributes[i], n);
	fprintf(f, "        </Grid>\n");
}

/* Formats one set's grid of a frame into *text (malloc'ed), or NULL when out of memory. */
static char *format_grid(const struct xdmf_frame *fr, const char *set, long n, size_t *len)
{
	char *text = NULL;
	FILE *m = open_memstream(&text, len);
	if (!m)
		return NULL;
	put_grid(m, fr->index, set, n, fr->time, fr->water_n >= 0);
	if (fclose(m) != 0) {
		free(text);
		return NULL;
	}
	return text;
}

/* Appends len bytes to a series' text; -1 when out of memory (the series is left as it was). */
static int series_append(struct xdmf_series *x, const char *text, size_t len)
{
	if (x->len + len > x->cap) {
		size_t cap = x->cap ? 2 * x->cap : 64 * 1024;
		while (cap < x->len + len)
			cap *= 2;
		char *grown = realloc(x->text, cap);
		if (!grown)
			return -1;
		x->text = grown;
		x->cap = cap;
	}
	memcpy(x->text + x->len, text, len);
	x->len += len;
	return 0;
}

/* A set without points at a frame is left out of its series there: ParaView has no use for an
 * empty grid (a water series whose points have all drained ends at its last frame with water). */
enum poro_status xdmf_index_add(struct xdmf_index *x, const struct xdmf_frame *frame, struct poro_error *err)
{
	size_t soil_len = 0, water_len = 0;
	char *soil = frame->soil_n > 0 ? format_grid(frame, "soil", frame->soil_n, &soil_len) : NULL;
	char *water = frame->water_n > 0 ? format_grid(frame, "water", frame->water_n, &water_len) : NULL;
	int ok = (soil || frame->soil_n <= 0) && (water || frame->water_n <= 0);
	const size_t soil_before = x->soil.len;
	if (ok && soil)
		ok = series_append(&x->soil, soil, soil_len) == 0;
	if (ok && water && series_append(&x->water, water, water_len) != 0) {
		x->soil.len = soil_before;   /* all of the frame or none of it */
		ok = 0;
	}
	free(soil);
	free(water);
	if (!ok)
		return poro_error_set(err, PORO_ENOMEM, "cannot allocate the xdmf index");
	x->frames++;
	return PORO_OK;
}

/* The file around the series. */
static const char xdmf_head[] = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
				"<Xdmf Version=\"3.0\">\n  <Domain>\n";
static const char xdmf_tail[] = "  </Domain>\n</Xdmf>\n";

static void put_series(FILE *f, const char *set, const struct xdmf_series *x)
{
	if (!x->len)
		return;
	fprintf(f, "    <Grid Name=\"%s\" GridType=\"Collection\" CollectionType=\"Temporal\">\n", set);
	fwrite(x->text, 1, x->len, f);
	fputs("    </Grid>\n", f);
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
	put_series(f, "soil", &x->soil);
	put_series(f, "water", &x->water);
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
	free(x->soil.text);
	free(x->water.text);
	*x = (struct xdmf_index){0};
}
