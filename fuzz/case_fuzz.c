/*
 * case_fuzz.c - libFuzzer target: the case parser and validator (solver/case/), as the server and
 * poro-solve reach it.
 *
 * Each input is a case text. It goes the server's way (jansson with JSON_REJECT_DUPLICATES, then
 * case_load_json on the tree) and poro-solve's way (case_load_string), and the two must agree:
 * a case one accepts the other accepts, and an accepted case's canonical text (what the server
 * stores and a worker later hands to poro-solve) must load again to the same canonical text.
 * A disagreement aborts, so the fuzzer reports it like a crash. Refusals must say something:
 * an empty message for a refused case would reach users as an empty problem list.
 *
 * Seeds: the cases of tests/cases (fuzz/run.sh copies them); dictionary fuzz/case.dict.
 */
#include "case.h"

#include <jansson.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void fail(const char *what, const char *detail)
{
	fprintf(stderr, "case_fuzz: %s: %s\n", what, detail ? detail : "");
	abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	char *text = malloc(size + 1);
	if (!text)
		return 0;
	memcpy(text, data, size);
	text[size] = '\0';

	struct case_spec *from_text = NULL;
	struct poro_error err_text = { 0 };
	enum poro_status st_text = case_load_string(text, &from_text, &err_text);
	if (st_text != PORO_OK && err_text.message[0] == '\0')
		fail("a refused case without a message (case_load_string)", poro_status_name(st_text));

	json_error_t jerr;
	json_t *root = json_loadb((const char *)data, size, JSON_REJECT_DUPLICATES, &jerr);
	if (root && json_is_object(root)) {
		struct case_spec *from_tree = NULL;
		struct poro_error err_tree = { 0 };
		enum poro_status st_tree = case_load_json(root, &from_tree, &err_tree);
		if (st_tree != PORO_OK && err_tree.message[0] == '\0')
			fail("a refused case without a message (case_load_json)", poro_status_name(st_tree));
		/* NUL bytes: case_load_string stops at the first, jansson reads them; only compare texts
		 * without one. Duplicate keys: jansson refuses them here, the text loader may not. */
		if (strlen(text) == size && (st_tree == PORO_OK) != (st_text == PORO_OK) && st_text != PORO_ENOMEM &&
		    st_tree != PORO_ENOMEM)
			fail("the server's and poro-solve's loaders disagree",
			     st_tree == PORO_OK ? err_text.message : err_tree.message);
		if (st_tree == PORO_OK) {
			/* what a worker gets: the canonical text must load and be a fixed point */
			struct case_spec *again = NULL;
			struct poro_error err_again = { 0 };
			if (case_load_string(from_tree->json, &again, &err_again) != PORO_OK)
				fail("the stored canonical case does not load again", err_again.message);
			if (strcmp(again->json, from_tree->json) != 0) {
				struct case_spec *third = NULL;
				json_t *t = json_loads(again->json, 0, NULL);
				if (t && case_load_json(t, &third, NULL) == PORO_OK && strcmp(third->json, from_tree->json) != 0)
					fail("the canonical case changes when loaded again", from_tree->json);
				json_decref(t);
				case_destroy(&third);
			}
			case_destroy(&again);
		}
		case_destroy(&from_tree);
	}
	json_decref(root);
	case_destroy(&from_text);
	free(text);
	return 0;
}
