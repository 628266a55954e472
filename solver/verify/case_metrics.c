/*
 * case_metrics.c - reading a case's "metrics" object, see case_metrics.h.
 */
#include "case_metrics.h"

#include "case.h"
#include "element.h"
#include "figures.h"

static const char *const NAMES[] = {
#define FIGURE_KEY(kind, name, unit, cls, where) name,
	FIGURE_MAP(FIGURE_KEY)
#undef FIGURE_KEY
	NULL
};

void case_read_metrics(struct case_reader *r, const json_t *root, unsigned *bits)
{
	const json_t *m = case_read_object(r, root, "", "metrics", CASE_OPTIONAL);
	*bits = 0;
	if (!m)
		return;
	case_check_keys(r, m, "/metrics", NAMES);
	for (int k = 0; k < FIGURE_COUNT; k++) {
		int on = 0;
		if (case_read_bool(r, m, "/metrics", NAMES[k], CASE_OPTIONAL, &on) && on)
			*bits |= 1u << k;
	}
}

/* check is figure_check or figure_check_element on case c. */
static void check_each(struct case_reader *r, unsigned bits, const void *c,
		       int (*check)(const void *c, enum figure_kind k, char *why, size_t why_size))
{
	for (int k = 0; k < FIGURE_COUNT; k++) {
		char why[200], pointer[CASE_POINTER_MAX];
		if (!(bits & 1u << k) || check(c, (enum figure_kind)k, why, sizeof why) == 0)
			continue;
		case_pointer_key(pointer, "/metrics", NAMES[k]);
		case_problem(r, pointer, "%s", why);
	}
}

static int check_sim(const void *c, enum figure_kind k, char *why, size_t why_size)
{
	return figure_check(c, k, why, why_size);
}

static int check_element(const void *c, enum figure_kind k, char *why, size_t why_size)
{
	return figure_check_element(c, k, why, why_size);
}

void case_check_metrics(struct case_reader *r, const struct case_spec *c)
{
	check_each(r, c->metrics, c, check_sim);
}

void case_check_element_metrics(struct case_reader *r, const struct element_case *c)
{
	check_each(r, c->metrics, c, check_element);
}
