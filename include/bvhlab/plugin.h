/*
 * bvhlab — the former name of host.h (plugin loading, options, builds) plus
 * machine.h (thread count, pinning), kept so code written against it still
 * compiles. New code includes host.h and machine.h, or bvhlab.h.
 */
#ifndef BVHLAB_PLUGIN_H
#define BVHLAB_PLUGIN_H

#include "host.h"
#include "machine.h"

#endif /* BVHLAB_PLUGIN_H */
