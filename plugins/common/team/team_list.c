/* The task list (team_list.h). */
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "team_list.h"

int team_list_push(team_list *l, const void *item)
{
	if (l->n == l->cap) {
		size_t cap = l->cap ? 2 * l->cap : 64;
		void *grown = realloc(l->items, cap * l->size);
		if (!grown)
			return -ENOMEM;
		l->items = grown;
		l->cap = cap;
	}
	memcpy((char *)l->items + l->n++ * l->size, item, l->size);
	return 0;
}

void team_list_order(team_list *l, int (*cmp)(const void *, const void *))
{
	if (l->n > 1) /* qsort may not take the NULL of an empty list */
		qsort(l->items, l->n, l->size, cmp);
	atomic_store_explicit(&l->next, 0, memory_order_relaxed);
}

void team_list_free(team_list *l)
{
	free(l->items);
	l->items = NULL;
	l->n = l->cap = 0;
	atomic_store_explicit(&l->next, 0, memory_order_relaxed);
}
