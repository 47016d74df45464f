/* A built tree's spare capacity given back (tree.c). */
#ifndef BVHLAB_CORE_TREE_SPARE_H
#define BVHLAB_CORE_TREE_SPARE_H

#include <bvhlab/tree.h>

/*
 * Gives the kernel the pages of the tree's arrays past its counts, keeping
 * the capacity: builders keep their scratch there between builds (lbvh's
 * Morton codes, binned SAH's reference arrays: big_spare_nodes), which
 * after the last build only holds memory that validation and tracing
 * want. What lies there reads as zeros afterwards.
 */
void tree_release_spare(bvhlab_tree *tree);

#endif
