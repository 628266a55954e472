/*
 * case_json.h - private to the case loader: typed, pointer-tracking reads of a parsed JSON document.
 *
 * case_load.c reads a case section by section through these functions and never calls jansson
 * itself; case_json.c is the one file jansson enters through (STYLE rule 5). Every read knows the
 * JSON pointer (RFC 6901) of what it reads, and every problem it finds is counted in the reader and,
 * among the first CASE_PROBLEMS_MAX (case.h), recorded as one line "JSON-pointer: message";
 * reading then goes on, so one pass lists the problems of a document and says how many there were.
 * A problem past the cap costs a counter and a short line, so a document of a million bad items
 * costs no more to refuse than to read.
 *
 * Conventions of the read functions: `base` is the pointer of the object read from ("" for the
 * root), `key` the member. A member read returns 1 when the member is present and valid (the value
 * is then stored in *out), 0 otherwise: absent (a problem only when CASE_REQUIRED; *out is left
 * untouched, so callers store the default first) or invalid (a problem is recorded). Returned
 * json_t pointers and strings are borrowed from the document and live until case_json_free().
 */
#ifndef PORO_CASE_JSON_H
#define PORO_CASE_JSON_H

#include <stddef.h>

#include "error.h"

typedef struct json_t json_t;

#define CASE_POINTER_MAX 256        /* longest JSON pointer kept in a message; longer ones are cut */

struct case_reader {
	struct poro_error *err;     /* where problems go; may be NULL */
	char *warnings;             /* [CASE_WARNINGS_SIZE] where warnings go (case.h); NULL: dropped */
	int problem_count;          /* problems found so far */
	int out_of_memory;          /* an allocation failed while reading */
	int recorded;               /* problems written into err->message, a prefix of those found */
	size_t used;                /* bytes of err->message those lines fill (without the "more" line) */
};

enum case_need { CASE_OPTIONAL, CASE_REQUIRED };

/* Bounds on a real number: open (x > lo), closed (x >= lo) or none, and the same above. */
enum case_bound { BOUND_NONE, BOUND_OPEN, BOUND_CLOSED };
struct case_range {
	enum case_bound lo_kind;
	double lo;
	enum case_bound hi_kind;
	double hi;
};

/* Counts one problem and records it as "pointer: message" while under the cap (case.h). */
void case_problem(struct case_reader *r, const char *pointer, const char *fmt, ...)
	__attribute__((format(printf, 3, 4)));

/* Appends "pointer: message" as a line to r->warnings while it fits (case.h, CASE_WARNINGS_SIZE):
 * a value that is valid but most likely not what the author meant. */
void case_warn(struct case_reader *r, const char *pointer, const char *fmt, ...) __attribute__((format(printf, 3, 4)));

/* Writes base + "/" + key (escaped per RFC 6901) or base + "/" + index into dst[CASE_POINTER_MAX]. */
void case_pointer_key(char *dst, const char *base, const char *key);
void case_pointer_index(char *dst, const char *base, size_t index);

/* Copies s into dst[CASE_QUOTE_SIZE] for a message: control characters become '?', long strings
 * are cut and end in "...". Returns dst. */
#define CASE_QUOTE_SIZE 52
const char *case_quote(char *dst, const char *s);

/* Formats x into dst[CASE_NUMBER_SIZE] in the fewest significant digits that read back as x. */
#define CASE_NUMBER_SIZE 32
const char *case_format_number(char *dst, double x);

/* Reads a whole file into a NUL-terminated heap string the caller frees (case_load.c). PORO_EIO
 * naming the path when it cannot be read; PORO_EINVAL ("/: malformed JSON") when it holds a NUL. */
enum poro_status case_read_text(const char *path, char **text, struct poro_error *err);

/* Parses text. On malformed JSON records "/: malformed JSON at line L column C: why" and returns
 * NULL. The root must be an object. Frees with case_json_free(). */
json_t *case_json_parse(struct case_reader *r, const char *text);
void case_json_free(json_t *doc);
/* 1 when doc, parsed by the caller, is an object; otherwise records "/: expected an object, got T". */
int case_json_root(struct case_reader *r, const json_t *doc);
/* doc in canonical form (compact, keys sorted), a heap string the caller frees; NULL without memory. */
char *case_json_text(const json_t *doc);

/* The names of a list's items (materials, bodies, probes), for duplicate checks and references
 * in constant time per name: a jansson object from name to item index, i.e. jansson's hash table,
 * whose hash is seeded at random per process so that chosen names cannot force collisions.
 * case_names_add returns -1 when the name is new (and keeps index for it), else the index kept
 * for the name, whose first item stays the one found. Both record out of memory in r. */
struct case_names {
	json_t *index;
};
void case_names_init(struct case_reader *r, struct case_names *n);
int case_names_add(struct case_reader *r, struct case_names *n, const char *name, int index);
int case_names_find(const struct case_names *n, const char *name);   /* -1 when absent */
void case_names_release(struct case_names *n);

/* Records "pointer: must VERB at most LIMIT WHAT (the case limit), got GOT" unless got <= limit;
 * returns 1 when within it. For the counts a case implies (cells, steps, ...). */
int case_check_limit(struct case_reader *r, const char *pointer, const char *verb, const char *what,
		     double got, double limit);

/* Records "pointer/key: unknown key" for every member of obj not in allowed (NULL-terminated). */
void case_check_keys(struct case_reader *r, const json_t *obj, const char *base,
		     const char *const *allowed);
int case_has_key(const json_t *obj, const char *key);

/* Records a problem unless x lies in range; returns 1 when it does. */
int case_check_range(struct case_reader *r, const char *pointer, double x, const struct case_range *range);

/* Member reads (see the conventions above). range may be NULL: any finite number. */
int case_read_number(struct case_reader *r, const json_t *obj, const char *base, const char *key,
		     enum case_need need, const struct case_range *range, double *out);
/* A number in range, or the string word ("auto"): returns 1 with *out set, or with *is_word 1. */
int case_read_number_or_word(struct case_reader *r, const json_t *obj, const char *base, const char *key,
			     enum case_need need, const struct case_range *range, const char *word, double *out,
			     int *is_word);
int case_read_int(struct case_reader *r, const json_t *obj, const char *base, const char *key,
		  enum case_need need, int lo, int hi, int *out);
int case_read_bool(struct case_reader *r, const json_t *obj, const char *base, const char *key,
		   enum case_need need, int *out);
int case_read_string(struct case_reader *r, const json_t *obj, const char *base, const char *key,
		     enum case_need need, const char **out);
/* A string of at most max_chars characters (Unicode code points, as JSON Schema's maxLength counts
 * them: a byte count would refuse a title of accented letters that the schema accepts), copied into
 * out[4 max_chars + 1]. */
int case_read_short_text(struct case_reader *r, const json_t *obj, const char *base, const char *key,
			 enum case_need need, int max_chars, char *out);
/* A string that must be one of names (NULL-terminated); *out is its index. */
int case_read_choice(struct case_reader *r, const json_t *obj, const char *base, const char *key,
		     enum case_need need, const char *const *names, int *out);
/* A name: 1 to size-1 characters from [A-Za-z0-9_-], copied into out[size]. */
int case_read_name(struct case_reader *r, const json_t *obj, const char *base, const char *key,
		   enum case_need need, char *out, size_t size);
/* Exactly two numbers [x, y], each in range (NULL: any finite). */
int case_read_vec2(struct case_reader *r, const json_t *obj, const char *base, const char *key,
		   enum case_need need, const struct case_range *range, double out[2]);
/* An object or an array member; NULL when absent or of another type. */
const json_t *case_read_object(struct case_reader *r, const json_t *obj, const char *base,
			       const char *key, enum case_need need);
const json_t *case_read_array(struct case_reader *r, const json_t *obj, const char *base,
			      const char *key, enum case_need need, size_t *count);
/* An array of at most max items, called what in the message: NULL, *count 0 and the problem of
 * case_check_limit when longer, so that no item of an oversized list is read. */
const json_t *case_read_list(struct case_reader *r, const json_t *obj, const char *base, const char *key,
			     enum case_need need, size_t max, const char *what, size_t *count);

/* Value reads, for array items: v at pointer must be an object / two numbers. */
int case_expect_object(struct case_reader *r, const json_t *v, const char *pointer);
int case_value_vec2(struct case_reader *r, const json_t *v, const char *pointer,
		    const struct case_range *range, double out[2]);
const json_t *case_array_item(const json_t *array, size_t index);

#endif
