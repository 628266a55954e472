/*
 * key_counts_test.c - the per-key counts of common/key_counts.c against a brute-force reference
 * (a plain array of every key's count) over 200,000 random additions and removals of 60 keys in a
 * table of 128 entries (long probe runs, so removals shift entries back), and the refusal of a key
 * beyond the table's size.
 */
#include "../harness.h"
#include "key_counts.h"

#define KEYS 60
#define KEY_SIZE 16

static void random_operations(void)
{
	struct key_counts t;
	unsigned char keys[KEYS][KEY_SIZE];
	int want[KEYS] = { 0 };
	for (int k = 0; k < KEYS; k++)
		for (int b = 0; b < KEY_SIZE; b++) /* random keys: about 40% of them collide at 128 entries */
			keys[k][b] = (unsigned char)rnd(0, 256);
	int ok = key_counts_init(&t, KEY_SIZE, 40) == 0, wrong = 0, held_wrong = 0;
	for (int step = 0; ok && step < 200000; step++) {
		int k = (int)rnd(0, KEYS);
		/* each key climbs to a few, then drops to 0 at once: most keys are present at any time and
		 * removals are frequent */
		int delta = want[k] < 1 + (int)rnd(0, 4) ? 1 : -want[k] - (int)rnd(0, 2);
		int got = key_counts_add(&t, keys[k], delta);
		want[k] = want[k] + delta > 0 ? want[k] + delta : 0;
		wrong += got != want[k];
		if (step % 997 == 0) {
			size_t held = 0;
			for (int j = 0; j < KEYS; j++) {
				wrong += key_counts_get(&t, keys[j]) != want[j];
				held += want[j] > 0;
			}
			held_wrong += held != t.held;
		}
	}
	CHECK(ok && wrong == 0 && held_wrong == 0, "key_counts_matches_reference",
	      "%d counts and %d key totals differ from the reference", wrong, held_wrong);
	key_counts_release(&t);
}

/* The table's hash, written out again to pick keys whose probe runs wrap past the last entry. */
static size_t fnv_home(const unsigned char *key, size_t mask)
{
	unsigned long long h = 14695981039346656037ull;
	for (int i = 0; i < KEY_SIZE; i++)
		h = (h ^ key[i]) * 1099511628211ull;
	return (size_t)h & mask;
}

static void wrapping_runs(void)
{
	struct key_counts t;
	key_counts_init(&t, KEY_SIZE, 40);
	unsigned char keys[12][KEY_SIZE];
	int found = 0;
	while (found < 12) { /* five keys at home 127, four at 126, three at 0: a run that wraps */
		for (int b = 0; b < KEY_SIZE; b++)
			keys[found][b] = (unsigned char)rnd(0, 256);
		found += fnv_home(keys[found], t.mask) == (size_t)(found < 5 ? 127 : found < 9 ? 126 : 0);
	}
	int wrong = 0;
	for (int round = 0; round < 200; round++) {
		int present[12];
		for (int k = 0; k < 12; k++)
			present[k] = key_counts_add(&t, keys[(k * 5 + round) % 12], 1) == 1;
		for (int k = 0; k < 12; k++) { /* remove half, in an order that changes each round */
			int victim = (k * 7 + round * 3) % 12;
			if (k % 2 == 0)
				key_counts_add(&t, keys[victim], -1);
			present[victim] = k % 2 != 0;
		}
		for (int k = 0; k < 12; k++) {
			wrong += key_counts_get(&t, keys[k]) != present[k];
			key_counts_add(&t, keys[k], -1);
		}
	}
	CHECK(wrong == 0 && t.held == 0, "key_counts_runs_that_wrap", "%d lookups wrong, %zu keys left", wrong, t.held);
	key_counts_release(&t);
}

static void full_table(void)
{
	struct key_counts t;
	key_counts_init(&t, sizeof(int), 40); /* room for 64 keys: the table is made twice the size */
	int refused_at = -1;
	for (int k = 0; k < 200 && refused_at < 0; k++)
		if (key_counts_add(&t, &k, 1) < 0)
			refused_at = k;
	int present = 0;
	for (int k = 0; k < refused_at; k++)
		present += key_counts_get(&t, &k) == 1;
	int known_still_counts = key_counts_add(&t, &(int){ 3 }, 1) == 2;
	CHECK(refused_at == 64 && present == 64 && known_still_counts, "key_counts_full_table_refuses_new_keys",
	      "refused at key %d, %d present, a known key counted: %d", refused_at, present, known_still_counts);
	key_counts_release(&t);
}

int main(void)
{
	random_operations();
	wrapping_runs();
	full_table();
	return harness_failed_count ? 1 : 0;
}
