/*
 * json_scan.c - the one-pass JSON checker of json_scan.h: a pushdown automaton over RFC 8259's
 * grammar whose stack is one bit per open container (object or array), so its memory is fixed
 * however long or deep the text is. Each byte is looked at once; a number is only known to have
 * ended at the byte after it, which is then taken again in the state after a value.
 */
#include "json_scan.h"

#include <stdio.h>
#include <string.h>

enum {
	S_VALUE,           /* a value must start: at the top, after ':' and after ',' in an array */
	S_VALUE_OR_CLOSE,  /* just after '[' */
	S_KEY_OR_CLOSE,    /* just after '{' */
	S_KEY,             /* after ',' in an object */
	S_COLON,
	S_AFTER,           /* after a value: ',', the container's close, or (at the top) the end */
	S_STRING,
	S_ESCAPE,          /* after a backslash */
	S_HEX,             /* in the four hex digits of \u */
	S_MINUS, S_ZERO, S_INT, S_DOT, S_FRACTION, S_E, S_E_SIGN, S_EXPONENT,
	S_LITERAL,
	S_FAILED,
};

void json_scan_init(struct json_scan *s, const struct json_limits *limits)
{
	memset(s, 0, sizeof *s);
	s->limits = *limits;
	if (s->limits.max_depth > JSON_SCAN_DEPTH_MAX || s->limits.max_depth <= 0)
		s->limits.max_depth = JSON_SCAN_DEPTH_MAX;
	s->state = S_VALUE;
	s->line = 1;
	s->column = 1;
}

static int fail(struct json_scan *s, enum json_scan_verdict verdict, unsigned char c)
{
	char seen[8];
	if (c >= 0x20 && c < 0x7f)
		snprintf(seen, sizeof seen, "'%c'", c);
	else
		snprintf(seen, sizeof seen, "0x%02x", c);
	switch (verdict) {
	case JSON_SCAN_TOO_DEEP:
		snprintf(s->error, sizeof s->error, "JSON nested deeper than %d levels at line %lld column %lld",
			 s->limits.max_depth, s->line, s->column);
		break;
	case JSON_SCAN_TOO_MANY:
		snprintf(s->error, sizeof s->error,
			 "JSON holds more than %lld values (keys included) at line %lld column %lld",
			 s->limits.max_values, s->line, s->column);
		break;
	case JSON_SCAN_TOKEN_TOO_LONG:
		snprintf(s->error, sizeof s->error, "JSON string or number longer than %zu bytes at line %lld column %lld",
			 s->limits.max_token_bytes, s->line, s->column);
		break;
	default:
		snprintf(s->error, sizeof s->error, "invalid JSON at line %lld column %lld: unexpected %s", s->line,
			 s->column, seen);
		break;
	}
	s->verdict = verdict;
	s->state = S_FAILED;
	return -1;
}

static int is_space(unsigned char c)
{
	return c == ' ' || c == '\t' || c == '\n' || c == '\r';
}

static int is_digit(unsigned char c)
{
	return c >= '0' && c <= '9';
}

static int is_hex(unsigned char c)
{
	return is_digit(c) || (c >= 'a' && c <= 'f') || (c >= 'A' && c <= 'F');
}

static int top_is_object(const struct json_scan *s)
{
	int level = s->depth - 1;
	return (s->kinds[level / 8] >> (level % 8)) & 1;
}

static int count_value(struct json_scan *s, unsigned char c)
{
	if (++s->values > s->limits.max_values)
		return fail(s, JSON_SCAN_TOO_MANY, c);
	return 0;
}

static int open_container(struct json_scan *s, unsigned char c, int object)
{
	if (s->depth >= s->limits.max_depth)
		return fail(s, JSON_SCAN_TOO_DEEP, c);
	int level = s->depth++;
	if (object)
		s->kinds[level / 8] |= (unsigned char)(1u << (level % 8));
	else
		s->kinds[level / 8] &= (unsigned char)~(1u << (level % 8));
	s->state = object ? S_KEY_OR_CLOSE : S_VALUE_OR_CLOSE;
	return 0;
}

static int close_container(struct json_scan *s, unsigned char c)
{
	if (s->depth == 0 || top_is_object(s) != (c == '}'))
		return fail(s, JSON_SCAN_SYNTAX, c);
	s->depth--;
	s->state = S_AFTER;
	return 0;
}

/* The first byte of a value. */
static int start_value(struct json_scan *s, unsigned char c)
{
	if (count_value(s, c))
		return -1;
	s->token = 1;
	switch (c) {
	case '{':
		return open_container(s, c, 1);
	case '[':
		return open_container(s, c, 0);
	case '"':
		s->in_key = 0;
		s->token = 0;
		s->state = S_STRING;
		return 0;
	case '-':
		s->state = S_MINUS;
		return 0;
	case '0':
		s->state = S_ZERO;
		return 0;
	case 't':
		s->literal = "rue";
		break;
	case 'f':
		s->literal = "alse";
		break;
	case 'n':
		s->literal = "ull";
		break;
	default:
		if (c >= '1' && c <= '9') {
			s->state = S_INT;
			return 0;
		}
		return fail(s, JSON_SCAN_SYNTAX, c);
	}
	s->state = S_LITERAL;
	return 0;
}

static int start_key(struct json_scan *s, unsigned char c)
{
	if (c != '"')
		return fail(s, JSON_SCAN_SYNTAX, c);
	if (count_value(s, c))
		return -1;
	s->in_key = 1;
	s->token = 0;
	s->state = S_STRING;
	return 0;
}

static int token_byte(struct json_scan *s, unsigned char c)
{
	if (++s->token > s->limits.max_token_bytes)
		return fail(s, JSON_SCAN_TOKEN_TOO_LONG, c);
	return 0;
}

/* A byte inside a number: 1 when the number goes on, 0 when c is not part of it (the number ended
 * before c, which the caller takes again), -1 on a syntax error. */
static int number_byte(struct json_scan *s, unsigned char c)
{
	int digit = is_digit(c), e = c == 'e' || c == 'E';
	int next = -1, may_end = 0;
	switch (s->state) {
	case S_MINUS:
		next = c == '0' ? S_ZERO : digit ? S_INT : -1;
		break;
	case S_ZERO:
		next = c == '.' ? S_DOT : e ? S_E : -1;
		may_end = 1;
		break;
	case S_INT:
		next = digit ? S_INT : c == '.' ? S_DOT : e ? S_E : -1;
		may_end = 1;
		break;
	case S_DOT:
		next = digit ? S_FRACTION : -1;
		break;
	case S_FRACTION:
		next = digit ? S_FRACTION : e ? S_E : -1;
		may_end = 1;
		break;
	case S_E:
		next = c == '+' || c == '-' ? S_E_SIGN : digit ? S_EXPONENT : -1;
		break;
	case S_E_SIGN:
		next = digit ? S_EXPONENT : -1;
		break;
	default: /* S_EXPONENT */
		next = digit ? S_EXPONENT : -1;
		may_end = 1;
		break;
	}
	if (next >= 0) {
		s->state = next;
		return token_byte(s, c) ? -1 : 1;
	}
	if (may_end) {
		s->state = S_AFTER;
		return 0;
	}
	return fail(s, JSON_SCAN_SYNTAX, c);
}

static int string_byte(struct json_scan *s, unsigned char c)
{
	switch (s->state) {
	case S_ESCAPE:
		if (c == 'u') {
			s->hex = 4;
			s->state = S_HEX;
		} else if (strchr("\"\\/bfnrt", c) && c) {
			s->state = S_STRING;
		} else {
			return fail(s, JSON_SCAN_SYNTAX, c);
		}
		return token_byte(s, c);
	case S_HEX:
		if (!is_hex(c))
			return fail(s, JSON_SCAN_SYNTAX, c);
		if (--s->hex == 0)
			s->state = S_STRING;
		return token_byte(s, c);
	default: /* S_STRING */
		if (c == '"') {
			s->state = s->in_key ? S_COLON : S_AFTER;
			return 0;
		}
		if (c < 0x20)
			return fail(s, JSON_SCAN_SYNTAX, c);
		if (c == '\\')
			s->state = S_ESCAPE;
		return token_byte(s, c);
	}
}

static int after_value(struct json_scan *s, unsigned char c)
{
	if (is_space(c))
		return 0;
	if (s->depth == 0)
		return fail(s, JSON_SCAN_SYNTAX, c); /* text after the one top-level value */
	if (c == ',') {
		s->state = top_is_object(s) ? S_KEY : S_VALUE;
		return 0;
	}
	if (c == ']' || c == '}')
		return close_container(s, c);
	return fail(s, JSON_SCAN_SYNTAX, c);
}

static int take(struct json_scan *s, unsigned char c)
{
	switch (s->state) {
	case S_VALUE:
		return is_space(c) ? 0 : start_value(s, c);
	case S_VALUE_OR_CLOSE:
		if (is_space(c))
			return 0;
		return c == ']' ? close_container(s, c) : start_value(s, c);
	case S_KEY_OR_CLOSE:
		if (is_space(c))
			return 0;
		return c == '}' ? close_container(s, c) : start_key(s, c);
	case S_KEY:
		return is_space(c) ? 0 : start_key(s, c);
	case S_COLON:
		if (is_space(c))
			return 0;
		if (c != ':')
			return fail(s, JSON_SCAN_SYNTAX, c);
		s->state = S_VALUE;
		return 0;
	case S_AFTER:
		return after_value(s, c);
	case S_STRING:
	case S_ESCAPE:
	case S_HEX:
		return string_byte(s, c);
	case S_LITERAL:
		if (c != (unsigned char)*s->literal)
			return fail(s, JSON_SCAN_SYNTAX, c);
		if (!*++s->literal)
			s->state = S_AFTER;
		return 0;
	case S_FAILED:
		return -1;
	default: { /* in a number */
		int more = number_byte(s, c);
		if (more < 0)
			return -1;
		return more ? 0 : after_value(s, c);
	}
	}
}

int json_scan_feed(struct json_scan *s, const char *data, size_t size)
{
	if (s->state == S_FAILED)
		return -1;
	for (size_t i = 0; i < size; i++) {
		if (take(s, (unsigned char)data[i]))
			return -1;
		s->offset++;
		if (data[i] == '\n') {
			s->line++;
			s->column = 1;
		} else {
			s->column++;
		}
	}
	return 0;
}

int json_scan_finish(struct json_scan *s)
{
	if (s->state == S_FAILED)
		return -1;
	int complete = s->depth == 0 && (s->state == S_AFTER || s->state == S_ZERO || s->state == S_INT ||
					 s->state == S_FRACTION || s->state == S_EXPONENT);
	if (complete)
		return 0;
	snprintf(s->error, sizeof s->error, "invalid JSON: the text ends at line %lld column %lld %s", s->line,
		 s->column, s->values == 0 ? "before any value" : "inside a value");
	s->verdict = JSON_SCAN_SYNTAX;
	s->state = S_FAILED;
	return -1;
}
