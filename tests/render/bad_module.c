// A plugin that is wrong in one way (chosen at compile time) so the loader's
// refusals can be tested by name.
#include "st_module.h"
#include <stdlib.h>

static void *create(st_world *w, const double *p, st_err *err) {
    return malloc(1);
}
static void destroy(void *s) {
    free(s);
}
static int num_passes(void *s) {
    return 0;
}
static const st_pass_info *pass_info(void *s, int p) {
    return NULL;
}

static const st_plugin plugin = {
#if BAD_ABI_MAJOR
    .abi_major = ST_ABI_MAJOR + 1,
    .abi_minor = 0,
#elif BAD_ABI_NEWER_MINOR
    .abi_major = ST_ABI_MAJOR,
    .abi_minor = ST_ABI_MINOR + 1,
#else
    .abi_major = ST_ABI_MAJOR,
    .abi_minor = ST_ABI_MINOR,
#endif
    .struct_size = sizeof(st_plugin),
    .name = BAD_NAME,
    .description = "test plugin",
#if !BAD_MISSING_HOOKS
    .create = create,
    .destroy = destroy,
    .num_passes = num_passes,
#endif
    .pass_info = pass_info,
};

ST_EXPORT const st_plugin *strahl_plugin(void) {
    return &plugin;
}

#if BAD_FRAME_SIZE
// Built as if st_frame had grown by a field this strahl does not know.
ST_EXPORT const st_abi_sizes *strahl_plugin_sizes(void) {
    static st_abi_sizes s = ST_ABI_SIZES;
    s.frame += 8;
    return &s;
}
#elif BAD_PASS_INFO_SIZE
// Built with a smaller st_pass_info: the world would read past its end.
ST_EXPORT const st_abi_sizes *strahl_plugin_sizes(void) {
    static st_abi_sizes s = ST_ABI_SIZES;
    s.pass_info -= 8;
    return &s;
}
#endif
