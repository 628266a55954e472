/*
 * key_counts.c - counts per fixed-size key (key_counts.h).
 */
#include "key_counts.h"

#include <stdlib.h>
#include <string.h>

int key_counts_init(struct key_counts *t, size_t key_size, size_t keys)
{
	size_t capacity = 64;
	while (capacity < 2 * keys)
		capacity *= 2;
	memset(t, 0, sizeof *t);
	t->keys = calloc(capacity, key_size);
	t->counts = calloc(capacity, sizeof *t->counts);
	if (!t->keys || !t->counts) {
		key_counts_release(t);
		return -1;
	}
	t->key_size = key_size;
	t->mask = capacity - 1;
	return 0;
}

void key_counts_release(struct key_counts *t)
{
	free(t->keys);
	free(t->counts);
	memset(t, 0, sizeof *t);
}

static size_t home_of(const struct key_counts *t, const unsigned char *key)
{
	unsigned long long h = 14695981039346656037ull;
	for (size_t i = 0; i < t->key_size; i++)
		h = (h ^ key[i]) * 1099511628211ull;
	return (size_t)h & t->mask;
}

static unsigned char *key_at(const struct key_counts *t, size_t i)
{
	return t->keys + i * t->key_size;
}

/* The entry of key, or the empty entry where it would go. */
static size_t find(const struct key_counts *t, const void *key)
{
	size_t i = home_of(t, key);
	while (t->counts[i] && memcmp(key_at(t, i), key, t->key_size) != 0)
		i = (i + 1) & t->mask;
	return i;
}

int key_counts_get(const struct key_counts *t, const void *key)
{
	return t->counts[find(t, key)];
}

int key_counts_add(struct key_counts *t, const void *key, int delta)
{
	size_t i = find(t, key);
	if (!t->counts[i]) {
		if (delta <= 0)
			return 0;
		if (t->held >= (t->mask + 1) / 2)
			return -1;
		memcpy(key_at(t, i), key, t->key_size);
		t->held++;
	}
	t->counts[i] += delta;
	if (t->counts[i] > 0)
		return t->counts[i];
	t->counts[i] = 0;
	t->held--;
	/* backward shift: pull later entries of the probe run into the hole, so every key stays
	 * reachable from its home without tombstones */
	for (size_t hole = i, j = (i + 1) & t->mask; t->counts[j]; j = (j + 1) & t->mask) {
		size_t home = home_of(t, key_at(t, j));
		int movable = hole <= j ? (home <= hole || home > j) : (home <= hole && home > j);
		if (movable) {
			memcpy(key_at(t, hole), key_at(t, j), t->key_size);
			t->counts[hole] = t->counts[j];
			t->counts[j] = 0;
			hole = j;
		}
	}
	return 0;
}
