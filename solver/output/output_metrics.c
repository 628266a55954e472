/*
 * output_metrics.c - a run's figures as files (metrics.h): DIR/metrics.json, written to a
 * temporary name and renamed so a reader never sees half a document, and the /metrics group of
 * DIR/result.h5 (schemas/results.md), added to the finished file and replaced if present:
 *   /metrics                 attributes schema ("poro-metrics/1"), kind, status ("succeeded" or
 *                            "failed"), error, solver_version, at_time, and the machine's
 *                            cpu_model, cores, memory_mb, kernel, compiler, blas, host
 *   /metrics/<figure>        scalar double (NaN where undefined), attributes unit and class
 */
#include "metrics.h"

#include <errno.h>
#include <hdf5.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "hdf5_attr.h"
#include "hdf5_reason.h"
#include "json_text.h"

static void json_member(FILE *f, const char *indent, const char *key, const char *value, const char *end)
{
	fprintf(f, "%s", indent);
	json_text_string(f, key, 0);
	fputs(": ", f);
	if (value)
		json_text_string(f, value, 0);
	else
		fputs("null", f);
	fputs(end, f);
}

static void write_machine(FILE *f, const struct machine *mc)
{
	fputs("  \"machine\": {\n", f);
	json_member(f, "    ", "cpu_model", mc->cpu_model, ",\n");
	fprintf(f, "    \"cores\": %d,\n    \"memory_mb\": %ld,\n", mc->cores, mc->memory_mb);
	json_member(f, "    ", "kernel", mc->kernel, ",\n");
	json_member(f, "    ", "compiler", mc->compiler, ",\n");
	json_member(f, "    ", "blas", mc->blas, ",\n");
	json_member(f, "    ", "host", mc->host, "\n");
	fputs("  },\n", f);
}

static void write_json(FILE *f, const struct metrics *m)
{
	fprintf(f, "{\n  \"schema\": \"%s\",\n", METRICS_SCHEMA);
	json_member(f, "  ", "kind", m->kind, ",\n");
	json_member(f, "  ", "title", m->title, ",\n");
	json_member(f, "  ", "status", m->succeeded ? "succeeded" : "failed", ",\n");
	json_member(f, "  ", "error", m->error[0] ? m->error : NULL, ",\n");
	json_member(f, "  ", "solver_version", m->solver_version, ",\n");
	fputs("  \"at_time\": ", f);
	json_text_number(f, m->at_time);
	fputs(",\n", f);
	write_machine(f, &m->machine);
	fputs("  \"figures\": {", f);
	int first = 1;
	for (int k = 0; k < FIGURE_COUNT; k++) {
		if (!(m->present & 1u << k))
			continue;
		fprintf(f, "%s\n    \"%s\": {\"value\": ", first ? "" : ",", figure_name(k));
		json_text_number(f, m->value[k]);
		fprintf(f, ", \"unit\": \"%s\", \"class\": \"%s\"}", figure_unit(k), figure_class_name(figure_class(k)));
		first = 0;
	}
	fputs("\n  }\n}\n", f);
}

static enum poro_status write_json_file(const struct metrics *m, const char *dir, struct poro_error *err)
{
	char path[4200], tmp[4300];
	snprintf(path, sizeof path, "%s/%s", dir, METRICS_FILE);
	snprintf(tmp, sizeof tmp, "%s.tmp", path);
	FILE *f = fopen(tmp, "w");
	if (!f)
		return poro_error_set(err, PORO_EIO, "cannot create '%s': %s", tmp, strerror(errno));
	write_json(f, m);
	int failed = fflush(f) != 0 || ferror(f) || fsync(fileno(f)) != 0;
	failed |= fclose(f) != 0;
	if (failed || rename(tmp, path) != 0) {
		int e = errno;
		remove(tmp);
		return poro_error_set(err, PORO_EIO, "cannot write '%s': %s", path, strerror(e));
	}
	return PORO_OK;
}

static int write_group(hid_t file, const struct metrics *m)
{
	if (H5Lexists(file, "metrics", H5P_DEFAULT) > 0 && H5Ldelete(file, "metrics", H5P_DEFAULT) < 0)
		return -1;
	hid_t g = H5Gcreate2(file, "metrics", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
	if (g < 0)
		return -1;
	const struct machine *mc = &m->machine;
	int cores = mc->cores;
	long long memory = mc->memory_mb;
	int rc = hdf5_attr_write_string(g, "schema", METRICS_SCHEMA) | hdf5_attr_write_string(g, "kind", m->kind) |
		 hdf5_attr_write_string(g, "status", m->succeeded ? "succeeded" : "failed") |
		 hdf5_attr_write_string(g, "error", m->error) |
		 hdf5_attr_write_string(g, "solver_version", m->solver_version) |
		 hdf5_attr_write(g, "at_time", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &m->at_time) |
		 hdf5_attr_write_string(g, "cpu_model", mc->cpu_model) |
		 hdf5_attr_write(g, "cores", H5T_STD_I32LE, H5T_NATIVE_INT, &cores) |
		 hdf5_attr_write(g, "memory_mb", H5T_STD_I64LE, H5T_NATIVE_LLONG, &memory) |
		 hdf5_attr_write_string(g, "kernel", mc->kernel) | hdf5_attr_write_string(g, "compiler", mc->compiler) |
		 hdf5_attr_write_string(g, "blas", mc->blas) | hdf5_attr_write_string(g, "host", mc->host);
	for (int k = 0; k < FIGURE_COUNT && rc >= 0; k++) {
		if (!(m->present & 1u << k))
			continue;
		rc = hdf5_dataset_write(g, figure_name(k), 1, 1, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &m->value[k]);
		hid_t d = rc >= 0 ? H5Dopen2(g, figure_name(k), H5P_DEFAULT) : -1;
		if (d < 0)
			rc = -1;
		else
			rc = hdf5_attr_write_string(d, "unit", figure_unit(k)) |
			     hdf5_attr_write_string(d, "class", figure_class_name(figure_class(k)));
		if (d >= 0)
			H5Dclose(d);
	}
	H5Gclose(g);
	return rc < 0 ? -1 : 0;
}

/* Adds /metrics to DIR/result.h5 when the file exists. */
static enum poro_status write_hdf5(const struct metrics *m, const char *dir, struct poro_error *err)
{
	char path[4200];
	snprintf(path, sizeof path, "%s/result.h5", dir);
	if (access(path, F_OK) != 0)
		return PORO_OK;
	H5Eset_auto2(H5E_DEFAULT, hdf5_record_reason, NULL);
	hdf5_reason[0] = '\0';
	hid_t file = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT);
	int rc = file < 0 ? -1 : write_group(file, m);
	if (file >= 0 && H5Fclose(file) < 0)
		rc = -1;
	if (rc < 0)
		return poro_error_set(err, PORO_EIO, "cannot write the /metrics group of '%s'%s%s", path,
				      hdf5_reason[0] ? ": " : "", hdf5_reason);
	return PORO_OK;
}

enum poro_status metrics_write(const struct metrics *m, const char *dir, struct poro_error *err)
{
	enum poro_status st = write_hdf5(m, dir, err);
	return st ? st : write_json_file(m, dir, err);
}
