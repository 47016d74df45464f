/* placeholder: being written */
typedef int bvhlab_placeholder_options;
