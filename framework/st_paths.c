// Where libstrahl lives: an installed tree is found relative to the library
// itself, so a prefix copied elsewhere (or installed with --prefix) still
// finds its shaders and modules.
#define _GNU_SOURCE
#include "st_base.h"
#include <dlfcn.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

const char *st_install_prefix(void) {
    static char prefix[1024];
    static bool done;
    if (done) return prefix;
    done = true;
    Dl_info info;
    if (!dladdr((void *)st_install_prefix, &info) || !info.dli_fname) return prefix;
    char real[PATH_MAX], lib[1024], dir[1024];
    if (!realpath(info.dli_fname, real)) return prefix;
    st_path_dir(lib, sizeof lib, real); // <prefix>/lib
    st_path_dir(dir, sizeof dir, lib);  // <prefix>
    // Only an installed layout counts: the build tree has no share/strahl.
    char probe[1100];
    struct stat st;
    snprintf(probe, sizeof probe, "%s/share/strahl", dir);
    if (stat(probe, &st) == 0 && S_ISDIR(st.st_mode)) snprintf(prefix, sizeof prefix, "%s", dir);
    return prefix;
}
