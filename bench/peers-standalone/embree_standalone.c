/*
 * Embree 3 alone: rtcBuildBVH timed as Embree's own bvh_builder tutorial
 * times it: one device ("threads=N"), one RTCBVH made before the loop and
 * reused by every build (its allocator keeps its blocks), the primitive
 * array refilled from a pristine copy before each build, untimed (Embree
 * reorders it and, for high, splits into its spare capacity), and only
 * rtcBuildBVH timed. The build arguments are the plugin's defaults (binary
 * nodes, depth 64, leaves of 1 to 8, costs 1, high's room 1.2 x the
 * triangles). --callbacks says which callbacks build the tree:
 * "tutorial" (the default), the tutorial's kind: inner nodes with their
 * children's boxes, leaves with their ids, high splitting a reference by
 * cutting its box at the plane; "plugin", the embree plugin's own
 * (plugins/embree/embree_tree.c: high clips the triangle exactly), so the
 * callbacks' share of the plugin's time shows apart from the harness's.
 */
#include <embree3/rtcore.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "embree_internal.h"
#include "standalone.h"

#define MAX_DEPTH 64
#define MAX_LEAF 8
#define SPLIT_FACTOR 1.2

typedef struct inner {
	struct RTCBounds bounds[2];
	void *child[2];
} inner;

typedef struct leaf {
	unsigned count;
	struct RTCBounds bounds;
	unsigned prim[];
} leaf;

typedef struct job {
	RTCBVH bvh;
	struct RTCBuildArguments args;
	struct RTCBuildPrimitive *prims, *pristine;
	size_t count, capacity;
	const bvhlab_scene *scene;
	bvhlab_prims input;   /* what the plugin's callbacks read */
	embree_job plugin;    /* their userPtr */
} job;

static void *create_node(RTCThreadLocalAllocator alloc, unsigned int n, void *user)
{
	(void)n, (void)user;
	inner *node = rtcThreadLocalAlloc(alloc, sizeof(inner), 16);
	node->child[0] = node->child[1] = NULL;
	return node;
}

static void set_children(void *node, void **children, unsigned int n, void *user)
{
	(void)user;
	for (unsigned k = 0; k < n && k < 2; k++)
		((inner *)node)->child[k] = children[k];
}

static void set_bounds(void *node, const struct RTCBounds **bounds, unsigned int n, void *user)
{
	(void)user;
	for (unsigned k = 0; k < n && k < 2; k++)
		((inner *)node)->bounds[k] = *bounds[k];
}

static void *create_leaf(RTCThreadLocalAllocator alloc, const struct RTCBuildPrimitive *prims,
                         size_t n, void *user)
{
	(void)user;
	leaf *l = rtcThreadLocalAlloc(alloc, sizeof(leaf) + n * sizeof(unsigned), 16);
	l->count = (unsigned)n;
	l->bounds = *(const struct RTCBounds *)&prims[0];
	for (size_t k = 0; k < n; k++) {
		const float *lo = &prims[k].lower_x, *hi = &prims[k].upper_x;
		for (int a = 0; a < 3; a++) {
			(&l->bounds.lower_x)[a] = fminf((&l->bounds.lower_x)[a], lo[a]);
			(&l->bounds.upper_x)[a] = fmaxf((&l->bounds.upper_x)[a], hi[a]);
		}
		l->prim[k] = prims[k].primID;
	}
	return l;
}

static void split_box(const struct RTCBuildPrimitive *prim, unsigned int dim, float pos,
                      struct RTCBounds *left, struct RTCBounds *right, void *user)
{
	(void)user;
	*left = *right = *(const struct RTCBounds *)prim;
	(&left->upper_x)[dim] = pos;
	(&right->lower_x)[dim] = pos;
}

static int fill_pristine(job *j)
{
	const bvhlab_scene *s = j->scene;
	size_t bytes = j->capacity * sizeof(struct RTCBuildPrimitive);
	j->pristine = aligned_alloc(32, (bytes + 31) & ~(size_t)31);
	j->prims = aligned_alloc(32, (bytes + 31) & ~(size_t)31);
	if (!j->pristine || !j->prims)
		return -1;
	for (uint32_t t = 0; t < s->triangle_count; t++) {
		struct RTCBuildPrimitive *p = &j->pristine[t];
		const uint32_t *tri = &s->indices[3 * (size_t)t];
		for (int a = 0; a < 3; a++) {
			float lo = INFINITY, hi = -INFINITY;
			for (int v = 0; v < 3; v++) {
				lo = fminf(lo, s->vertices[3 * (size_t)tri[v] + a]);
				hi = fmaxf(hi, s->vertices[3 * (size_t)tri[v] + a]);
			}
			(&p->lower_x)[a] = lo, (&p->upper_x)[a] = hi;
		}
		p->geomID = 0, p->primID = t;
	}
	return 0;
}

static void set_args(job *j, const sa_args *a)
{
	struct RTCBuildArguments *g = &j->args;
	bool high = strcmp(a->variant, "high") == 0;
	*g = rtcDefaultBuildArguments();
	g->buildQuality = high ? RTC_BUILD_QUALITY_HIGH
	                  : strcmp(a->variant, "low") == 0 ? RTC_BUILD_QUALITY_LOW
	                                                    : RTC_BUILD_QUALITY_MEDIUM;
	g->maxBranchingFactor = 2;
	g->maxDepth = MAX_DEPTH;
	g->minLeafSize = 1;
	g->maxLeafSize = MAX_LEAF;
	g->bvh = j->bvh;
	g->primitives = j->prims;
	g->primitiveCount = j->count;
	g->primitiveArrayCapacity = j->capacity;
	if (strcmp(a->callbacks, "plugin") == 0) {
		j->plugin.input = &j->input.input;
		embree_set_callbacks(g, high);
		g->userPtr = &j->plugin;
		return;
	}
	g->createNode = create_node;
	g->setNodeChildren = set_children;
	g->setNodeBounds = set_bounds;
	g->createLeaf = create_leaf;
	g->splitPrimitive = high ? split_box : NULL;
	g->userPtr = j;
}

static int prepare(void *user)
{
	job *j = user;
	memcpy(j->prims, j->pristine, j->count * sizeof(*j->prims));
	j->args.primitiveCount = j->count;
	return 0;
}

static int build(void *user)
{
	job *j = user;
	return rtcBuildBVH(&j->args) ? 0 : -EIO;
}

int main(int argc, char **argv)
{
	sa_args a;
	bvhlab_scene *scene;
	int rc = sa_start(argc, argv, "low|medium|high", "medium", &a, &scene);
	if (rc)
		return rc;
	if (a.input_each >= 0) { /* its array is refilled before every build anyway */
		fprintf(stderr, "embree-standalone: --input is tinybvh-standalone's only\n");
		bvhlab_scene_destroy(scene);
		return 2;
	}
	if (!a.callbacks)
		a.callbacks = "tutorial";
	char config[64];
	snprintf(config, sizeof(config), "threads=%u,verbose=0", a.threads);
	RTCDevice dev = rtcNewDevice(config);
	job j = {.scene = scene, .count = scene->triangle_count};
	j.capacity = strcmp(a.variant, "high") == 0 ? (size_t)ceil(SPLIT_FACTOR * j.count) : j.count;
	bvhlab_error err;
	rc = dev && (j.bvh = rtcNewBVH(dev)) && fill_pristine(&j) == 0 &&
	         bvhlab_prims_init(&j.input, scene, &err) == 0 ? 0 : -1;
	if (rc == 0) {
		set_args(&j, &a);
		rc = sa_time("embree", &a, prepare, build, &j);
	} else {
		fprintf(stderr, "embree: no device, BVH or memory for %zu primitives\n", j.capacity);
	}
	if (j.bvh)
		rtcReleaseBVH(j.bvh);
	if (dev)
		rtcReleaseDevice(dev);
	free(j.prims), free(j.pristine);
	bvhlab_prims_finish(&j.input);
	bvhlab_scene_destroy(scene);
	return rc < 0 ? 1 : 0;
}
