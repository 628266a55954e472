/*
 * frames_export.h - the frames of a result.h5 in the compact form the dashboard draws
 * (docs/web.md "Frames"): `frames.bin`, every frame's points as little-endian 32-bit floats, and
 * `frames.json`, its index. The job service's worker writes both with `poro-solve probes ...
 * --frames DIR` in the child that already reads the probes, and uploads them; poro-server serves
 * the index as GET /v1/jobs/{id}/frames and one frame's bytes as GET /v1/jobs/{id}/frames/{frame}
 * without ever opening a result file.
 *
 * frames.bin is the frames' blocks one after the other, in frame order. A frame's block holds, for
 * each point set of the index's "sets" in order ("soil", then "water" in double point), each of
 * that set's arrays in order, count floats each (count = the frame's "counts"[set]). Arrays:
 *   x, y                    m, current position
 *   pore_pressure           Pa, positive in compression (water in double point, soil in single point)
 *   mean_effective_stress   Pa, p' = -(s'xx + s'yy + s'zz) / 3, positive in compression (soil)
 *   plastic_strain          1, accumulated deviatoric plastic strain (soil)
 *   displacement            m, |x - x0| (soil, water)
 * A value that is not finite is stored as NaN. The layout only grows at its end as frames are
 * added, so the offsets of an older index stay valid in a newer frames.bin of the same run.
 *
 * frames.json: {"format": "poro-frames/1", "job", "attempt", "bin_bytes", "grid": {"origin",
 * "extent", "cell_size"}, "sets": {set: [array...]}, "fields": [{"name", "label", "unit",
 * "sets": [...], "range": [min, max]}], "frames": [{"index", "time", "offset", "length",
 * "counts": {set: N}, "ranges": {field: [min, max]}}], "report": {"time", "runout", "toe_x",
 * "crest_settlement"} or null}. Ranges are over the finite values (null when there is none);
 * "report" holds report.h's rows for cases report_open() accepts (polygon bodies: slopes,
 * landslides), else null.
 *
 * Errors: as results_read.h (PORO_EIO for what cannot be read or written, naming it; PORO_EINVAL
 * for a file that is not a result; PORO_ENOMEM). Nothing is printed; on failure the two files are
 * removed.
 */
#ifndef PORO_FRAMES_EXPORT_H
#define PORO_FRAMES_EXPORT_H

#include "error.h"

#define FRAMES_EXPORT_FORMAT "poro-frames/1"
#define FRAMES_EXPORT_BIN "frames.bin"
#define FRAMES_EXPORT_INDEX "frames.json"

/* Writes DIR/frames.bin and DIR/frames.json for result file path; job and attempt are what the
 * index names (the service's), any whole numbers for a file of one's own. */
enum poro_status frames_export(const char *path, const char *dir, long long job, long long attempt,
			       struct poro_error *err);

#endif
