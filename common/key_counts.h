/*
 * key_counts.h - a count per fixed-size key: how many connections an address holds, how many
 * requests a token has in progress. Open addressing with linear probing, FNV-1a over the key's
 * bytes, deletion by backward shift (no tombstones, so a table that sees many keys come and go
 * never slows down); an entry whose count falls to 0 is removed. Not thread-safe: the caller
 * holds its own lock.
 */
#ifndef PORO_KEY_COUNTS_H
#define PORO_KEY_COUNTS_H

#include <stddef.h>

struct key_counts {
	unsigned char *keys;          /* capacity * key_size bytes */
	int *counts;                  /* 0: the entry is empty */
	size_t key_size, mask;        /* capacity - 1, capacity a power of two */
	size_t held;                  /* keys with a count */
};

/* Room for at least `keys` keys at once (the table is sized at twice that). 0, or -1 when out of
 * memory. */
int key_counts_init(struct key_counts *t, size_t key_size, size_t keys);
void key_counts_release(struct key_counts *t);

/* The count of key (0 when absent). */
int key_counts_get(const struct key_counts *t, const void *key);
/* Adds delta to key's count (a count never goes below 0) and returns the new count; -1 when the key
 * is new and the table already holds as many keys as it was made for. */
int key_counts_add(struct key_counts *t, const void *key, int delta);

#endif
