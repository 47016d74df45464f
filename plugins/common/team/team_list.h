/*
 * A task list: items appended by one thread, put in order (largest first,
 * so that a big task does not start last), then claimed one at a time by
 * every member of a team (team.h) until none is left. The task phases of
 * sah_tasks and sbvh; part of the team library.
 */
#ifndef BVHLAB_TEAM_LIST_H
#define BVHLAB_TEAM_LIST_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>

typedef struct team_list {
	void *items;        /* [n] of `size` bytes each */
	size_t size;        /* bytes of an item */
	size_t n, cap;
	atomic_size_t next; /* the first item not yet claimed */
} team_list;

/* An empty list of items of `type` (nothing allocated yet). */
#define TEAM_LIST(type) { .size = sizeof(type) }

/* The item at i, as a `type *`. */
#define TEAM_LIST_AT(l, type, i) ((type *)(l)->items + (i))

/* Appends a copy of *item: 0, or -ENOMEM with the list unchanged. */
int team_list_push(team_list *l, const void *item);

/* Orders the items by cmp (qsort's) and makes every one unclaimed. */
void team_list_order(team_list *l, int (*cmp)(const void *, const void *));

/* By any member: claims the next item, its index into *i; false when
 * every item is claimed. */
static inline bool team_list_claim(team_list *l, size_t *i)
{
	*i = atomic_fetch_add_explicit(&l->next, 1, memory_order_relaxed);
	return *i < l->n;
}

/* Frees the items; the list is empty after. */
void team_list_free(team_list *l);

#endif /* BVHLAB_TEAM_LIST_H */
