/*
 * output_xdmf.h - private to the results writer (output.c): the names both halves of it agree on,
 * and result.xdmf, the XML index that lets ParaView open result.h5.
 *
 * output.c writes the heavy data into result.h5; after every frame is flushed it adds the frame to
 * an xdmf_index and calls xdmf_index_write(), which rewrites result.xdmf atomically (temporary
 * file, fsync, rename), so the index never names a frame that is not yet flushed to result.h5.
 * The dataset names written here must match the field table in output.c; schemas/results.md is
 * the user's description of both.
 */
#ifndef PORO_OUTPUT_XDMF_H
#define PORO_OUTPUT_XDMF_H

#include <stddef.h>

#include "error.h"

#define OUTPUT_H5_NAME "result.h5"
#define OUTPUT_XDMF_NAME "result.xdmf"
#define OUTPUT_XDMF_TMP_NAME ".result.xdmf.tmp"
#define OUTPUT_FRAME_FORMAT "/frames/%06ld"  /* frame group of a sequence number */
#define OUTPUT_POINTS_FORMAT "/xdmf/points_%ld" /* 0 .. n-1, the Polyvertex connectivity for n points */

/* One completed frame as result.xdmf lists it. */
struct xdmf_frame {
	long index;       /* sequence number: the group is OUTPUT_FRAME_FORMAT of it */
	double time;      /* s */
	long soil_n;      /* points in soil/ */
	long water_n;     /* points in water/; -1 when the frame has no water group (single point) */
};

/* One point set's grids of the frames listed so far, formatted. */
struct xdmf_series {
	char *text;       /* [cap] the frames' <Grid> elements, not NUL terminated */
	size_t len, cap;
};

/* The XML of the frames listed so far, kept so that a rewrite is one write, not a reformatting of
 * every frame (which would make a long run's output quadratic in formatting work). */
struct xdmf_index {
	struct xdmf_series soil, water;
	size_t frames;    /* frames listed */
};

/* Appends a frame to the index (in memory only). Returns PORO_ENOMEM on failure, leaving the
 * index as it was. */
enum poro_status xdmf_index_add(struct xdmf_index *x, const struct xdmf_frame *frame, struct poro_error *err);

/* Rewrites DIR/result.xdmf to list the index's frames: writes DIR/.result.xdmf.tmp, fsyncs it and
 * renames it over result.xdmf. Returns PORO_EIO, naming the file, on failure. */
enum poro_status xdmf_index_write(const struct xdmf_index *x, const char *dir, struct poro_error *err);

/* Frees the text; the index is empty afterwards. */
void xdmf_index_release(struct xdmf_index *x);

#endif
