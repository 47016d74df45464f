/*
 * sah_seq: the sequential top-down SAH builder, the reference the parallel
 * SAH strategies are compared with. All split decisions are the shared
 * kernel's (sah_kernel.h); this plugin only runs the whole
 * tree as one subtree on the calling thread.
 */

#include <bvhlab/builder.h>

#include "sah_kernel.h"
#include "sah_threads.h"

/* The reference schedule: the whole tree as one subtree, on this thread. */
static int schedule(team_host *th, sah_builder *b, const sah_job *root, uint32_t threads,
                    void *arg)
{
	(void)th;
	(void)threads;
	(void)arg;
	sah_build_subtree(b, root);
	return 0;
}

SAH_PLAIN_PLUGIN("sah_seq", BVHLAB_BUILDER_DETERMINISTIC | BVHLAB_BUILDER_BOXES,
	"sequential top-down SAH (exact sweep or binned), the reference")
