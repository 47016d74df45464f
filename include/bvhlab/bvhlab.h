/*
 * bvhlab — umbrella header for the core library.
 *
 * Plugins include only <bvhlab/builder.h>; programs that drive builders
 * (the bvhlab command, tests, other tools) include this.
 */
#ifndef BVHLAB_BVHLAB_H
#define BVHLAB_BVHLAB_H

#include "builder.h"
#include "plugin.h"
#include "scene.h"
#include "tree.h"
#include "types.h"

/* The library's version, e.g. "0.1.0". */
const char *bvhlab_version(void);

#endif /* BVHLAB_BVHLAB_H */
