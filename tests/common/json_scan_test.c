/*
 * json_scan_test.c - the one-pass JSON checker (common/json_scan.c) against jansson as the
 * reference parser: the same verdict on hand-picked texts and on 20,000 random mutations of valid
 * documents, whatever the pieces the text is fed in; and each limit (depth, values, token length)
 * refused at the byte where it is crossed, with a message that says which.
 */
#include "../harness.h"
#include "json_scan.h"

#include <jansson.h>

static const struct json_limits GENEROUS = { .max_depth = 400, .max_values = 1000000, .max_token_bytes = 1 << 20 };

/* Feeds text in pieces of at most piece bytes (0: at once) and returns the verdict (0 = valid). */
static int scan(const char *text, size_t n, size_t piece, const struct json_limits *limits, struct json_scan *s)
{
	json_scan_init(s, limits);
	size_t step = piece ? piece : (n ? n : 1);
	for (size_t at = 0; at < n; at += step)
		if (json_scan_feed(s, text + at, n - at < step ? n - at : step))
			return -1;
	return json_scan_finish(s);
}

/* jansson's verdict, 0 = valid. Texts jansson refuses for what it decodes, not for their syntax
 * (integers beyond 64 bits, reals beyond double), are reported as 1 and skipped by the callers:
 * the scanner does not decode. */
static int reference(const char *text, size_t n)
{
	json_error_t e;
	json_t *v = json_loadb(text, n, JSON_DECODE_ANY | JSON_ALLOW_NUL, &e);
	if (v) {
		json_decref(v);
		return 0;
	}
	return strstr(e.text, "too big") || strstr(e.text, "overflow") ? 1 : -1;
}

static void fixed_texts(void)
{
	static const char *const valid[] = {
		"0", "-0", "1.5e-3", "-12.25E+7", "\"\"", "\"a\\u00e9\\n\\\\\"", "true", "false", "null",
		"[]", "{}", " [ 1 , 2 ] ", "{\"a\":{\"b\":[true,null,{\"c\":-1e5}]}}", "[[[[[]]]]]",
		"{\"k\":\"v\",\"l\":[0,1.0,2e2]}\n",
	};
	static const char *const invalid[] = {
		"", " ", "01", "-", "1.", ".5", "1e", "1e+", "+1", "tru", "truex", "nul", "[1,]", "[,1]",
		"{\"a\"}", "{\"a\":}", "{a:1}", "{\"a\":1,}", "[1 2]", "[1}", "{\"a\":1]", "\"abc", "\"\\x\"",
		"\"\\u12g4\"", "\"a\tb\"", "[]]", "{}{}", "1 2", "[", "{", "\"\\",
	};
	int bad = 0;
	struct json_scan s;
	for (size_t i = 0; i < sizeof valid / sizeof *valid; i++)
		for (size_t piece = 0; piece <= 3; piece++)
			if (scan(valid[i], strlen(valid[i]), piece, &GENEROUS, &s) != 0) {
				printf("INFO valid text refused: '%s' (%s)\n", valid[i], s.error);
				bad++;
			}
	CHECK(bad == 0, "json_scan_accepts_valid_texts", "%d valid texts refused", bad);
	bad = 0;
	for (size_t i = 0; i < sizeof invalid / sizeof *invalid; i++)
		for (size_t piece = 0; piece <= 3; piece++)
			if (scan(invalid[i], strlen(invalid[i]), piece, &GENEROUS, &s) == 0) {
				printf("INFO invalid text accepted: '%s'\n", invalid[i]);
				bad++;
			}
	CHECK(bad == 0, "json_scan_refuses_invalid_texts", "%d invalid texts accepted", bad);
	int agree = 1;
	for (size_t i = 0; i < sizeof valid / sizeof *valid; i++)
		agree &= reference(valid[i], strlen(valid[i])) == 0;
	for (size_t i = 0; i < sizeof invalid / sizeof *invalid; i++)
		agree &= reference(invalid[i], strlen(invalid[i])) != 0;
	CHECK(agree, "json_scan_fixed_texts_agree_with_jansson", "the hand-picked verdicts differ from jansson's");
}

/* A random valid document of about budget values into buf; returns its length. */
static size_t random_value(char *buf, size_t cap, size_t n, int depth, int *budget)
{
	static const char *const atoms[] = { "0", "-3", "12.5", "6.02e23", "true", "false", "null", "\"x\"",
					     "\"a\\\"b\"", "\"\\u0041\"", "\"\"" };
	double r = rnd(0, 1);
	if (n + 64 >= cap || *budget <= 0 || depth > 6 || r < 0.45) {
		const char *a = atoms[(int)rnd(0, sizeof atoms / sizeof *atoms)];
		size_t len = strlen(a);
		if (n + len < cap) {
			memcpy(buf + n, a, len);
			n += len;
		}
		return n;
	}
	int object = r < 0.7;
	buf[n++] = object ? '{' : '[';
	int items = (int)rnd(0, 5);
	for (int i = 0; i < items && n + 64 < cap; i++) {
		(*budget)--;
		if (i)
			buf[n++] = ',';
		if (object) {
			n += (size_t)snprintf(buf + n, cap - n, "\"k%d\":", i);
		}
		n = random_value(buf, cap, n, depth + 1, budget);
	}
	buf[n++] = object ? '}' : ']';
	return n;
}

static void random_mutations(void)
{
	static const char alphabet[] = "{}[],:\"\\ 0123456789-+.eEtrufalsn\tabcu";
	char text[2048];
	int disagree = 0, compared = 0, split_differs = 0, invalid_seen = 0;
	struct json_scan s, t;
	for (int trial = 0; trial < 20000; trial++) {
		int budget = 30;
		size_t n = random_value(text, sizeof text - 8, 0, 0, &budget);
		int mutations = (int)rnd(0, 4);
		for (int m = 0; m < mutations && n > 0; m++) {
			size_t at = (size_t)rnd(0, (double)n);
			char c = alphabet[(int)rnd(0, sizeof alphabet - 1)];
			double kind = rnd(0, 1);
			if (kind < 0.4) {
				text[at] = c;
			} else if (kind < 0.7) {
				memmove(text + at, text + at + 1, n - at - 1);
				n--;
			} else {
				memmove(text + at + 1, text + at, n - at);
				text[at] = c;
				n++;
			}
		}
		int want = reference(text, n);
		if (want > 0)
			continue;
		compared++;
		invalid_seen += want != 0;
		int got = scan(text, n, 0, &GENEROUS, &s);
		if ((got == 0) != (want == 0)) {
			if (disagree++ < 5)
				printf("INFO disagreement (jansson %s): %.*s\n", want ? "refuses" : "accepts", (int)n, text);
		}
		if (scan(text, n, 1 + (size_t)rnd(0, 7), &GENEROUS, &t) != got)
			split_differs++;
	}
	printf("INFO %d random texts compared with jansson, %d of them invalid\n", compared, invalid_seen);
	CHECK(disagree == 0 && compared > 15000 && invalid_seen > 1000, "json_scan_random_texts_agree_with_jansson",
	      "%d of %d verdicts differ", disagree, compared);
	CHECK(split_differs == 0, "json_scan_verdict_independent_of_pieces", "%d texts judged otherwise in pieces",
	      split_differs);
}

static void limits(void)
{
	/* positions count lines and columns as jansson does, from 1 */
	const char *two_lines = "{\"a\": 1,\n \"b\": }";
	struct json_scan p;
	int bad = scan(two_lines, strlen(two_lines), 0, &GENEROUS, &p);
	CHECK(bad != 0 && strstr(p.error, "line 2 column 7: unexpected '}'"), "json_scan_names_line_and_column",
	      "'%s'", p.error);

	struct json_scan s;
	char deep[200];
	for (int i = 0; i < 100; i++)
		deep[i] = '[', deep[199 - i] = ']';
	struct json_limits lim = GENEROUS;
	lim.max_depth = 100;
	int at_limit = scan(deep, sizeof deep, 0, &lim, &s);
	lim.max_depth = 99;
	int over = scan(deep, sizeof deep, 0, &lim, &s);
	CHECK(at_limit == 0 && over != 0 && s.verdict == JSON_SCAN_TOO_DEEP && s.offset == 99 &&
		      strstr(s.error, "deeper than 99 levels at line 1 column 100"),
	      "json_scan_depth_limit", "at limit %d, over %d, verdict %d, offset %lld, '%s'", at_limit, over, s.verdict,
	      s.offset, s.error);

	const char *flat = "[1,2,3,4,{\"a\":5}]"; /* 8 values: the array, 5 numbers... the object, its key */
	lim = GENEROUS;
	lim.max_values = 8;
	at_limit = scan(flat, strlen(flat), 0, &lim, &s);
	lim.max_values = 7;
	over = scan(flat, strlen(flat), 0, &lim, &s);
	CHECK(at_limit == 0 && over != 0 && s.verdict == JSON_SCAN_TOO_MANY && strstr(s.error, "more than 7 values"),
	      "json_scan_value_limit", "at limit %d, over %d, verdict %d, '%s'", at_limit, over, s.verdict, s.error);

	const char *strings = "[\"abcdefgh\",123456789]";
	lim = GENEROUS;
	lim.max_token_bytes = 9;
	at_limit = scan(strings, strlen(strings), 0, &lim, &s);
	lim.max_token_bytes = 8;
	over = scan(strings, strlen(strings), 0, &lim, &s);
	CHECK(at_limit == 0 && over != 0 && s.verdict == JSON_SCAN_TOKEN_TOO_LONG && s.offset == 20,
	      "json_scan_token_limit", "at limit %d, over %d, verdict %d, offset %lld, '%s'", at_limit, over, s.verdict,
	      s.offset, s.error);

	/* a refused text stays refused: later pieces are not looked at */
	json_scan_init(&s, &GENEROUS);
	int first = json_scan_feed(&s, "[1,}", 4), again = json_scan_feed(&s, "1]", 2);
	CHECK(first != 0 && again != 0 && json_scan_finish(&s) != 0 && strstr(s.error, "line 1 column 4: unexpected '}'"),
	      "json_scan_failure_sticks", "first %d, again %d, '%s'", first, again, s.error);
}

int main(void)
{
	fixed_texts();
	random_mutations();
	limits();
	return harness_failed_count ? 1 : 0;
}
