#include <bvhlab/builder.h>
BVHLAB_PLUGIN_ENTRY
{
	(void)host_abi_major;
	return 0;
}
