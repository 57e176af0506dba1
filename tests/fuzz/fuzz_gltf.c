// libFuzzer target: st_gltf_load_memory on arbitrary bytes (.glb when they
// start with "glTF", JSON glTF otherwise). Must never crash, leak or hang.
#include "st_scene.h"
#include <stddef.h>
#include <stdint.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    st_scene s = {0};
    st_err e = {0};
    bool cam = false;
    st_gltf_load_memory(data, size, "fuzz.glb", ST_FUZZ_DIR, &s, &cam, &e);
    st_scene_free(&s);
    return 0;
}
