/* Peak memory of a run's builds (harness_memory.c). */
#ifndef BVHLAB_CORE_HARNESS_MEMORY_H
#define BVHLAB_CORE_HARNESS_MEMORY_H

#include <bvhlab/bvhlab.h>

struct build_memory; /* output/results.h */

/* Before the first build (warm-up included), and after the last one. */
void harness_memory_begin(struct build_memory *m);
void harness_memory_end(struct build_memory *m, const bvhlab_tree *tree);

#endif
