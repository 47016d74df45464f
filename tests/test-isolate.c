/*
 * Isolated calls: a report comes back whole (also one larger than a pipe's
 * buffer), and every way a child can end early is told apart: a signal,
 * an exit before reporting, a hang past the timeout, a memory limit.
 */
#include <errno.h>
#include <signal.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "harness/isolate.h"
#include "testutil.h"

#define BIG (1u << 20) /* 16 pipe buffers */

static int parent_value = 7;

static void fill(void *arg, void *report, size_t size)
{
	unsigned char *p = report;
	(void)arg;
	parent_value = 99; /* the child's copy only */
	for (size_t i = 0; i < size; i++)
		p[i] = (unsigned char)(i * 31 + 5);
}

static void die_by_signal(void *arg, void *report, size_t size)
{
	(void)report;
	(void)size;
	raise(*(int *)arg);
}

static void exit_early(void *arg, void *report, size_t size)
{
	(void)arg;
	(void)report;
	(void)size;
	exit(3);
}

static void hang(void *arg, void *report, size_t size)
{
	(void)arg;
	(void)report;
	(void)size;
	for (;;)
		pause();
}

/* Reports whether a 64 MB allocation succeeded under the limit. */
static void allocate(void *arg, void *report, size_t size)
{
	(void)arg;
	(void)size;
	char *p = malloc(64u << 20);
	*(int *)report = p != NULL;
	free(p);
}

static const struct isolate_limits quick = {.timeout_s = 30};

static void test_report(void)
{
	unsigned char *buf = calloc(1, BIG);
	char why[256] = "";
	bool same = true;
	CHECK_INT(isolate_call(fill, NULL, buf, BIG, &quick, why, sizeof(why)), ISOLATE_REPORTED);
	for (size_t i = 0; i < BIG; i++)
		same = same && buf[i] == (unsigned char)(i * 31 + 5);
	CHECK(same);
	CHECK_INT(parent_value, 7);
	free(buf);
}

static void test_endings(void)
{
	char why[256] = "";
	int report = 0, sig = SIGUSR1;
	CHECK_INT(isolate_call(die_by_signal, &sig, &report, sizeof(report), &quick, why,
	                       sizeof(why)), ISOLATE_CRASHED);
	CHECK_CONTAINS(why, "killed by SIGUSR1");
	sig = SIGKILL;
	CHECK_INT(isolate_call(die_by_signal, &sig, &report, sizeof(report), &quick, why,
	                       sizeof(why)), ISOLATE_CRASHED);
	CHECK_CONTAINS(why, "killed by SIGKILL (out of memory?)");
	CHECK_INT(isolate_call(exit_early, NULL, &report, sizeof(report), &quick, why,
	                       sizeof(why)), ISOLATE_CRASHED);
	CHECK_CONTAINS(why, "exited with status 3 before reporting");

	struct isolate_limits brief = {.timeout_s = 0.2};
	CHECK_INT(isolate_call(hang, NULL, &report, sizeof(report), &brief, why, sizeof(why)),
	          ISOLATE_TIMEOUT);
	CHECK_CONTAINS(why, "no result after 0.2 s (timeout_s); killed");
	/* Every child was reaped. */
	CHECK(waitpid(-1, NULL, WNOHANG) == -1 && errno == ECHILD);
}

static void test_memory_limit(void)
{
	char why[256] = "";
	int ok = -1;
	struct isolate_limits roomy = {.timeout_s = 30};
	CHECK_INT(isolate_call(allocate, NULL, &ok, sizeof(ok), &roomy, why, sizeof(why)),
	          ISOLATE_REPORTED);
	CHECK_INT(ok, 1);
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
	/* Sanitizers reserve terabytes of address space: any RLIMIT_AS starves them. */
	printf("memory limit check skipped under a sanitizer\n");
#else
	struct isolate_limits tight = {.timeout_s = 30, .memory_bytes = 32u << 20};
	int r = isolate_call(allocate, NULL, &ok, sizeof(ok), &tight, why, sizeof(why));
	CHECK(r == ISOLATE_CRASHED || (r == ISOLATE_REPORTED && ok == 0));
#endif
}

static void test_signal_names(void)
{
	char buf[32];
	CHECK(strcmp(isolate_signal_name(SIGSEGV, buf, sizeof(buf)), "SIGSEGV") == 0);
	CHECK(strcmp(isolate_signal_name(SIGABRT, buf, sizeof(buf)), "SIGABRT") == 0);
	CHECK(strcmp(isolate_signal_name(SIGRTMIN + 3, buf, sizeof(buf)), buf) == 0);
	CHECK_CONTAINS(buf, "signal ");
}

int main(void)
{
	test_report();
	test_endings();
	test_memory_limit();
	test_signal_names();
	return test_finish();
}
