/*
 * file_sweep.h - removing files of the artifact store (STATE/files, files.c) that nothing owns:
 * the temporary files of uploads the server did not see end, and the directories of deleted jobs.
 */
#ifndef PORO_FILE_SWEEP_H
#define PORO_FILE_SWEEP_H

struct store;

struct sweep_counts {
	long long tmp_files, tmp_bytes;        /* ".tmp-*" files of interrupted uploads removed */
	long long job_dirs, job_bytes;         /* directories of jobs no longer in the database removed */
	long long kept_restored, kept_dropped; /* old versions of unfinished replacements put back, removed */
};

/* At start-up, before any request: removes every ".tmp-*" file in STATE/files/<job>/<attempt>/,
 * settles every old version kept there by an unfinished replacement (file_replace.h: put back
 * when its row still names it, else removed), and removes the directory of every job that store
 * does not hold. Walks exactly those two levels and
 * follows no symbolic link. Returns 0, or -1 with errno when STATE/files cannot be read (a
 * missing one is 0: nothing was ever uploaded); what could not be removed is skipped. */
int file_sweep_startup(const char *state, struct store *store, struct sweep_counts *counts);

/* Removes STATE/files/<id> and everything in it (a deleted job's files); *bytes gets the bytes
 * removed. 0 (also when there was no such directory), or -1 with errno. */
int file_sweep_job(const char *state, long long id, long long *bytes);

#endif
