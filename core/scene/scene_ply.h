/*
 * PLY header model, shared by the header parser (scene_ply_header.c) and
 * the body reader (scene_ply.c). Private to the core.
 */
#ifndef BVHLAB_CORE_SCENE_PLY_H
#define BVHLAB_CORE_SCENE_PLY_H

#include <stddef.h>
#include <stdint.h>

#include <bvhlab/types.h>

enum ply_format {
	PLY_ASCII,
	PLY_BINARY_LE,
	PLY_BINARY_BE,
};

enum ply_type {
	PLY_NONE, /* count_type of a scalar property */
	PLY_INT8,
	PLY_UINT8,
	PLY_INT16,
	PLY_UINT16,
	PLY_INT32,
	PLY_UINT32,
	PLY_FLOAT32,
	PLY_FLOAT64,
};

struct ply_property {
	char *name;
	enum ply_type type;       /* the scalar's type, or a list's item type */
	enum ply_type count_type; /* a list's length type; PLY_NONE for scalars */
};

struct ply_element {
	char *name;
	uint64_t count;
	struct ply_property *props;
	size_t prop_count, prop_cap;
	size_t line; /* header line that declared it, for error messages */
};

struct ply_header {
	enum ply_format format;
	struct ply_element *elements;
	size_t element_count, element_cap;
	size_t body_offset; /* first byte after end_header's newline */
	size_t body_line;   /* line number of that byte (ASCII bodies) */
	size_t end_line;    /* line of end_header */
};

/* Parses the header of data[0 .. size) (NUL-terminated); errors "PATH:LINE: ...". */
int ply_header_parse(const char *path, const char *data, size_t size, struct ply_header *header,
                     bvhlab_error *err);

void ply_header_free(struct ply_header *header);

/* Bytes of one binary value; 0 for PLY_NONE. */
size_t ply_type_size(enum ply_type type);

static inline int ply_type_is_integer(enum ply_type type)
{
	return type >= PLY_INT8 && type <= PLY_UINT32;
}

/* The element's property named `name`, or -1. */
long ply_find_property(const struct ply_element *element, const char *name);

#endif /* BVHLAB_CORE_SCENE_PLY_H */
