/*
 * bvhlab — the former name of trace.h (camera, rays, batch traversal), kept
 * so code written against it still compiles. New code includes trace.h.
 */
#ifndef BVHLAB_RAYS_H
#define BVHLAB_RAYS_H

#include "trace.h"

#endif /* BVHLAB_RAYS_H */
