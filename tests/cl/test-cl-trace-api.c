/*
 * The device traversals through bvhlab_trace_measure on trees made by hand,
 * where no builder would put them:
 *   ties    two copies of one triangle, the larger id in the first leaf:
 *           both kernels visit it first and must still return the smaller
 *           id at the same t, u, v (the tie rule, not the visiting order);
 *   deep    a chain of 300 leaves that rays walking -x enter far end first,
 *           so the stack kernel holds ~300 far children: the host must
 *           size its stack from the tree (a program with a larger stack);
 *           hits and nodes entered equal the CPU's (wide8 on the device:
 *           the chain collapsed 8-wide is still ~50 nodes deep, its
 *           stack sized so too; hits equal);
 *   errors  a bad device spec: -EINVAL and the spec named.
 * Skips (77) when this machine has no OpenCL device.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <bvhlab/opencl.h>
#include <bvhlab/trace.h>

#include "../testutil.h"
#include "cl_device.h"
#include "trace/trace_series.h"

#define CHAIN 300

static const int device_traversals[] = {BVHLAB_TRAVERSAL_DEVICE_STACK,
                                        BVHLAB_TRAVERSAL_DEVICE_STACKLESS,
                                        BVHLAB_TRAVERSAL_DEVICE_WIDE8};
/* The CPU traversal whose nodes entered each one's must equal (wide8 on
 * the device counts its compressed nodes: compared by hits only). */
static const int cpu_twins[] = {BVHLAB_TRAVERSAL_STACK, BVHLAB_TRAVERSAL_STACKLESS, -1};

static void grow(bvhlab_node *n, const float *p)
{
	for (int k = 0; k < 3; k++) {
		n->lo[k] = fminf(n->lo[k], p[k]);
		n->hi[k] = fmaxf(n->hi[k], p[k]);
	}
}

static void leaf(bvhlab_node *n, const bvhlab_scene *s, uint32_t slot, uint32_t prim)
{
	*n = (bvhlab_node){{INFINITY, INFINITY, INFINITY}, slot, {-INFINITY, -INFINITY, -INFINITY}, 1};
	for (int v = 0; v < 3; v++)
		grow(n, s->vertices + 3 * s->indices[3 * prim + v]);
}

static void inner(bvhlab_node *nodes, uint32_t i, uint32_t first)
{
	bvhlab_node *n = &nodes[i];
	*n = (bvhlab_node){{INFINITY, INFINITY, INFINITY}, first, {-INFINITY, -INFINITY, -INFINITY}, 0};
	grow(n, nodes[first].lo);
	grow(n, nodes[first].hi);
	grow(n, nodes[first + 1].lo);
	grow(n, nodes[first + 1].hi);
}

/* Each device traversal's hits against the CPU stack traversal's, and its
 * node counts against its CPU twin's (stackless counts its own). */
static void compare(const bvhlab_tree *t, const bvhlab_scene *s, const bvhlab_ray *rays,
                    size_t n, uint32_t want_prim)
{
	bvhlab_hit *ref = calloc(n, sizeof(*ref)), *got = calloc(n, sizeof(*got));
	uint32_t *rn = calloc(n, sizeof(*rn)), *gn = calloc(n, sizeof(*gn));
	bvhlab_trace_timing tm;
	for (int d = 0; d < 3; d++) {
		int k = device_traversals[d], cpu = cpu_twins[d];
		bvhlab_trace_options o = {.traversal = cpu < 0 ? BVHLAB_TRAVERSAL_STACK : cpu,
		                          .threads = 1, .max_repeats = 1};
		CHECK_INT(bvhlab_trace_measure(t, s, rays, n, &o, ref, rn, &tm), 0);
		o.traversal = k;
		CHECK_INT(bvhlab_trace_measure(t, s, rays, n, &o, got, gn, &tm), 0);
		CHECK(tm.repeats == 1 && tm.stats.rays == n && tm.mrays_best > 0);
		size_t hits = 0, differ = 0;
		for (size_t i = 0; i < n; i++) {
			hits += got[i].prim != BVHLAB_NO_HIT;
			differ += memcmp(&ref[i], &got[i], sizeof(ref[i])) != 0 ||
			          (cpu >= 0 && rn[i] != gn[i]);
			if (want_prim != BVHLAB_NO_HIT && got[i].prim != BVHLAB_NO_HIT)
				CHECK_INT(got[i].prim, want_prim);
		}
		printf("%s: %zu rays, %zu hits, %zu differ from the CPU's\n",
		       bvhlab_traversal_name(k), n, hits, differ);
		CHECK(hits > n / 2);
		CHECK_INT(differ, 0);
	}
	free(ref);
	free(got);
	free(rn);
	free(gn);
}

static bvhlab_ray down(float x, float y)
{
	return (bvhlab_ray){{x, y, 1.0f}, 0.0f, {0.01f, 0.02f, -1.0f}, INFINITY};
}

static void ties(void)
{
	float v[] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
	uint32_t idx[] = {0, 1, 2, 0, 1, 2};
	bvhlab_scene s = {.vertices = v, .vertex_count = 3, .indices = idx, .triangle_count = 2};
	uint32_t prim_index[] = {1, 0}; /* the larger id first */
	bvhlab_node nodes[3];
	leaf(&nodes[1], &s, 0, 1);
	leaf(&nodes[2], &s, 1, 0);
	inner(nodes, 0, 1);
	bvhlab_tree t = {.nodes = nodes, .node_count = 3, .prim_index = prim_index, .index_count = 2};
	bvhlab_ray rays[256];
	for (int i = 0; i < 256; i++)
		rays[i] = down((float)(i % 16) / 20.0f + 0.01f, (float)(i / 16) / 40.0f + 0.01f);
	compare(&t, &s, rays, 256, 0);
}

/* Triangle i stands upright in the plane x = i (z from 0 to 1); node 2i
 * (i < CHAIN - 1) is inner with children leaf i and the rest of the chain. */
static void deep(void)
{
	static float v[9 * CHAIN];
	static uint32_t idx[3 * CHAIN], prim_index[CHAIN];
	static bvhlab_node nodes[2 * CHAIN - 1];
	for (uint32_t i = 0; i < CHAIN; i++) {
		float tri[9] = {(float)i, 0, 0, (float)i, 1, 0, (float)i, 0.5f, 1};
		memcpy(v + 9 * i, tri, sizeof(tri));
		for (int k = 0; k < 3; k++)
			idx[3 * i + k] = 3 * i + (uint32_t)k;
		prim_index[i] = i;
	}
	bvhlab_scene s = {.vertices = v, .vertex_count = 3 * CHAIN, .indices = idx,
	                  .triangle_count = CHAIN};
	/* leaves first from the end: the last inner node's children are two leaves */
	leaf(&nodes[2 * CHAIN - 2], &s, CHAIN - 1, CHAIN - 1);
	for (uint32_t i = CHAIN - 1; i-- > 0;) {
		leaf(&nodes[2 * i + 1], &s, i, i);
		inner(nodes, 2 * i, 2 * i + 1);
		/* the chain's next inner node is 2i + 2: already made, or the last leaf */
	}
	bvhlab_tree t = {.nodes = nodes, .node_count = 2 * CHAIN - 1, .prim_index = prim_index,
	                 .index_count = CHAIN};
	bvhlab_ray rays[512];
	for (int i = 0; i < 512; i++) { /* from beyond the far end, walking -x, shallow */
		float y = 0.2f + 0.6f * (float)(i % 32) / 32.0f, z = 0.05f + 0.4f * (float)(i / 32) / 16.0f;
		rays[i] = (bvhlab_ray){{CHAIN + 5.0f, y, z}, 0.0f, {-1.0f, 0.001f, 0.0f}, INFINITY};
	}
	compare(&t, &s, rays, 512, BVHLAB_NO_HIT);
}

static void errors(void)
{
	float v[] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
	uint32_t idx[] = {0, 1, 2}, prim_index[] = {0};
	bvhlab_scene s = {.vertices = v, .vertex_count = 3, .indices = idx, .triangle_count = 1};
	bvhlab_node node;
	leaf(&node, &s, 0, 0);
	bvhlab_tree t = {.nodes = &node, .node_count = 1, .prim_index = prim_index, .index_count = 1};
	bvhlab_ray ray = down(0.2f, 0.2f);
	bvhlab_hit hit;
	bvhlab_trace_timing tm;
	bvhlab_error err = {{0}};
	bvhlab_trace_options o = {.traversal = BVHLAB_TRAVERSAL_DEVICE_STACK, .device = "banana"};
	CHECK_INT(trace_measure(&t, &s, &ray, 1, &o, &hit, NULL, &tm, NULL, 0, &err), -EINVAL);
	CHECK_CONTAINS(err.message, "device 'banana' is not auto, gpu, cpu or P:D");
	o.device = NULL; /* auto: the device main() found */
	/* A tree that does not fit the device is refused by the device layer's
	 * check, with the figures, before any upload. */
	setenv("BVHLAB_CL_MEM_CAP_MB", "0.001", 1);
	CHECK_INT(trace_measure(&t, &s, &ray, 1, &o, &hit, NULL, &tm, NULL, 0, &err), -ENOMEM);
	CHECK_CONTAINS(err.message, "allows in one allocation");
	CHECK_CONTAINS(err.message, "(capped by $BVHLAB_CL_MEM_CAP_MB)");
	unsetenv("BVHLAB_CL_MEM_CAP_MB");
	CHECK_INT(trace_measure(&t, &s, &ray, 1, &o, &hit, NULL, &tm, NULL, 0, &err), 0);
	CHECK_INT(hit.prim, 0);
}

int main(void)
{
	if (!cl_device_present(NULL, 0))
		return TEST_SKIP;
	ties();
	deep();
	errors();
	return test_finish();
}
