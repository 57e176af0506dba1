// libFuzzer target: st_scene_parse on arbitrary bytes, then a few --set
// assignments on whatever parsed. Must never crash, leak or hang.
#include "st_scene.h"
#include <stddef.h>
#include <stdint.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    static const char *const sets[] = {"shadow_map.resolution=2048",
                                       "toth.integrator=thesis",
                                       "toth.samples=1e999",
                                       "mitchell.n=",
                                       "a.b=true",
                                       "=.",
                                       "x"};
    st_scene s;
    st_err e = {0};
    if (st_scene_parse((const char *)data, size, ST_FUZZ_DIR "/scene.json", &s, &e)) {
        for (size_t i = 0; i < sizeof sets / sizeof sets[0]; i++)
            st_scene_set(&s, sets[i], &e);
        (void)st_scene_triangle_count(&s);
    }
    st_scene_free(&s);
    return 0;
}
