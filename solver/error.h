/*
 * error.h - the one table of PoroMPM status codes, and the error record a simulation keeps.
 *
 * Every fallible library function returns an enum poro_status. The X-macro below is the single
 * source of codes, their names, a one-line meaning and the process exit code poro-solve uses
 * (0 success, 2 invalid input, 3 solver failure, 4 I/O, 5 out of memory), so the CLI, the server
 * and the tests agree on what each failure means.
 *
 * Errors are recorded once, where they happen, with poro_error_set(), which stores code, source
 * location and a formatted message in a struct poro_error; callers only pass the code up. The
 * library never prints and never exits.
 */
#ifndef PORO_ERROR_H
#define PORO_ERROR_H

#include <stddef.h>

/*      code                  exit  meaning */
#define PORO_STATUS_MAP(X)                                              \
	X(PORO_OK,              0, "success")                               \
	X(PORO_EINVAL,          2, "invalid input")                         \
	X(PORO_ESOLVER,         3, "solver failure")                        \
	X(PORO_EIO,             4, "input/output error")                    \
	X(PORO_ENOMEM,          5, "out of memory")                         \
	X(PORO_EINTERRUPTED,    6, "interrupted")

enum poro_status {
#define PORO_STATUS_ENUM(code, exit_code, meaning) code,
	PORO_STATUS_MAP(PORO_STATUS_ENUM)
#undef PORO_STATUS_ENUM
};

#define PORO_ERROR_MESSAGE_MAX 8192

/* The last error of an object: code, where it was raised, and a message (lower case, subject first). */
struct poro_error {
	enum poro_status code;
	const char *file;
	int line;
	char message[PORO_ERROR_MESSAGE_MAX];
};

/* Records an error in err (may be NULL) and returns code, so call sites read
 * `return poro_error_set(err, PORO_EINVAL, "...", ...);`. Use through the POROERR macro. */
enum poro_status poro_error_record(struct poro_error *err, enum poro_status code, const char *file,
				   int line, const char *fmt, ...)
	__attribute__((format(printf, 5, 6)));
#define poro_error_set(err, code, ...) poro_error_record((err), (code), __FILE__, __LINE__, __VA_ARGS__)

/* Appends a further line to an existing message (used to list several validation problems). */
void poro_error_append(struct poro_error *err, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* Name ("PORO_EINVAL"), meaning ("invalid input") and process exit code of a status. */
const char *poro_status_name(enum poro_status code);
const char *poro_status_meaning(enum poro_status code);
int poro_status_exit_code(enum poro_status code);

#endif
