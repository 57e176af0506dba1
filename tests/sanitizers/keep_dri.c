// LD_PRELOAD shim for the sanitizer test run (CMakePresets.json, debug test
// preset): keeps Mesa's DRI driver mapped until the process exits.
//
// Why: eglTerminate dlcloses the driver (swrast_dri.so, llvmpipe). Blocks the
// driver still points to from its static data then lose their only root, and
// LeakSanitizer, which checks at exit, reports them as leaks from
// "<unknown module>" (the code that allocated them is unmapped by then, so
// no suppression pattern can name it). With the driver kept, those blocks
// stay reachable, nothing needs suppressing, and leak checking stays on for
// every GL process, our own allocations included.
//
// The same holds for Mesa's EGL vendor library (libEGL_mesa.so.0, which
// glvnd's libEGL dlcloses): a 1608-byte block of it was reported after
// renders with atlas_gi (found with every dlclose skipped and
// LSAN_OPTIONS=use_globals=0, which names the allocating module).
// Only dlclose of a *_dri.so or libEGL_mesa.so* handle is skipped; every
// other handle (our plugins among them) is closed as usual.
#define _GNU_SOURCE
#include <dlfcn.h>
#include <link.h>
#include <string.h>

int dlclose(void *handle) {
    static int (*real_dlclose)(void *);
    if (!real_dlclose) real_dlclose = (int (*)(void *))dlsym(RTLD_NEXT, "dlclose");
    struct link_map *lm = NULL;
    // glibc declares handle nonnull, but a bad caller must get dlclose's
    // error, not a crash in dlinfo: the volatile copy keeps the test.
    void *volatile h = handle;
    if (h && dlinfo(h, RTLD_DI_LINKMAP, &lm) == 0 && lm && lm->l_name) {
        size_t n = strlen(lm->l_name);
        if (n >= 7 && !strcmp(lm->l_name + n - 7, "_dri.so")) return 0;
        if (strstr(lm->l_name, "libEGL_mesa.so")) return 0;
    }
    return real_dlclose ? real_dlclose(handle) : -1;
}
