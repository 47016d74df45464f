/* placeholder */
typedef int bvhlab_placeholder_kernel;
