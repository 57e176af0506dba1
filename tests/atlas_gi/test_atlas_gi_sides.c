// Two atlas paths the oracles above do not reach. A double-sided receiver
// gets texels for each side: with an emitter of L0 = 1 above and L0 = 2 below,
// the top sees rho F and the bottom 2 rho F (parallel unit squares, F =
// 0.199825); with the lower emitter off, the bottom gets nothing. And a scene
// whose every mesh has TEXCOORD_1 (glTF) uses it as the atlas: the same oracle.
#include "gi_test.h"

#define H 128
#define K 100
static const double RHO = 0.5, F = 0.199825;

static double view(const char *name, const char *geometry, double D) {
    char cam[512], json[4096];
    gi_headon_camera(cam, sizeof cam, H, K, D);
    snprintf(
        json, sizeof json,
        "{\"image\": {\"width\": %d, \"height\": %d}, %s, \"lights\": [],\n \"geometry\": [%s],\n"
        " \"modules\": [{\"name\": \"atlas_gi\", \"params\": {\"atlas_size\": 128, \"mode\": "
        "\"gather\", \"visibility\": false, \"sampling\": \"uniform\", \"samples\": 256,"
        " \"display\": \"indirect\", \"max_frames\": 12, \"tolerance\": 0}}]}\n",
        H, H, cam, geometry);
    st_image img = {0};
    double v = -1;
    if (gi_render(name, json, "--frames 12", &img)) {
        v = gi_headon_mean(&img, K, 0);
        st_image_free(&img);
    }
    printf("%s: mean indirect %.6f (rho F = %.6f)\n", name, v, RHO * F);
    return v;
}

// A unit quad as glTF 2.0 with POSITION, NORMAL, TEXCOORD_1 and indices in
// a base64 data URI.
static void b64(const unsigned char *in, size_t n, char *out) {
    static const char t[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    size_t o = 0;
    for (size_t i = 0; i < n; i += 3) {
        uint32_t v = (uint32_t)in[i] << 16 | (i + 1 < n ? (uint32_t)in[i + 1] << 8 : 0) |
                     (i + 2 < n ? in[i + 2] : 0);
        out[o++] = t[v >> 18 & 63];
        out[o++] = t[v >> 12 & 63];
        out[o++] = i + 1 < n ? t[v >> 6 & 63] : '=';
        out[o++] = i + 2 < n ? t[v & 63] : '=';
    }
    out[o] = 0;
}

static void write_quad_gltf(const char *path, const float pos[4][3], const float nrm[3],
                            const float uv[4][2]) {
    struct {
        float p[4][3], n[4][3], uv[4][2];
        uint16_t idx[6];
    } buf;
    memcpy(buf.p, pos, sizeof buf.p);
    for (int i = 0; i < 4; i++)
        memcpy(buf.n[i], nrm, sizeof buf.n[i]);
    memcpy(buf.uv, uv, sizeof buf.uv);
    const uint16_t idx[6] = {0, 1, 2, 0, 2, 3};
    memcpy(buf.idx, idx, sizeof idx);
    char enc[1024];
    b64((const unsigned char *)&buf, sizeof buf, enc);
    float mn[3], mx[3];
    for (int k = 0; k < 3; k++) {
        mn[k] = mx[k] = pos[0][k];
        for (int i = 1; i < 4; i++)
            mn[k] = fminf(mn[k], pos[i][k]), mx[k] = fmaxf(mx[k], pos[i][k]);
    }
    char json[4096];
    snprintf(
        json, sizeof json,
        "{\"asset\": {\"version\": \"2.0\"}, \"scene\": 0, \"scenes\": [{\"nodes\": [0]}], "
        "\"nodes\": [{\"mesh\": 0}],\n"
        " \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0, \"NORMAL\": 1, "
        "\"TEXCOORD_1\": 2}, \"indices\": 3}]}],\n"
        " \"buffers\": [{\"byteLength\": %zu, \"uri\": "
        "\"data:application/octet-stream;base64,%s\"}],\n"
        " \"bufferViews\": [{\"buffer\": 0, \"byteOffset\": 0, \"byteLength\": 48}, {\"buffer\": "
        "0, \"byteOffset\": 48, \"byteLength\": 48},\n"
        "   {\"buffer\": 0, \"byteOffset\": 96, \"byteLength\": 32}, {\"buffer\": 0, "
        "\"byteOffset\": 128, \"byteLength\": 12}],\n"
        " \"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 4, \"type\": "
        "\"VEC3\", \"min\": [%g, %g, %g], \"max\": [%g, %g, %g]},\n"
        "   {\"bufferView\": 1, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC3\"},\n"
        "   {\"bufferView\": 2, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC2\"},\n"
        "   {\"bufferView\": 3, \"componentType\": 5123, \"count\": 6, \"type\": \"SCALAR\"}]}\n",
        sizeof buf, enc, mn[0], mn[1], mn[2], mx[0], mx[1], mx[2]);
    st_test_write(path, json);
}

int main(void) {
    const char *recv = "{\"quad\": {\"corner\": [0, 0, 0], \"u\": [0, 0, 1], \"v\": [1, 0, 0]}, "
                       "\"albedo\": [0.5, 0.5, 0.5], "
                       "\"double_sided\": true}";
    char geo[2048];
    // Emitter above only.
    snprintf(geo, sizeof geo,
             "%s,\n {\"quad\": {\"corner\": [0, 1, 0], \"u\": [1, 0, 0], \"v\": [0, 0, 1]}, "
             "\"albedo\": [0, 0, 0], "
             "\"emission\": [1, 1, 1]}",
             recv);
    double top = view("double_sided_top", geo, 0.5),
           bottom = view("double_sided_bottom_dark", geo, -0.5);
    CHECK_REL(top, RHO * F, 0.02, 0);
    CHECK(bottom >= 0 && bottom < 1e-6, "the unlit side stays dark: %g", bottom);
    // Both emitters, the lower one twice as bright.
    snprintf(geo, sizeof geo,
             "%s,\n {\"quad\": {\"corner\": [0, 1, 0], \"u\": [1, 0, 0], \"v\": [0, 0, 1]}, "
             "\"albedo\": [0, 0, 0], "
             "\"emission\": [1, 1, 1]},\n {\"quad\": {\"corner\": [0, -1, 0], \"u\": [0, 0, 1], "
             "\"v\": [1, 0, 0]}, "
             "\"albedo\": [0, 0, 0], \"emission\": [2, 2, 2]}",
             recv);
    top = view("double_sided_both_top", geo, 0.5);
    bottom = view("double_sided_both_bottom", geo, -0.5);
    CHECK_REL(top, RHO * F, 0.02, 0);
    CHECK_REL(bottom, 2 * RHO * F, 0.02, 0);

    // TEXCOORD_1: receiver in the left half of the atlas, emitter in the right.
    char rpath[512], epath[512];
    snprintf(rpath, sizeof rpath, "%s/receiver.gltf", ST_TEST_SCRATCH);
    snprintf(epath, sizeof epath, "%s/emitter.gltf", ST_TEST_SCRATCH);
    const float rp[4][3] = {{0, 0, 0}, {0, 0, 1}, {1, 0, 1}, {1, 0, 0}}, rn[3] = {0, 1, 0};
    const float ep[4][3] = {{0, 1, 0}, {1, 1, 0}, {1, 1, 1}, {0, 1, 1}}, en[3] = {0, -1, 0};
    const float ruv[4][2] = {{0.05f, 0.05f}, {0.05f, 0.95f}, {0.45f, 0.95f}, {0.45f, 0.05f}};
    const float euv[4][2] = {{0.55f, 0.05f}, {0.95f, 0.05f}, {0.95f, 0.95f}, {0.55f, 0.95f}};
    write_quad_gltf(rpath, rp, rn, ruv);
    write_quad_gltf(epath, ep, en, euv);
    snprintf(geo, sizeof geo,
             "{\"gltf\": \"receiver.gltf\", \"albedo\": [0.5, 0.5, 0.5]},\n"
             " {\"gltf\": \"emitter.gltf\", \"albedo\": [0, 0, 0], \"emission\": [1, 1, 1]}");
    double uv1 = view("texcoord1", geo, 0.5);
    CHECK_REL(uv1, RHO * F, 0.02, 0);
    return st_test_summary("test_atlas_gi_sides");
}
