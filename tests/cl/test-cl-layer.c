/*
 * The OpenCL device layer (include/bvhlab/opencl.h): device specs, kernel
 * build errors with the compiler's log, profiled event times, release on
 * every path. `test-cl-layer --no-platform` runs with OCL_ICD_VENDORS at an
 * empty folder and checks the "no OpenCL platform" message.
 * Skips (77) when the machine has no OpenCL device.
 */
#include <bvhlab/opencl.h>

#include "../testutil.h"

static const char good_src[] =
	"__kernel void twice(__global float *x) {\n"
	"  size_t i = get_global_id(0);\n"
	"  x[i] = 2.0f * x[i];\n"
	"}\n";

static void check_specs(void)
{
	bvhlab_cl cl = {0};
	char err[BVHLAB_CL_ERROR_SIZE];
	const char *bad[] = {"banana", "0:", ":0", "0:0x", "GPU", "", "1:-1"};
	for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
		err[0] = '\0';
		CHECK_INT(bvhlab_cl_init(&cl, bad[i], err, sizeof err), -EINVAL);
		char want[64];
		snprintf(want, sizeof want, "device '%s' is not auto, gpu, cpu or P:D", bad[i]);
		CHECK_CONTAINS(err, want);
		CHECK(cl.context == NULL && cl.queue == NULL);
	}
	/* Well formed, but no such device. */
	CHECK_INT(bvhlab_cl_init(&cl, "9:0", err, sizeof err), -ENODEV);
	CHECK_CONTAINS(err, "device '9:0': no such OpenCL device");
	bvhlab_cl_finish(&cl);
	bvhlab_cl_finish(&cl);
}

/* A kernel that does not compile: -EINVAL, the device named, the log
 * quoted (it names the undeclared identifier), and cut when long. */
static void check_build_error(bvhlab_cl *cl)
{
	char err[BVHLAB_CL_ERROR_SIZE], small[200];
	cl_program prog = NULL;
	const char *src = "__kernel void k(__global int *x) { x[0] = no_such_name_42; }\n";
	CHECK_INT(bvhlab_cl_program(cl, src, 0, NULL, &prog, err, sizeof err), -EINVAL);
	CHECK(prog == NULL);
	CHECK_CONTAINS(err, "cl: kernel build failed (CL_BUILD_PROGRAM_FAILURE) on ");
	CHECK_CONTAINS(err, cl->name);
	CHECK_CONTAINS(err, "no_such_name_42");
	CHECK(strlen(err) < sizeof err);

	CHECK_INT(bvhlab_cl_program(cl, src, 0, NULL, &prog, small, sizeof small), -EINVAL);
	CHECK_CONTAINS(small, "cl: kernel build failed");
	CHECK_CONTAINS(small, "[compiler log truncated]");
	CHECK(strlen(small) == sizeof small - 1);

	CHECK_INT(bvhlab_cl_program(cl, good_src, 0, "-no-such-option", &prog, err, sizeof err),
		-EINVAL);
	CHECK_CONTAINS(err, "cl: kernel build failed");
	bvhlab_cl_release_program(&prog);
}

/* A kernel runs and its event has a profiled time. */
static void check_run(bvhlab_cl *cl)
{
	char err[BVHLAB_CL_ERROR_SIZE];
	cl_program prog = NULL;
	cl_kernel k = NULL;
	cl_mem buf = NULL;
	cl_event ev = NULL;
	cl_int rc = CL_SUCCESS;
	float x[256];
	size_t n = 256;
	for (size_t i = 0; i < n; i++)
		x[i] = (float)i;
	CHECK_INT(bvhlab_cl_program(cl, good_src, sizeof good_src - 1,
		"-cl-fp32-correctly-rounded-divide-sqrt", &prog, err, sizeof err), 0);
	CHECK_INT(bvhlab_cl_kernel(prog, "nope", &k, err, sizeof err), -EIO);
	CHECK_CONTAINS(err, "cl: kernel 'nope': CL_INVALID_KERNEL_NAME");
	CHECK_INT(bvhlab_cl_kernel(prog, "twice", &k, err, sizeof err), 0);
	buf = clCreateBuffer(cl->context, CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, sizeof x, x, &rc);
	CHECK_INT(rc, CL_SUCCESS);
	CHECK_INT(clSetKernelArg(k, 0, sizeof buf, &buf), CL_SUCCESS);
	CHECK_INT(clEnqueueNDRangeKernel(cl->queue, k, 1, NULL, &n, NULL, 0, NULL, &ev), CL_SUCCESS);
	CHECK_INT(clEnqueueReadBuffer(cl->queue, buf, CL_TRUE, 0, sizeof x, x, 0, NULL, NULL),
		CL_SUCCESS);
	CHECK(x[255] == 510.0f && x[1] == 2.0f);
	CHECK(bvhlab_cl_event_ms(ev) >= 0.0);
	CHECK(bvhlab_cl_event_ms(NULL) < 0.0);
	bvhlab_cl_release_event(&ev);
	bvhlab_cl_release_mem(&buf);
	bvhlab_cl_release_kernel(&k);
	bvhlab_cl_release_program(&prog);
	CHECK(!ev && !buf && !k && !prog);
}

static int no_platform(void)
{
	bvhlab_cl cl = {0};
	char err[BVHLAB_CL_ERROR_SIZE];
	CHECK_INT(bvhlab_cl_init(&cl, "auto", err, sizeof err), -ENODEV);
	CHECK_CONTAINS(err, "no OpenCL platform found");
	CHECK_CONTAINS(err, "pocl-opencl-icd");
	bvhlab_cl_finish(&cl);
	return test_finish();
}

int main(int argc, char **argv)
{
	bvhlab_cl cl = {0};
	char err[BVHLAB_CL_ERROR_SIZE];
	if (argc > 1 && !strcmp(argv[1], "--no-platform"))
		return no_platform();
	bvhlab_cl_finish(&cl); /* zeroed: nothing to release */
	if (bvhlab_cl_init(&cl, "auto", err, sizeof err) < 0) {
		printf("skip: %s\n", err);
		return TEST_SKIP;
	}
	CHECK(cl.context && cl.queue && cl.name[0]);
	printf("device %u:%u %s\n", cl.platform_index, cl.device_index, cl.name);
	check_specs();
	check_build_error(&cl);
	check_run(&cl);
	bvhlab_cl_finish(&cl);
	CHECK(cl.context == NULL);
	return test_finish();
}
