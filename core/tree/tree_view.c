/*
 * bvhlab — the tree interface's whole-tree service: refusing a wide tree
 * to a binary-only stage by name.
 */
#include <errno.h>

#include "tree/tree_view.h"
#include "util/util.h"

int tree_require_binary(const bvhlab_tree *t, const char *stage, bvhlab_error *err)
{
	if (tree_width(t) == 2)
		return 0;
	error_set(err, "%s takes binary trees only; this tree is %u-wide (ABI 1.5 width): use "
	          "it on the binary tree before any collapse", stage, tree_width(t));
	return -ENOTSUP;
}
