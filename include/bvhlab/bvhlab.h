/*
 * bvhlab — umbrella header for the core library: every public header.
 *
 * Plugins include only <bvhlab/builder.h> (and <bvhlab/aabb.h> for box
 * helpers); programs that drive builders (the bvhlab command, tests, other
 * tools) include this. Each header holds one concept:
 *   types.h    boxes, nodes, rays, hits, errors (plain data, fixed layouts)
 *   aabb.h     box helpers (header-only)
 *   clip.h     clipping polygons by axis planes (header-only; spatial splits)
 *   builder.h  the plugin ABI
 *   scene.h    triangle scenes: loading, generators, per-primitive data
 *   tree.h     the tree, validation, metrics, canonical compare
 *   trace.h    traversals (stack, stackless, wide), cameras and rays, timed batches
 *   epo.h      end-point overlap, the sampled tree metric beside SAH
 *   host.h     loading plugins, their options, running a build
 *   machine.h  what threads = 0 means, thread pinning
 * All are C11 and C++17 (extern "C").
 */
#ifndef BVHLAB_BVHLAB_H
#define BVHLAB_BVHLAB_H

#include "aabb.h"
#include "builder.h"
#include "clip.h"
#include "epo.h"
#include "host.h"
#include "machine.h"
#include "scene.h"
#include "trace.h"
#include "tree.h"
#include "types.h"

BVHLAB_BEGIN_DECLS

/* The library's version and the commit it was built from, e.g.
 * "0.1.0+2f1cbf6a0b1c" ("-dirty" after it: with uncommitted changes;
 * "+unknown": built outside git). */
const char *bvhlab_version(void);

BVHLAB_END_DECLS

#endif /* BVHLAB_BVHLAB_H */
