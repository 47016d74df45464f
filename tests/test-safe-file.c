/*
 * core/output/safe_file.c: files created anew (a planted symlink is
 * replaced, never followed), atomic replacement, moving old results aside
 * without overwriting, the output folders a fresh sweep may claim, and
 * temporary files written in parts (replaced whole, none left on failure).
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "output/safe_file.h"
#include "testutil.h"

static char dir[] = "/tmp/bvhlab-safe-XXXXXX";

static void put(const char *name, const char *text)
{
	char path[256];
	snprintf(path, sizeof(path), "%s/%s", dir, name);
	FILE *f = fopen(path, "w");
	fputs(text, f);
	fclose(f);
}

static char *get(const char *name)
{
	static char buf[256];
	char path[256];
	snprintf(path, sizeof(path), "%s/%s", dir, name);
	FILE *f = fopen(path, "r");
	if (!f)
		return NULL;
	size_t n = fread(buf, 1, sizeof(buf) - 1, f);
	buf[n] = '\0';
	fclose(f);
	return buf;
}

static void test_no_follow(void)
{
	char link[256], target[256];
	bvhlab_error err = {{0}};
	put("precious", "keep");
	snprintf(target, sizeof(target), "%s/precious", dir);
	snprintf(link, sizeof(link), "%s/.out.txt.tmp", dir);
	CHECK_INT(symlink(target, link), 0);
	CHECK_INT(safe_write_file(dir, "out.txt", "new", 3, &err), 0);
	CHECK_CONTAINS(get("precious"), "keep");
	CHECK_CONTAINS(get("out.txt"), "new");
	struct stat st;
	CHECK(lstat(link, &st) < 0 && errno == ENOENT); /* renamed away */
	snprintf(link, sizeof(link), "%s/raw", dir);
	CHECK_INT(symlink(target, link), 0);
	int fd = safe_create(link);
	CHECK(fd >= 0);
	if (fd >= 0)
		close(fd);
	CHECK(lstat(link, &st) == 0 && S_ISREG(st.st_mode) && st.st_size == 0);
	CHECK_CONTAINS(get("precious"), "keep");
}

static void test_claim(void)
{
	bvhlab_error err = {{0}};
	CHECK_INT(safe_claim_output(dir, false, &err), 0); /* no results.json yet */
	put("results.json", "old");
	put("report.md", "old report");
	put("results.json.1", "older");
	CHECK_INT(safe_claim_output(dir, false, &err), -EEXIST);
	CHECK_CONTAINS(err.message, "already holds a results.json: --resume");
	CHECK_CONTAINS(err.message, "--force");
	CHECK_CONTAINS(get("results.json"), "old");
	CHECK_INT(safe_claim_output(dir, true, &err), 0);
	CHECK(get("results.json") == NULL);
	CHECK_CONTAINS(get("results.json.1"), "older");
	CHECK_CONTAINS(get("results.json.2"), "old");
	CHECK_CONTAINS(get("report.md.2"), "old report");
	CHECK_INT(safe_claim_output("/", false, &err), -EINVAL);
	CHECK_CONTAINS(err.message, "output folder / is the file system root");
	CHECK_INT(safe_claim_output("/tmp/..", true, &err), -EINVAL);
}

static void test_parts(void)
{
	char path[256];
	const struct safe_part parts[] = {{"bvh", 3}, {"", 0}, {"lab", 3}};
	put("parts", "an older and longer text");
	snprintf(path, sizeof(path), "%s/parts", dir);
	CHECK_INT(safe_write_parts(path, parts, 3), 0);
	CHECK(get("parts") && strcmp(get("parts"), "bvhlab") == 0);
	snprintf(path, sizeof(path), "%s/no-such-folder/parts", dir);
	CHECK_INT(safe_write_parts(path, parts, 3), -ENOENT);
	CHECK(!get("no-such-folder/parts"));
}

int main(void)
{
	if (!mkdtemp(dir))
		return 1;
	test_no_follow();
	test_claim();
	test_parts();
	char cmd[128];
	snprintf(cmd, sizeof(cmd), "rm -rf '%s'", dir);
	if (!test_failures && system(cmd) != 0)
		test_failures++;
	return test_finish();
}
