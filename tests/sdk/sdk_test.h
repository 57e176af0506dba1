// Helpers of the SDK tests: install this build's strahl into a scratch
// prefix, and configure and build a CMake project against it.
// ST_TEST_BINARY_DIR, ST_TEST_CMAKE and ST_TEST_GENERATOR come from
// tests/sdk/CMakeLists.txt.
#ifndef SDK_TEST_H
#define SDK_TEST_H
#include "st_test.h"

// `cmake --install` of this build into `prefix` (emptied first); the exit code.
static inline int sdk_install(const char *prefix) {
    st_test_sh("rm -rf %s", prefix);
    return st_test_sh("%s --install %s --prefix %s >/dev/null", ST_TEST_CMAKE, ST_TEST_BINARY_DIR,
                      prefix);
}

// Configures `src` into `out` (emptied first) with find_package(strahl)
// pointed at `prefix`, and builds it on two cores. With a `log`, both steps
// write there instead of the test's output. The exit code.
static inline int sdk_build(const char *src, const char *out, const char *prefix, const char *log) {
    char redirect[1400] = "";
    if (log) snprintf(redirect, sizeof redirect, ">%s 2>&1", log);
    st_test_sh("rm -rf %s", out);
    return st_test_sh("{ %s -S %s -B %s -G '%s' -DCMAKE_PREFIX_PATH=%s >/dev/null && %s --build %s "
                      "-j2; } %s",
                      ST_TEST_CMAKE, src, out, ST_TEST_GENERATOR, prefix, ST_TEST_CMAKE, out,
                      redirect);
}

#endif
