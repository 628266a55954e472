/*
 * case_json.c - typed, pointer-tracking reads of a JSON document for the case loader (case_json.h).
 *
 * The only file of the case loader that talks to jansson. Parsing rejects duplicate object keys
 * (jansson would otherwise keep the last silently) and NUL characters inside strings. jansson
 * itself refuses NaN, Infinity and numbers that overflow a double, so every number read here is
 * finite; the check is kept anyway because the document is outside input (STYLE rule 12).
 *
 * A JSON "integer" is any number with no fractional part (2 and 2.0 alike), as in JSON Schema.
 * Strings from the document that appear in messages are cut short and control characters are
 * replaced by '?' (case_quote), so that every problem stays one line.
 *
 * Problems are capped (CASE_PROBLEMS_MAX in case.h): the first ones are written into the error
 * record as they come, the rest only counted, with one last line that says how many more there
 * were. Names of list items are kept in jansson objects (struct case_names), so that checking a
 * list of n names costs n hash lookups, not n^2/2 comparisons.
 *
 * It also compares two case texts as JSON values (case_json_difference in case.h), which is how a
 * checkpoint is matched to the case a resumed run is given.
 */
#include "case_json.h"

#include <jansson.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "case.h"

#define PROBLEM_MAX 1024            /* longest single problem message */
/* Room kept at the end of the message for the line "... and N more problems". */
#define MORE_LINE_SIZE (sizeof "\n" CASE_PROBLEMS_MORE "2147483647 more problems")

/* Rewrites the last line of the message, "... and N more problems", after a problem past the cap:
 * a short snprintf at a known offset, so counting costs the same for the millionth problem. */
static void write_more_line(struct case_reader *r)
{
	int more = r->problem_count - r->recorded;
	snprintf(r->err->message + r->used, sizeof r->err->message - r->used, "\n%s%d more problem%s",
		 CASE_PROBLEMS_MORE, more, more == 1 ? "" : "s");
}

void case_warn(struct case_reader *r, const char *pointer, const char *fmt, ...)
{
	if (!r->warnings)
		return;
	char message[PROBLEM_MAX];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(message, sizeof message, fmt, ap);
	va_end(ap);
	size_t used = strlen(r->warnings);
	int n = snprintf(r->warnings + used, CASE_WARNINGS_SIZE - used, "%s%s: %s", used ? "\n" : "",
			 pointer[0] ? pointer : "/", message);
	if (n < 0 || (size_t)n >= CASE_WARNINGS_SIZE - used)
		r->warnings[used] = '\0';   /* a warning that does not fit is left out whole */
}

void case_problem(struct case_reader *r, const char *pointer, const char *fmt, ...)
{
	/* Only a prefix of the problems is recorded, so the list reads in document order. */
	int listing = r->recorded == r->problem_count++ && r->recorded < CASE_PROBLEMS_MAX;
	if (!r->err)
		return;
	if (!listing) {
		write_more_line(r);
		return;
	}
	char message[PROBLEM_MAX];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(message, sizeof message, fmt, ap);
	va_end(ap);
	/* The empty pointer is the whole document; show it as "/" so every line starts alike. */
	const char *where = pointer[0] ? pointer : "/";
	if (r->recorded == 0) {
		poro_error_set(r->err, PORO_EINVAL, "%s: %s", where, message);
		r->used = strlen(r->err->message);
		r->recorded = 1;
		return;
	}
	size_t room = sizeof r->err->message - r->used;
	int n = snprintf(r->err->message + r->used, room, "\n%s: %s", where, message);
	if (n > 0 && (size_t)n + MORE_LINE_SIZE < room) {
		r->used += (size_t)n;
		r->recorded++;
	} else {
		write_more_line(r);                 /* overwrites the line that did not fit */
	}
}

long case_problem_count(const char *message)
{
	long lines = 0;
	for (const char *line = message; line && *line;) {
		const char *end = strchr(line, '\n');
		if (strncmp(line, CASE_PROBLEMS_MORE, strlen(CASE_PROBLEMS_MORE)) == 0)
			lines += strtol(line + strlen(CASE_PROBLEMS_MORE), NULL, 10);
		else
			lines++;
		line = end ? end + 1 : NULL;
	}
	return lines;
}

const char *case_quote(char *dst, const char *s)
{
	size_t n = 0, limit = CASE_QUOTE_SIZE - sizeof "...";
	for (; n < limit && s[n]; n++)
		dst[n] = (unsigned char)s[n] < 0x20 || s[n] == 0x7f ? '?' : s[n];
	if (s[n]) {
		while (n > 0 && ((unsigned char)s[n] & 0xc0) == 0x80)
			n--;                        /* do not cut a UTF-8 character in two */
		strcpy(dst + n, "...");
	} else {
		dst[n] = '\0';
	}
	return dst;
}

void case_pointer_key(char *dst, const char *base, const char *key)
{
	size_t n = (size_t)snprintf(dst, CASE_POINTER_MAX, "%s/", base);
	for (const char *k = key; *k && n + 3 < CASE_POINTER_MAX; k++) {
		if (*k == '~' || *k == '/') {       /* RFC 6901: '~' is written ~0, '/' is ~1 */
			dst[n++] = '~';
			dst[n++] = *k == '~' ? '0' : '1';
		} else {
			dst[n++] = (unsigned char)*k < 0x20 || *k == 0x7f ? '?' : *k;
		}
	}
	if (n >= CASE_POINTER_MAX)
		n = CASE_POINTER_MAX - 1;
	dst[n] = '\0';
}

void case_pointer_index(char *dst, const char *base, size_t index)
{
	snprintf(dst, CASE_POINTER_MAX, "%s/%zu", base, index);
}

const char *case_format_number(char *dst, double x)
{
	for (int precision = 6; precision <= 17; precision++) {
		snprintf(dst, CASE_NUMBER_SIZE, "%.*g", precision, x);
		if (strtod(dst, NULL) == x)
			break;
	}
	return dst;
}

static const char *type_name(const json_t *v)
{
	switch (json_typeof(v)) {
	case JSON_OBJECT: return "object";
	case JSON_ARRAY: return "array";
	case JSON_STRING: return "string";
	case JSON_INTEGER:
	case JSON_REAL: return "number";
	case JSON_TRUE:
	case JSON_FALSE: return "boolean";
	case JSON_NULL: return "null";
	}
	return "unknown";
}

json_t *case_json_parse(struct case_reader *r, const char *text)
{
	json_error_t e;
	json_t *doc = json_loads(text, JSON_REJECT_DUPLICATES, &e);
	if (!doc) {
		case_problem(r, "", "malformed JSON at line %d column %d: %s", e.line, e.column, e.text);
		return NULL;
	}
	if (!case_json_root(r, doc)) {
		json_decref(doc);
		return NULL;
	}
	return doc;
}

void case_json_free(json_t *doc)
{
	json_decref(doc);
}

int case_json_root(struct case_reader *r, const json_t *doc)
{
	if (json_is_object(doc))
		return 1;
	case_problem(r, "", "expected an object, got %s", doc ? type_name(doc) : "nothing");
	return 0;
}

char *case_json_text(const json_t *doc)
{
	return json_dumps(doc, JSON_COMPACT | JSON_SORT_KEYS);
}

void case_names_init(struct case_reader *r, struct case_names *n)
{
	if (!(n->index = json_object()))
		r->out_of_memory = 1;
}

int case_names_add(struct case_reader *r, struct case_names *n, const char *name, int index)
{
	int earlier = case_names_find(n, name);
	/* names are checked ASCII before they get here: no UTF-8 check needed */
	if (earlier < 0 && n->index && json_object_set_new_nocheck(n->index, name, json_integer(index)))
		r->out_of_memory = 1;
	return earlier;
}

int case_names_find(const struct case_names *n, const char *name)
{
	const json_t *v = n->index ? json_object_get(n->index, name) : NULL;
	return v ? (int)json_integer_value(v) : -1;
}

void case_names_release(struct case_names *n)
{
	json_decref(n->index);
	n->index = NULL;
}

/* A count for a message: whole up to 1e15, beyond that in the shortest exact form. */
static const char *format_count(char *dst, double x)
{
	if (x < 1e15)
		snprintf(dst, CASE_NUMBER_SIZE, "%.0f", x);
	else
		case_format_number(dst, x);
	return dst;
}

int case_check_limit(struct case_reader *r, const char *pointer, const char *verb, const char *what,
		     double got, double limit)
{
	char a[CASE_NUMBER_SIZE], b[CASE_NUMBER_SIZE];
	if (got <= limit)
		return 1;
	case_problem(r, pointer, "must %s at most %s %s (the case limit), got %s", verb, format_count(a, limit), what,
		     format_count(b, got));
	return 0;
}

static int is_allowed(const char *key, const char *const *allowed)
{
	for (; *allowed; allowed++)
		if (strcmp(key, *allowed) == 0)
			return 1;
	return 0;
}

void case_check_keys(struct case_reader *r, const json_t *obj, const char *base,
		     const char *const *allowed)
{
	const char *key;
	json_t *value;
	char pointer[CASE_POINTER_MAX];
	/* jansson's iteration macros take a non-const object; nothing is modified. */
	json_object_foreach((json_t *)obj, key, value) {
		if (!is_allowed(key, allowed)) {
			case_pointer_key(pointer, base, key);
			case_problem(r, pointer, "unknown key");
		}
	}
}

int case_has_key(const json_t *obj, const char *key)
{
	return json_object_get(obj, key) != NULL;
}

static int below_ok(double x, const struct case_range *range)
{
	switch (range->lo_kind) {
	case BOUND_OPEN: return x > range->lo;
	case BOUND_CLOSED: return x >= range->lo;
	case BOUND_NONE: break;
	}
	return 1;
}

static int above_ok(double x, const struct case_range *range)
{
	switch (range->hi_kind) {
	case BOUND_OPEN: return x < range->hi;
	case BOUND_CLOSED: return x <= range->hi;
	case BOUND_NONE: break;
	}
	return 1;
}

int case_check_range(struct case_reader *r, const char *pointer, double x, const struct case_range *range)
{
	if (below_ok(x, range) && above_ok(x, range))
		return 1;
	char lo[CASE_NUMBER_SIZE], hi[CASE_NUMBER_SIZE], got[CASE_NUMBER_SIZE], want[128] = "";
	size_t n = 0;
	if (range->lo_kind != BOUND_NONE)
		n += (size_t)snprintf(want, sizeof want, "%s %s", range->lo_kind == BOUND_OPEN ? ">" : ">=",
				      case_format_number(lo, range->lo));
	if (range->hi_kind != BOUND_NONE)
		snprintf(want + n, sizeof want - n, "%s%s %s", n ? " and " : "",
			 range->hi_kind == BOUND_OPEN ? "<" : "<=", case_format_number(hi, range->hi));
	case_problem(r, pointer, "must be %s, got %s", want, case_format_number(got, x));
	return 0;
}

/* Looks up obj[key], writing its pointer; records a problem if it is required and absent. */
static const json_t *member(struct case_reader *r, const json_t *obj, const char *base, const char *key,
			    enum case_need need, char *pointer)
{
	case_pointer_key(pointer, base, key);
	const json_t *v = json_object_get(obj, key);
	if (!v && need == CASE_REQUIRED)
		case_problem(r, pointer, "missing required key");
	return v;
}

static int value_number(struct case_reader *r, const json_t *v, const char *pointer,
			const struct case_range *range, double *out)
{
	if (!json_is_number(v)) {
		case_problem(r, pointer, "expected a number, got %s", type_name(v));
		return 0;
	}
	double x = json_number_value(v);
	if (!isfinite(x)) {
		case_problem(r, pointer, "expected a finite number");
		return 0;
	}
	if (range && !case_check_range(r, pointer, x, range))
		return 0;
	*out = x;
	return 1;
}

int case_read_number(struct case_reader *r, const json_t *obj, const char *base, const char *key,
		     enum case_need need, const struct case_range *range, double *out)
{
	char pointer[CASE_POINTER_MAX];
	const json_t *v = member(r, obj, base, key, need, pointer);
	return v && value_number(r, v, pointer, range, out);
}

int case_read_number_or_word(struct case_reader *r, const json_t *obj, const char *base, const char *key,
			     enum case_need need, const struct case_range *range, const char *word, double *out,
			     int *is_word)
{
	char pointer[CASE_POINTER_MAX], shown[CASE_QUOTE_SIZE];
	const json_t *v = member(r, obj, base, key, need, pointer);
	*is_word = 0;
	if (!v)
		return 0;
	if (json_is_number(v))
		return value_number(r, v, pointer, range, out);
	if (json_is_string(v) && !strcmp(json_string_value(v), word)) {
		*is_word = 1;
		return 1;
	}
	if (json_is_string(v))
		case_problem(r, pointer, "expected a number or \"%s\", got \"%s\"", word,
			     case_quote(shown, json_string_value(v)));
	else
		case_problem(r, pointer, "expected a number or \"%s\", got %s", word, type_name(v));
	return 0;
}

int case_read_int(struct case_reader *r, const json_t *obj, const char *base, const char *key,
		  enum case_need need, int lo, int hi, int *out)
{
	char pointer[CASE_POINTER_MAX], got[CASE_NUMBER_SIZE];
	const json_t *v = member(r, obj, base, key, need, pointer);
	double x;
	if (!v || !value_number(r, v, pointer, NULL, &x))
		return 0;
	if (x != floor(x)) {
		case_problem(r, pointer, "expected an integer, got %s", case_format_number(got, x));
		return 0;
	}
	struct case_range range = { BOUND_CLOSED, lo, BOUND_CLOSED, hi };
	if (!case_check_range(r, pointer, x, &range))
		return 0;
	*out = (int)x;
	return 1;
}

int case_read_bool(struct case_reader *r, const json_t *obj, const char *base, const char *key,
		   enum case_need need, int *out)
{
	char pointer[CASE_POINTER_MAX];
	const json_t *v = member(r, obj, base, key, need, pointer);
	if (!v)
		return 0;
	if (!json_is_boolean(v)) {
		case_problem(r, pointer, "expected a boolean, got %s", type_name(v));
		return 0;
	}
	*out = json_is_true(v);
	return 1;
}

/* Like case_read_string, also handing back the pointer for further checks. */
static int read_string_at(struct case_reader *r, const json_t *obj, const char *base, const char *key,
			  enum case_need need, const char **out, char *pointer)
{
	const json_t *v = member(r, obj, base, key, need, pointer);
	if (!v)
		return 0;
	if (!json_is_string(v)) {
		case_problem(r, pointer, "expected a string, got %s", type_name(v));
		return 0;
	}
	*out = json_string_value(v);
	return 1;
}

int case_read_string(struct case_reader *r, const json_t *obj, const char *base, const char *key,
		     enum case_need need, const char **out)
{
	char pointer[CASE_POINTER_MAX];
	return read_string_at(r, obj, base, key, need, out, pointer);
}

int case_read_short_text(struct case_reader *r, const json_t *obj, const char *base, const char *key,
			 enum case_need need, int max_chars, char *out)
{
	char pointer[CASE_POINTER_MAX];
	const char *s;
	if (!read_string_at(r, obj, base, key, need, &s, pointer))
		return 0;
	long chars = 0;
	for (const char *c = s; *c; c++)   /* jansson has checked the UTF-8: count the lead bytes */
		chars += ((unsigned char)*c & 0xc0) != 0x80;
	if (chars > max_chars) {
		case_problem(r, pointer, "must be at most %d characters long, got %ld", max_chars, chars);
		return 0;
	}
	memcpy(out, s, strlen(s) + 1);
	return 1;
}

int case_read_choice(struct case_reader *r, const json_t *obj, const char *base, const char *key,
		     enum case_need need, const char *const *names, int *out)
{
	char pointer[CASE_POINTER_MAX];
	const char *s;
	if (!read_string_at(r, obj, base, key, need, &s, pointer))
		return 0;
	for (int i = 0; names[i]; i++) {
		if (strcmp(s, names[i]) == 0) {
			*out = i;
			return 1;
		}
	}
	char list[512] = "", shown[CASE_QUOTE_SIZE];
	size_t n = 0;
	for (int i = 0; names[i] && n < sizeof list; i++)
		n += (size_t)snprintf(list + n, sizeof list - n, "%s'%s'", i ? ", " : "", names[i]);
	case_problem(r, pointer, "must be one of %s, got '%s'", list, case_quote(shown, s));
	return 0;
}

static int is_name_char(char ch)
{
	return (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') ||
	       ch == '_' || ch == '-';
}

int case_read_name(struct case_reader *r, const json_t *obj, const char *base, const char *key,
		   enum case_need need, char *out, size_t size)
{
	char pointer[CASE_POINTER_MAX], shown[CASE_QUOTE_SIZE];
	const char *s;
	if (!read_string_at(r, obj, base, key, need, &s, pointer))
		return 0;
	size_t length = strlen(s);
	if (length == 0 || length >= size) {
		case_problem(r, pointer, "must be 1 to %zu characters long, got %zu", size - 1, length);
		return 0;
	}
	for (const char *p = s; *p; p++) {
		if (!is_name_char(*p)) {
			case_problem(r, pointer, "must contain only letters, digits, '_' and '-', got '%s'",
				     case_quote(shown, s));
			return 0;
		}
	}
	memcpy(out, s, length + 1);
	return 1;
}

int case_value_vec2(struct case_reader *r, const json_t *v, const char *pointer,
		    const struct case_range *range, double out[2])
{
	if (!json_is_array(v)) {
		case_problem(r, pointer, "expected an array of 2 numbers, got %s", type_name(v));
		return 0;
	}
	if (json_array_size(v) != 2) {
		case_problem(r, pointer, "expected 2 numbers, got %zu", json_array_size(v));
		return 0;
	}
	char item[CASE_POINTER_MAX];
	int ok = 1;
	double xy[2];
	for (size_t i = 0; i < 2; i++) {
		case_pointer_index(item, pointer, i);
		ok &= value_number(r, json_array_get(v, i), item, range, &xy[i]);
	}
	if (ok) {
		out[0] = xy[0];
		out[1] = xy[1];
	}
	return ok;
}

int case_read_vec2(struct case_reader *r, const json_t *obj, const char *base, const char *key,
		   enum case_need need, const struct case_range *range, double out[2])
{
	char pointer[CASE_POINTER_MAX];
	const json_t *v = member(r, obj, base, key, need, pointer);
	return v && case_value_vec2(r, v, pointer, range, out);
}

int case_expect_object(struct case_reader *r, const json_t *v, const char *pointer)
{
	if (json_is_object(v))
		return 1;
	case_problem(r, pointer, "expected an object, got %s", type_name(v));
	return 0;
}

const json_t *case_read_object(struct case_reader *r, const json_t *obj, const char *base,
			       const char *key, enum case_need need)
{
	char pointer[CASE_POINTER_MAX];
	const json_t *v = member(r, obj, base, key, need, pointer);
	return v && case_expect_object(r, v, pointer) ? v : NULL;
}

const json_t *case_read_array(struct case_reader *r, const json_t *obj, const char *base,
			      const char *key, enum case_need need, size_t *count)
{
	char pointer[CASE_POINTER_MAX];
	const json_t *v = member(r, obj, base, key, need, pointer);
	*count = 0;
	if (!v)
		return NULL;
	if (!json_is_array(v)) {
		case_problem(r, pointer, "expected an array, got %s", type_name(v));
		return NULL;
	}
	*count = json_array_size(v);
	return v;
}

const json_t *case_read_list(struct case_reader *r, const json_t *obj, const char *base, const char *key,
			     enum case_need need, size_t max, const char *what, size_t *count)
{
	char pointer[CASE_POINTER_MAX];
	const json_t *v = case_read_array(r, obj, base, key, need, count);
	case_pointer_key(pointer, base, key);
	if (v && !case_check_limit(r, pointer, "list", what, (double)*count, (double)max)) {
		*count = 0;
		return NULL;
	}
	return v;
}

const json_t *case_array_item(const json_t *array, size_t index)
{
	return json_array_get(array, index);
}

/* ---- comparing two cases (case.h: case_json_difference) --------------------------------------- */

static int compare_keys(const void *a, const void *b)
{
	return strcmp(*(const char *const *)a, *(const char *const *)b);
}

/* The members of a and b, sorted, without repeats, in keys[json_object_size(a) + size(b)];
 * returns their number. */
static size_t union_keys(const json_t *a, const json_t *b, const char **keys)
{
	size_t n = 0, unique = 0;
	const char *key;
	json_t *v;
	json_object_foreach((json_t *)a, key, v)
		keys[n++] = key;
	json_object_foreach((json_t *)b, key, v)
		keys[n++] = key;
	qsort(keys, n, sizeof *keys, compare_keys);
	for (size_t i = 0; i < n; i++)
		if (unique == 0 || strcmp(keys[unique - 1], keys[i]))
			keys[unique++] = keys[i];
	return unique;
}

/* 0 when a and b are equal JSON values; otherwise 1 with the pointer of the first difference (in
 * sorted key order) in where[CASE_POINTER_MAX], or -1 when out of memory. Numbers compare by value. */
static int value_difference(const json_t *a, const json_t *b, const char *base, char *where)
{
	if (json_is_number(a) && json_is_number(b) && json_number_value(a) == json_number_value(b))
		return 0;
	if (json_typeof(a) != json_typeof(b) || (!json_is_object(a) && !json_is_array(a))) {
		if (json_equal((json_t *)a, (json_t *)b))
			return 0;
		snprintf(where, CASE_POINTER_MAX, "%s", base[0] ? base : "/");
		return 1;
	}
	char pointer[CASE_POINTER_MAX];
	if (json_is_array(a)) {
		size_t na = json_array_size(a), nb = json_array_size(b);
		for (size_t i = 0; i < na && i < nb; i++) {
			case_pointer_index(pointer, base, i);
			int d = value_difference(json_array_get(a, i), json_array_get(b, i), pointer, where);
			if (d)
				return d;
		}
		if (na == nb)
			return 0;
		case_pointer_index(where, base, na < nb ? na : nb);   /* the first item only one has */
		return 1;
	}
	const char **keys = malloc((json_object_size(a) + json_object_size(b) + 1) * sizeof *keys);
	if (!keys)
		return -1;
	size_t n = union_keys(a, b, keys);
	int d = 0;
	for (size_t i = 0; i < n && !d; i++) {
		const json_t *va = json_object_get(a, keys[i]), *vb = json_object_get(b, keys[i]);
		case_pointer_key(pointer, base, keys[i]);
		if (!va || !vb) {
			snprintf(where, CASE_POINTER_MAX, "%s", pointer);
			d = 1;
		} else {
			d = value_difference(va, vb, pointer, where);
		}
	}
	free(keys);
	return d;
}

int case_json_difference(const char *a, const char *b, char *where, size_t size)
{
	char pointer[CASE_POINTER_MAX] = "/";
	json_t *ja = json_loads(a ? a : "", JSON_DECODE_ANY, NULL);
	json_t *jb = json_loads(b ? b : "", JSON_DECODE_ANY, NULL);
	int d;
	if (!ja || !jb) {
		snprintf(pointer, sizeof pointer, "%s", ja ? "second" : "first");
		d = -1;
	} else {
		d = value_difference(ja, jb, "", pointer);
		if (d < 0) {
			snprintf(pointer, sizeof pointer, "out of memory");
			d = 1;
		}
	}
	json_decref(ja);
	json_decref(jb);
	if (where && size)
		snprintf(where, size, "%s", pointer);
	return d;
}
