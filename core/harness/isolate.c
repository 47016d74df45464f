/*
 * Isolated calls: fork, a pipe for the report, and a parent that waits
 * with a deadline. The parent never trusts the child: a short report is a
 * crash, silence past the deadline is a timeout, and either way the child
 * is reaped so no zombie or stray process outlives the run.
 */
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <poll.h>
#include <signal.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "harness/isolate.h"
#include "util/util.h"

/* The most of a child's stderr passed on, from its end; and the most of
 * it quoted in the message of a child that died. */
#define STDERR_RELAY_MAX (64 * 1024)
#define STDERR_TAIL_MAX 300

/* Exit statuses of the child's own failures, outside what plugins use. */
#define EXIT_ORPHANED 120
#define EXIT_PIPE_BROKEN 121

const char *isolate_signal_name(int sig, char *buf, size_t size)
{
	static const struct {
		int sig;
		const char *name;
	} names[] = {
		{SIGSEGV, "SIGSEGV"}, {SIGABRT, "SIGABRT"}, {SIGBUS, "SIGBUS"},   {SIGFPE, "SIGFPE"},
		{SIGILL, "SIGILL"},   {SIGKILL, "SIGKILL"}, {SIGTERM, "SIGTERM"}, {SIGINT, "SIGINT"},
		{SIGHUP, "SIGHUP"},   {SIGPIPE, "SIGPIPE"}, {SIGTRAP, "SIGTRAP"}, {SIGSYS, "SIGSYS"},
		{SIGQUIT, "SIGQUIT"}, {SIGXCPU, "SIGXCPU"}, {SIGXFSZ, "SIGXFSZ"}, {SIGALRM, "SIGALRM"},
		{SIGUSR1, "SIGUSR1"}, {SIGUSR2, "SIGUSR2"},
	};
	for (size_t k = 0; k < sizeof(names) / sizeof(names[0]); k++)
		if (names[k].sig == sig)
			return names[k].name;
	snprintf(buf, size, "signal %d", sig);
	return buf;
}

static void write_all(int fd, const char *p, size_t left)
{
	while (left > 0) {
		ssize_t n = write(fd, p, left);
		if (n < 0 && errno == EINTR)
			continue;
		if (n <= 0)
			_exit(EXIT_PIPE_BROKEN);
		p += n;
		left -= (size_t)n;
	}
}

/*
 * A plugin that calls exit() would run the parent's exit handlers in the
 * child, and some libraries' finalizers (log4cplus, loaded with
 * OpenImageIO) wait for threads that only exist in the parent: the child
 * would hang. Registered last, this runs first and leaves with the status.
 */
static void exit_now(int status, void *arg)
{
	(void)arg;
	_exit(status);
}

/* _exit only: the parent's atexit handlers and stdio buffers are not ours. */
static void child(int fd, int errfd, pid_t parent, isolate_work work, void *arg, void *report,
                  size_t size, const struct isolate_limits *limits)
{
	/* A killed sweep must not leave its runs behind, spinning. */
	prctl(PR_SET_PDEATHSIG, SIGKILL);
	if (getppid() != parent)
		_exit(EXIT_ORPHANED);
	if (errfd >= 0) /* the parent relays it, and quotes its end if we die */
		dup2(errfd, STDERR_FILENO);
	on_exit(exit_now, NULL);
	if (limits->memory_bytes) {
		struct rlimit rl = {.rlim_cur = limits->memory_bytes, .rlim_max = limits->memory_bytes};
		setrlimit(RLIMIT_AS, &rl);
	}
	work(arg, report, size);
	write_all(fd, report, size);
	_exit(0);
}

static int poll_ms(double deadline)
{
	double left = deadline - util_now();
	if (left <= 0)
		return 0;
	return left * 1e3 >= INT_MAX - 1 ? INT_MAX : (int)(left * 1e3) + 1;
}

/* Bytes of the report read before EOF or the deadline; -ETIMEDOUT at the deadline. */
static ssize_t read_report(int fd, char *buf, size_t size, double deadline)
{
	size_t got = 0;
	while (got < size) {
		struct pollfd p = {.fd = fd, .events = POLLIN};
		int ms = poll_ms(deadline);
		if (ms == 0)
			return -ETIMEDOUT;
		int r = poll(&p, 1, ms);
		if (r < 0 && errno != EINTR)
			return -errno;
		if (r <= 0)
			continue;
		ssize_t n = read(fd, buf + got, size - got);
		if (n < 0 && errno != EINTR && errno != EAGAIN)
			return -errno;
		if (n == 0)
			break;
		got += n > 0 ? (size_t)n : 0;
	}
	return (ssize_t)got;
}

static void kill_and_reap(pid_t pid, int *status)
{
	kill(pid, SIGKILL);
	while (waitpid(pid, status, 0) < 0 && errno == EINTR)
		;
}

/*
 * Reaps the child. After its report or EOF it is normally on its way out;
 * one that closed the pipe and went on is killed at the deadline.
 */
static int reap(pid_t pid, double deadline, int *status)
{
	const struct timespec pause = {.tv_nsec = 1000000};
	for (;;) {
		pid_t r = waitpid(pid, status, WNOHANG);
		if (r == pid)
			return 0;
		if (r < 0 && errno != EINTR) {
			*status = 0;
			return 0; /* not ours to reap (SIGCHLD ignored): trust the report */
		}
		if (util_now() >= deadline) {
			kill_and_reap(pid, status);
			return -ETIMEDOUT;
		}
		nanosleep(&pause, NULL);
	}
}

static void describe_death(int status, char *why, size_t size)
{
	char buf[32];
	if (WIFSIGNALED(status)) {
		int sig = WTERMSIG(status);
		/* We only send SIGKILL at the deadline; otherwise it is usually the OOM killer. */
		if (sig == SIGKILL)
			snprintf(why, size, "killed by SIGKILL (out of memory?)");
		else
			snprintf(why, size, "killed by %s (%s)", isolate_signal_name(sig, buf, sizeof(buf)),
			         strsignal(sig));
	} else if (WIFEXITED(status)) {
		snprintf(why, size, "exited with status %d before reporting", WEXITSTATUS(status));
	} else {
		snprintf(why, size, "ended before reporting (wait status %#x)", (unsigned)status);
	}
}

/* The parent's side: the report, then the child's end. */
static int await(pid_t pid, int fd, void *report, size_t size, double timeout_s, char *why,
                 size_t why_size)
{
	double deadline = util_now() + timeout_s;
	int status = 0;
	ssize_t got = read_report(fd, report, size, deadline);
	if (got == -ETIMEDOUT) {
		kill_and_reap(pid, &status);
		snprintf(why, why_size, "no result after %g s (timeout_s); killed", timeout_s);
		return ISOLATE_TIMEOUT;
	}
	if (got < 0) {
		kill_and_reap(pid, &status);
		snprintf(why, why_size, "reading the child's report: %s", strerror((int)-got));
		return ISOLATE_CRASHED;
	}
	bool lingered = reap(pid, deadline, &status) == -ETIMEDOUT;
	if ((size_t)got == size)
		return ISOLATE_REPORTED; /* whatever it did after reporting */
	if (lingered) {
		snprintf(why, why_size, "closed its report and ran past timeout_s (%g s); killed",
		         timeout_s);
		return ISOLATE_TIMEOUT;
	}
	describe_death(status, why, why_size);
	return ISOLATE_CRASHED;
}

/* The end of what the child wrote to stderr, on one line, after why:
 * what libstdc++, a sanitizer or the plugin said before it died. */
static void quote_tail(const char *text, size_t n, char *why, size_t why_size)
{
	while (n > 0 && (text[n - 1] == '\n' || text[n - 1] == ' '))
		n--;
	size_t from = n > STDERR_TAIL_MAX ? n - STDERR_TAIL_MAX : 0;
	if (n == 0)
		return;
	size_t used = strlen(why);
	used += (size_t)snprintf(why + used, why_size > used ? why_size - used : 0,
	                         "; its stderr ended: %s", from ? "..." : "");
	for (size_t k = from; k < n && used + 1 < why_size; k++) {
		bool space = text[k] == '\n' || text[k] == '\t' || text[k] == ' ';
		if (!space || why[used - 1] != ' ') /* lines and their indents: one space */
			why[used++] = space ? ' ' : text[k];
	}
	if (used < why_size)
		why[used] = '\0';
}

/* Passes the child's stderr on to ours (its last STDERR_RELAY_MAX bytes)
 * and, when it did not report, quotes its end in why. */
static void relay_stderr(int errfd, bool died, char *why, size_t why_size)
{
	static char buf[STDERR_RELAY_MAX];
	off_t end = lseek(errfd, 0, SEEK_END);
	if (end <= 0)
		return;
	off_t from = end > STDERR_RELAY_MAX ? end - STDERR_RELAY_MAX : 0;
	ssize_t n = pread(errfd, buf, (size_t)(end - from), from);
	if (n <= 0)
		return;
	for (ssize_t done = 0, w; done < n; done += w)
		if ((w = write(STDERR_FILENO, buf + done, (size_t)(n - done))) <= 0)
			break;
	if (died)
		quote_tail(buf, (size_t)n, why, why_size);
}

int isolate_call(isolate_work work, void *arg, void *report, size_t size,
                 const struct isolate_limits *limits, char *why, size_t why_size)
{
	int fds[2];
	if (pipe2(fds, O_CLOEXEC) < 0) {
		int e = errno;
		snprintf(why, why_size, "cannot create a pipe: %s", strerror(e));
		return -e;
	}
	/* The child's stderr, kept (in memory) to quote if it dies; -1: not kept. */
	int errfd = memfd_create("bvhlab-child-stderr", MFD_CLOEXEC);
	/* Buffered output would be written twice, once by each process. */
	fflush(stdout);
	fflush(stderr);
	pid_t parent = getpid();
	pid_t pid = fork();
	if (pid == 0) {
		close(fds[0]);
		child(fds[1], errfd, parent, work, arg, report, size, limits);
	}
	close(fds[1]);
	if (pid < 0) {
		int e = errno;
		close(fds[0]);
		if (errfd >= 0)
			close(errfd);
		snprintf(why, why_size, "cannot fork: %s", strerror(e));
		return -e;
	}
	int r = await(pid, fds[0], report, size, limits->timeout_s, why, why_size);
	close(fds[0]);
	if (errfd >= 0) {
		relay_stderr(errfd, r == ISOLATE_CRASHED || r == ISOLATE_TIMEOUT, why, why_size);
		close(errfd);
	}
	return r;
}
