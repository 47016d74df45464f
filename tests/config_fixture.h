/*
 * Test fixture for the config tests: a config written to the temporary
 * folder of scene_files.h and loaded from there, and the checks that a
 * load fails with "PATH:LINE:COL: " at a given place. Static inline so
 * that each test takes only what it uses.
 */
#ifndef BVHLAB_CONFIG_FIXTURE_H
#define BVHLAB_CONFIG_FIXTURE_H

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "config/config.h"
#include "scene_files.h"
#include "testutil.h"

#define SCENES "\"scenes\": [ { \"generator\": \"icosphere\" } ]"
#define BUILDERS "\"builders\": [ { \"plugin\": \"sah_seq\" } ]"

static const char *cfg_path; /* tmpdir/c.json, rewritten by every load */

static inline void write_config(const char *data, size_t size)
{
	FILE *f = fopen(cfg_path, "wb");
	CHECK(f && fwrite(data, 1, size, f) == size);
	if (f)
		fclose(f);
}

static inline int load(struct config *cfg, const char *text, bvhlab_error *err)
{
	write_config(text, strlen(text));
	return config_load(cfg, cfg_path, err);
}

/* Line and column of the n-th (0-based) occurrence of needle; ASCII text. */
static inline void position_of(const char *text, const char *needle, int n, int *line, int *col)
{
	const char *at = strstr(text, needle);
	while (at && n-- > 0)
		at = strstr(at + 1, needle);
	*line = 1;
	*col = 1;
	for (const char *p = text; at && p < at; p++) {
		*col = *p == '\n' ? 1 : *col + 1;
		*line += *p == '\n';
	}
	if (!at)
		fprintf(stderr, "test bug: '%s' not in the config\n", needle);
}

/* Loading must fail with a message starting "PATH:LINE:COL: " and holding needle. */
static inline void expect_error_at(const char *file, int caller, const char *text, int line,
                                   int col, const char *needle)
{
	struct config cfg;
	bvhlab_error err = { "" };
	char prefix[256];
	int rc = load(&cfg, text, &err);
	snprintf(prefix, sizeof(prefix), "%s:%d:%d: ", cfg_path, line, col);
	if (getenv("TEST_VERBOSE")) /* to read the messages as users will */
		fprintf(stderr, "%s\n", err.message);
	if (rc != -EINVAL || strncmp(err.message, prefix, strlen(prefix)) != 0 ||
	    !strstr(err.message, needle)) {
		fprintf(stderr, "%s:%d: rc %d; expected \"%s...%s...\"\n     got \"%s\"\n",
		        file, caller, rc, prefix, needle, err.message);
		test_failures++;
	}
	/* A failed load leaves nothing behind to free. */
	CHECK(!cfg.root && !cfg.text && !cfg.scenes && !cfg.builders && !cfg.threads);
	config_finish(&cfg);
}

#define EXPECT_ERROR(text, line, col, needle) \
	expect_error_at(__FILE__, __LINE__, text, line, col, needle)

/* The error is at the n-th occurrence of `at` in the text. */
static inline void expect_error_near(const char *file, int caller, const char *text,
                                     const char *at, int n, const char *needle)
{
	int line, col;
	position_of(text, at, n, &line, &col);
	expect_error_at(file, caller, text, line, col, needle);
}
#define EXPECT_ERROR_AT(text, at, n, needle) \
	expect_error_near(__FILE__, __LINE__, text, at, n, needle)

/* The temporary folder (/tmp/bvhlab-test-TAG-XXXXXX) and the config path in it. */
static inline void config_fixture_open(const char *tag)
{
	tmp_begin(tag);
	cfg_path = tmp_file("c.json");
}

#endif /* BVHLAB_CONFIG_FIXTURE_H */
