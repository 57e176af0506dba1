// glTF 2.0 loading (tinygltf) behind the C API of st_scene.h (st_vdb.cpp is
// libstrahl's only other C++). tinygltf parses; everything it leaves unchecked (indices into
// the arrays, accessor bounds, finite numbers, tree shape of the nodes) is
// checked here so malformed files give an error, never a crash. No
// exception leaves this file.
#include "st_scene.h"

#include "st_file.h"

#include <climits>
#include <sys/stat.h>
#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <new>
#include <sstream>
#include <string>
#include <vector>
// Included before the visibility push: libc/libstdc++ declarations (e.g.
// __assert_fail) must keep default visibility.
#include <nlohmann/json.hpp>

// Textures are not used: no image decoding or writing, no external images.
#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
// Hidden, so this private copy never interposes with the system libtinygltf.
#pragma GCC visibility push(hidden)
#include <tiny_gltf.h>
#pragma GCC visibility pop

namespace {

using tinygltf::Model;
using Mat = std::array<double, 16>; // column major

bool fail(std::string &e, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
bool fail(std::string &e, const char *fmt, ...) {
    char b[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(b, sizeof b, fmt, ap);
    va_end(ap);
    e = b;
    return false;
}

// ---- files -----------------------------------------------------------------

// Where external files may come from: buffer and image URIs resolve inside
// the folder tree of the glTF file (root, a realpath) unless the user allowed
// anything. tinygltf joins the decoded URI to base (and retries it relative
// to the working directory), so the check is on the resolved file.
struct AssetFs {
    std::string base, root;
    bool anywhere = false;
    std::string refused;           // why a URI was refused (replaces tinygltf's message)
    std::vector<std::string> read; // the buffer files read (st_scene_note_file)
};

// A URI's decoded path with a NUL ("tri.bin%00x" would open "tri.bin") or
// another control character is refused, not truncated.
bool has_control(const std::string &path) {
    for (unsigned char c : path)
        if (c < 0x20 || c == 0x7f) return true;
    return false;
}

// The URI as written in the glTF (percent-decoded), from the path tinygltf built.
std::string uri_of(const AssetFs &fs, const std::string &path) {
    if (!fs.base.empty() && path.compare(0, fs.base.size() + 1, fs.base + "/") == 0)
        return path.substr(fs.base.size() + 1);
    if (path.compare(0, 2, "./") == 0) return path.substr(2);
    return path;
}

bool inside(const std::string &root, const char *real) {
    if (root == "/") return true;
    size_t n = root.size();
    return strncmp(real, root.c_str(), n) == 0 && (real[n] == '/' || real[n] == 0);
}

// Reads a regular file only (st_read_input: a FIFO or /dev/zero would block
// or never end), within the asset cap; tinygltf takes 32-bit lengths.
bool read_regular(const std::string &path, std::vector<unsigned char> &out, std::string &e) {
    st_err err = {};
    size_t len = 0;
    char *buf = st_read_input(path.c_str(), ST_CAP_ASSET, "glTF file", &len, &err);
    if (!buf) return fail(e, "%s", err.msg);
    try {
        out.assign((unsigned char *)buf, (unsigned char *)buf + len);
    } catch (...) {
        free(buf);
        throw;
    }
    free(buf);
    return true;
}

// Existence only: the checks (folder, file type, size) are fs_read's, so
// that their message reaches the user instead of "File not found".
bool fs_exists(const std::string &path, void *) {
    struct stat st;
    return has_control(path) || stat(path.c_str(), &st) == 0;
}
// tinygltf joins an absolute URI to the folder ("dir//abs"): the file meant
// is the absolute one (then confined like any other).
std::string fs_expand(const std::string &path, void *user) {
    const AssetFs *fs = (const AssetFs *)user;
    if (fs && !fs->base.empty() && path.compare(0, fs->base.size() + 2, fs->base + "//") == 0)
        return path.substr(fs->base.size() + 1);
    return path;
}
bool fs_read(std::vector<unsigned char> *out, std::string *err, const std::string &path,
             void *user) {
    AssetFs *fs = (AssetFs *)user;
    std::string e, file = path;
    if (has_control(path)) {
        std::string shown;
        for (unsigned char c : uri_of(*fs, path)) {
            char b[8];
            snprintf(b, sizeof b, c < 0x20 || c == 0x7f ? "\\x%02x" : "%c", c);
            shown += b;
        }
        fs->refused = "buffer URI '" + shown + "': contains a NUL or control character";
        if (err) *err += fs->refused;
        return false;
    }
    if (fs && !fs->anywhere) {
        char real[PATH_MAX];
        if (!realpath(path.c_str(), real)) {
            if (err) *err += strerror(errno);
            return false;
        }
        if (!inside(fs->root, real)) {
            char b[1024];
            snprintf(b, sizeof b,
                     "buffer URI '%.300s' resolves to '%.300s', outside the glTF file's folder "
                     "'%.300s' (--allow-outside-assets allows it)",
                     uri_of(*fs, path).c_str(), real, fs->root.c_str());
            fs->refused = b;
            if (err) *err += b;
            return false;
        }
        file = real;
    }
    if (read_regular(file, *out, e)) {
        if (fs) fs->read.push_back(file);
        return true;
    }
    if (fs) fs->refused = "buffer URI '" + uri_of(*fs, path) + "': " + e;
    if (err) *err += e;
    return false;
}
bool fs_write(std::string *err, const std::string &, const std::vector<unsigned char> &, void *) {
    if (err) *err += "writing is disabled";
    return false;
}
// Images are parsed (for validity) but never decoded.
bool skip_image(tinygltf::Image *, const int, std::string *, std::string *, int, int,
                const unsigned char *, int, void *) {
    return true;
}

// tinygltf messages are newline separated; one line reads better.
std::string one_line(std::string s) {
    while (!s.empty() && (s.back() == '\n' || s.back() == ' '))
        s.pop_back();
    for (size_t i; (i = s.find('\n')) != std::string::npos;)
        s.replace(i, 1, "; ");
    return s.empty() ? "invalid glTF" : s;
}

// ---- math ------------------------------------------------------------------

Mat identity() {
    Mat m{};
    m[0] = m[5] = m[10] = m[15] = 1;
    return m;
}

Mat mul(const Mat &a, const Mat &b) {
    Mat r{};
    for (int c = 0; c < 4; c++)
        for (int row = 0; row < 4; row++)
            for (int k = 0; k < 4; k++)
                r[c * 4 + row] += a[k * 4 + row] * b[c * 4 + k];
    return r;
}

bool all_finite(const std::vector<double> &v) {
    return std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); });
}

// The node's local transform: its matrix, or T * R * S.
bool local_transform(const tinygltf::Node &n, int i, Mat &m, std::string &e) {
    if (!n.matrix.empty()) {
        if (n.matrix.size() != 16 || !all_finite(n.matrix))
            return fail(e, "nodes[%d].matrix: expected 16 finite numbers", i);
        std::copy(n.matrix.begin(), n.matrix.end(), m.begin());
        return true;
    }
    double t[3] = {0, 0, 0}, q[4] = {0, 0, 0, 1}, s[3] = {1, 1, 1};
    if (!n.translation.empty()) {
        if (n.translation.size() != 3 || !all_finite(n.translation))
            return fail(e, "nodes[%d].translation: expected 3 finite numbers", i);
        std::copy(n.translation.begin(), n.translation.end(), t);
    }
    if (!n.rotation.empty()) {
        if (n.rotation.size() != 4 || !all_finite(n.rotation))
            return fail(e, "nodes[%d].rotation: expected 4 finite numbers", i);
        double len = std::sqrt(n.rotation[0] * n.rotation[0] + n.rotation[1] * n.rotation[1] +
                               n.rotation[2] * n.rotation[2] + n.rotation[3] * n.rotation[3]);
        if (!(len > 0) || !std::isfinite(len))
            return fail(e, "nodes[%d].rotation: not a valid quaternion", i);
        for (int k = 0; k < 4; k++)
            q[k] = n.rotation[k] / len; // exporters round
    }
    if (!n.scale.empty()) {
        if (n.scale.size() != 3 || !all_finite(n.scale))
            return fail(e, "nodes[%d].scale: expected 3 finite numbers", i);
        std::copy(n.scale.begin(), n.scale.end(), s);
    }
    const double x = q[0], y = q[1], z = q[2], w = q[3];
    const double r[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
                            {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
                            {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)}};
    m = identity();
    for (int c = 0; c < 3; c++)
        for (int row = 0; row < 3; row++)
            m[c * 4 + row] = r[row][c] * s[c];
    for (int row = 0; row < 3; row++)
        m[12 + row] = t[row];
    return true;
}

// ---- accessors -------------------------------------------------------------

struct View {
    const unsigned char *base = nullptr;
    size_t stride = 0, count = 0;
    int comp_type = 0, comps = 0;
    bool normalized = false;
};

size_t comp_size(int t) {
    switch (t) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
        return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
        return 2;
    case TINYGLTF_COMPONENT_TYPE_INT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
        return 4;
    case TINYGLTF_COMPONENT_TYPE_DOUBLE:
        return 8;
    default:
        return 0;
    }
}

int type_comps(int t) {
    switch (t) {
    case TINYGLTF_TYPE_SCALAR:
        return 1;
    case TINYGLTF_TYPE_VEC2:
        return 2;
    case TINYGLTF_TYPE_VEC3:
        return 3;
    case TINYGLTF_TYPE_VEC4:
        return 4;
    case TINYGLTF_TYPE_MAT2:
        return 4;
    case TINYGLTF_TYPE_MAT3:
        return 9;
    case TINYGLTF_TYPE_MAT4:
        return 16;
    default:
        return 0;
    }
}

// Resolves accessor idx and checks that every element lies inside its
// buffer view and the view inside its buffer.
bool accessor_view(const Model &m, int idx, const char *what, View &v, std::string &e) {
    if (idx < 0 || (size_t)idx >= m.accessors.size())
        return fail(e, "%s: accessor %d does not exist", what, idx);
    const tinygltf::Accessor &a = m.accessors[(size_t)idx];
    if (a.sparse.isSparse) return fail(e, "accessors[%d]: sparse accessors are not supported", idx);
    size_t cs = comp_size(a.componentType);
    int nc = type_comps(a.type);
    if (!cs || !nc) return fail(e, "accessors[%d]: invalid type or componentType", idx);
    if (a.count > std::numeric_limits<uint32_t>::max())
        return fail(e, "accessors[%d]: count %zu is too large", idx, a.count);
    v = View{};
    v.count = a.count, v.comp_type = a.componentType, v.comps = nc, v.normalized = a.normalized;
    // Without a bufferView glTF reads zeros, for sparse accessors to patch; a
    // bare one would let a tiny file ask for billions of vertices.
    if (a.bufferView < 0)
        return fail(e, "accessors[%d]: no bufferView (sparse accessors are not supported)", idx);
    if ((size_t)a.bufferView >= m.bufferViews.size())
        return fail(e, "accessors[%d].bufferView: %d does not exist", idx, a.bufferView);
    const tinygltf::BufferView &bv = m.bufferViews[(size_t)a.bufferView];
    if (bv.buffer < 0 || (size_t)bv.buffer >= m.buffers.size())
        return fail(e, "bufferViews[%d].buffer: %d does not exist", a.bufferView, bv.buffer);
    const std::vector<unsigned char> &data = m.buffers[(size_t)bv.buffer].data;
    if (bv.byteOffset > data.size() || bv.byteLength > data.size() - bv.byteOffset)
        return fail(e, "bufferViews[%d]: byteOffset + byteLength exceed buffer %d (%zu bytes)",
                    a.bufferView, bv.buffer, data.size());
    size_t elem = cs * (size_t)nc;
    v.stride = bv.byteStride ? bv.byteStride : elem;
    if (v.stride < elem)
        return fail(e, "bufferViews[%d].byteStride: %zu is smaller than an element (%zu bytes)",
                    a.bufferView, v.stride, elem);
    if (a.count > 0) {
        // offset + (count - 1) * stride + elem <= byteLength, without overflow.
        bool fits = a.byteOffset <= bv.byteLength && bv.byteLength - a.byteOffset >= elem &&
                    (a.count - 1) <= (bv.byteLength - a.byteOffset - elem) / v.stride;
        if (!fits)
            return fail(e,
                        "accessors[%d]: %zu elements at byteOffset %zu exceed bufferViews[%d] "
                        "(%zu bytes)",
                        idx, a.count, a.byteOffset, a.bufferView, bv.byteLength);
    }
    v.base = data.data() + bv.byteOffset + a.byteOffset;
    return true;
}

// Component k of element i as a double (normalized integers mapped to [0,1]
// or [-1,1] when the accessor says so).
double read_comp(const View &v, size_t i, int k) {
    const unsigned char *p = v.base + i * v.stride + (size_t)k * comp_size(v.comp_type);
    switch (v.comp_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
        int8_t x;
        memcpy(&x, p, 1);
        return v.normalized ? std::max(x / 127.0, -1.0) : x;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
        uint8_t x;
        memcpy(&x, p, 1);
        return v.normalized ? x / 255.0 : x;
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
        int16_t x;
        memcpy(&x, p, 2);
        return v.normalized ? std::max(x / 32767.0, -1.0) : x;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        uint16_t x;
        memcpy(&x, p, 2);
        return v.normalized ? x / 65535.0 : x;
    }
    case TINYGLTF_COMPONENT_TYPE_INT: {
        int32_t x;
        memcpy(&x, p, 4);
        return x;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
        uint32_t x;
        memcpy(&x, p, 4);
        return x;
    }
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
        float x;
        memcpy(&x, p, 4);
        return x;
    }
    default: {
        double x;
        memcpy(&x, p, 8);
        return x;
    }
    }
}

// Reads a float attribute of `comps` components (positions, normals, UVs).
bool read_floats(const Model &m, int idx, const char *what, int comps, bool allow_unorm,
                 std::vector<float> &out, std::string &e) {
    View v;
    if (!accessor_view(m, idx, what, v, e)) return false;
    bool unorm = allow_unorm && v.normalized &&
                 (v.comp_type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                  v.comp_type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT);
    if (v.comps != comps || !(v.comp_type == TINYGLTF_COMPONENT_TYPE_FLOAT || unorm))
        return fail(e, "%s: accessors[%d] must be %d-component FLOAT%s", what, idx, comps,
                    allow_unorm ? " or normalized UNSIGNED_BYTE/SHORT" : "");
    out.resize(v.count * (size_t)comps);
    for (size_t i = 0; i < v.count; i++) {
        for (int k = 0; k < comps; k++) {
            double x = read_comp(v, i, k);
            if (!std::isfinite(x))
                return fail(e, "%s: accessors[%d] element %zu is not finite", what, idx, i);
            out[i * (size_t)comps + (size_t)k] = (float)x;
        }
    }
    return true;
}

// ---- primitives ------------------------------------------------------------

struct Prim {
    std::string name;
    std::vector<float> pos, nrm, uv;
    std::vector<uint32_t> idx;
    float albedo[3], emission[3];
    bool double_sided;
};

const char *mode_name(int mode) {
    static const char *const names[] = {"POINTS",    "LINES",          "LINE_LOOP",   "LINE_STRIP",
                                        "TRIANGLES", "TRIANGLE_STRIP", "TRIANGLE_FAN"};
    return mode >= 0 && mode < 7 ? names[mode] : "unknown";
}

bool material(const Model &m, int mi, const char *what, Prim &p, std::string &e) {
    // No material: the scene's default grey (the glTF default, white, would
    // be an albedo of 1).
    for (int k = 0; k < 3; k++)
        p.albedo[k] = 0.75f, p.emission[k] = 0;
    p.double_sided = false;
    if (mi < 0) return true;
    if ((size_t)mi >= m.materials.size())
        return fail(e, "%s.material: %d does not exist", what, mi);
    const tinygltf::Material &mat = m.materials[(size_t)mi];
    const std::vector<double> &bc = mat.pbrMetallicRoughness.baseColorFactor;
    const std::vector<double> &em = mat.emissiveFactor;
    if (bc.size() != 4 || !all_finite(bc))
        return fail(e, "materials[%d].pbrMetallicRoughness.baseColorFactor: expected 4 numbers",
                    mi);
    if (em.size() != 3 || !all_finite(em))
        return fail(e, "materials[%d].emissiveFactor: expected 3 numbers", mi);
    double strength = 1;
    auto ext = mat.extensions.find("KHR_materials_emissive_strength");
    if (ext != mat.extensions.end()) {
        const tinygltf::Value &s = ext->second;
        if (!s.IsObject() || !s.Has("emissiveStrength") || !s.Get("emissiveStrength").IsNumber())
            return fail(e, "materials[%d]: KHR_materials_emissive_strength needs emissiveStrength",
                        mi);
        strength = s.Get("emissiveStrength").GetNumberAsDouble();
        if (!std::isfinite(strength) || strength < 0)
            return fail(e, "materials[%d]: emissiveStrength must be >= 0", mi);
    }
    for (int k = 0; k < 3; k++) {
        if (bc[k] < 0 || bc[k] > 1)
            return fail(
                e, "materials[%d].pbrMetallicRoughness.baseColorFactor[%d]: %g is not in [0, 1]",
                mi, k, bc[k]);
        if (em[k] < 0)
            return fail(e, "materials[%d].emissiveFactor[%d]: %g is negative", mi, k, em[k]);
        double emission = em[k] * strength;
        if (emission > std::numeric_limits<float>::max())
            return fail(e, "materials[%d]: emission overflows a float", mi);
        p.albedo[k] = (float)bc[k];
        p.emission[k] = (float)emission;
    }
    p.double_sided = mat.doubleSided;
    return true;
}

bool read_indices(const Model &m, int idx, const char *what, size_t nverts,
                  std::vector<uint32_t> &out, std::string &e) {
    View v;
    if (!accessor_view(m, idx, what, v, e)) return false;
    if (v.comps != 1 || v.comp_type == TINYGLTF_COMPONENT_TYPE_FLOAT ||
        v.comp_type == TINYGLTF_COMPONENT_TYPE_DOUBLE)
        return fail(e, "%s: accessors[%d] must be an integer SCALAR", what, idx);
    if (v.count % 3) return fail(e, "%s: %zu indices is not a multiple of 3", what, v.count);
    out.resize(v.count);
    for (size_t i = 0; i < v.count; i++) {
        double x = read_comp(v, i, 0);
        if (x < 0 || x >= (double)nverts)
            return fail(e, "%s: index %zu is %.0f, but there are %zu vertices", what, i, x, nverts);
        out[i] = (uint32_t)x;
    }
    return true;
}

// Flat normals for a primitive without NORMAL (as the glTF spec asks): every
// triangle gets its own three vertices.
void flat_normals(Prim &p) {
    size_t nt = p.idx.size() / 3;
    std::vector<float> pos(nt * 9), nrm(nt * 9), uv(p.uv.empty() ? 0 : nt * 6);
    for (size_t t = 0; t < nt; t++) {
        const float *a = &p.pos[3 * p.idx[3 * t]], *b = &p.pos[3 * p.idx[3 * t + 1]],
                    *c = &p.pos[3 * p.idx[3 * t + 2]];
        double e1[3], e2[3];
        for (int k = 0; k < 3; k++)
            e1[k] = (double)b[k] - a[k], e2[k] = (double)c[k] - a[k];
        double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                       e1[0] * e2[1] - e1[1] * e2[0]};
        double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        // A zero-area triangle gets any unit normal: shaders must never
        // normalize a zero vector.
        if (!(len > 0) || !std::isfinite(len)) n[0] = n[1] = 0, n[2] = len = 1;
        for (int j = 0; j < 3; j++) {
            uint32_t src = p.idx[3 * t + (size_t)j];
            for (int k = 0; k < 3; k++) {
                pos[9 * t + 3 * (size_t)j + (size_t)k] = p.pos[3 * (size_t)src + (size_t)k];
                nrm[9 * t + 3 * (size_t)j + (size_t)k] = (float)(n[k] / len);
            }
            if (!uv.empty())
                for (int k = 0; k < 2; k++)
                    uv[6 * t + 2 * (size_t)j + (size_t)k] = p.uv[2 * (size_t)src + (size_t)k];
            p.idx[3 * t + (size_t)j] = (uint32_t)(3 * t + (size_t)j);
        }
    }
    p.pos.swap(pos), p.nrm.swap(nrm), p.uv.swap(uv);
}

bool convert_primitive(const Model &m, int mi, int pi, Prim &p, std::string &e) {
    const tinygltf::Mesh &mesh = m.meshes[(size_t)mi];
    const tinygltf::Primitive &prim = mesh.primitives[(size_t)pi];
    char what[96];
    snprintf(what, sizeof what, "meshes[%d].primitives[%d]", mi, pi);
    int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
    if (mode != TINYGLTF_MODE_TRIANGLES)
        return fail(e, "%s: mode %s (%d) is not supported, only TRIANGLES", what, mode_name(mode),
                    mode);
    auto attr = [&](const char *key) {
        auto it = prim.attributes.find(key);
        return it == prim.attributes.end() ? -1 : it->second;
    };
    int ip = attr("POSITION"), in = attr("NORMAL"), iu = attr("TEXCOORD_1");
    char aw[128];
    if (ip < 0) return fail(e, "%s: no POSITION attribute", what);
    snprintf(aw, sizeof aw, "%s.attributes.POSITION", what);
    if (!read_floats(m, ip, aw, 3, false, p.pos, e)) return false;
    size_t nv = p.pos.size() / 3;
    if (in >= 0) {
        snprintf(aw, sizeof aw, "%s.attributes.NORMAL", what);
        if (!read_floats(m, in, aw, 3, false, p.nrm, e)) return false;
        if (p.nrm.size() != p.pos.size())
            return fail(e, "%s: NORMAL count differs from POSITION count", what);
        for (size_t i = 0; i < nv; i++) {
            float *n = &p.nrm[3 * i];
            double len = std::sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
            if (len > 0)
                for (int k = 0; k < 3; k++)
                    n[k] = (float)(n[k] / len);
            else
                n[0] = n[1] = 0, n[2] = 1; // see flat_normals
        }
    }
    if (iu >= 0) {
        snprintf(aw, sizeof aw, "%s.attributes.TEXCOORD_1", what);
        if (!read_floats(m, iu, aw, 2, true, p.uv, e)) return false;
        if (p.uv.size() / 2 != nv)
            return fail(e, "%s: TEXCOORD_1 count differs from POSITION count", what);
    }
    if (prim.indices >= 0) {
        snprintf(aw, sizeof aw, "%s.indices", what);
        if (!read_indices(m, prim.indices, aw, nv, p.idx, e)) return false;
    } else {
        if (nv % 3)
            return fail(e, "%s: %zu vertices without indices is not a multiple of 3", what, nv);
        p.idx.resize(nv);
        for (size_t i = 0; i < nv; i++)
            p.idx[i] = (uint32_t)i;
    }
    if (!material(m, prim.material, what, p, e)) return false;
    if (in < 0) flat_normals(p);
    char name[ST_NAME_MAX];
    const std::string base = mesh.name.empty() ? "mesh" + std::to_string(mi) : mesh.name;
    if (mesh.primitives.size() > 1)
        snprintf(name, sizeof name, "%s.%d", base.c_str(), pi);
    else
        snprintf(name, sizeof name, "%s", base.c_str());
    p.name = name;
    return true;
}

// ---- the whole file --------------------------------------------------------

// Owns C meshes until they are handed to the scene.
struct Meshes {
    std::vector<st_mesh> v;
    ~Meshes() {
        for (st_mesh &m : v)
            st_mesh_free(&m);
    }
};

bool make_mesh(const Prim &p, const Mat &world, Meshes &out, std::string &e) {
    out.v.emplace_back();
    st_mesh &m = out.v.back();
    memset(&m, 0, sizeof m);
    snprintf(m.name, sizeof m.name, "%s", p.name.c_str());
    size_t nv = p.pos.size() / 3;
    m.positions = (float *)malloc(p.pos.size() * sizeof(float) + 1);
    m.normals = (float *)malloc(p.nrm.size() * sizeof(float) + 1);
    m.indices = (uint32_t *)malloc(p.idx.size() * sizeof(uint32_t) + 1);
    if (!p.uv.empty()) m.uv1 = (float *)malloc(p.uv.size() * sizeof(float));
    if (!m.positions || !m.normals || !m.indices || (!p.uv.empty() && !m.uv1))
        throw std::bad_alloc();
    if (!p.pos.empty()) memcpy(m.positions, p.pos.data(), p.pos.size() * sizeof(float));
    if (!p.nrm.empty()) memcpy(m.normals, p.nrm.data(), p.nrm.size() * sizeof(float));
    if (!p.uv.empty()) memcpy(m.uv1, p.uv.data(), p.uv.size() * sizeof(float));
    if (!p.idx.empty()) memcpy(m.indices, p.idx.data(), p.idx.size() * sizeof(uint32_t));
    m.num_vertices = (uint32_t)nv;
    m.num_triangles = (uint32_t)(p.idx.size() / 3);
    for (int i = 0; i < 16; i++) {
        if (!(std::fabs(world[(size_t)i]) <= std::numeric_limits<float>::max()))
            return fail(e, "%s: node transform overflows a float", p.name.c_str());
        m.model[i] = (float)world[(size_t)i];
    }
    memcpy(m.albedo, p.albedo, sizeof m.albedo);
    memcpy(m.emission, p.emission, sizeof m.emission);
    m.double_sided = p.double_sided;
    return true;
}

bool make_camera(const Model &m, int ci, int ni, const Mat &w, st_camera_desc &cam,
                 std::string &e) {
    const tinygltf::PerspectiveCamera &pc = m.cameras[(size_t)ci].perspective;
    const double pi = 3.14159265358979323846;
    if (!(pc.yfov > 0 && pc.yfov < pi))
        return fail(e, "cameras[%d].perspective.yfov: %g is not in (0, pi)", ci, pc.yfov);
    if (!(pc.znear > 0) || !std::isfinite(pc.znear) || pc.znear > 1e30)
        return fail(e, "cameras[%d].perspective.znear: %g is not > 0", ci, pc.znear);
    // zfar 0 means an infinite projection; GL needs a finite far plane.
    double zfar = pc.zfar == 0 ? std::max(1000.0, 1000.0 * pc.znear) : pc.zfar;
    if (!(zfar > pc.znear) || !std::isfinite(zfar) || zfar > 1e30)
        return fail(e, "cameras[%d].perspective.zfar: %g is not greater than znear", ci, pc.zfar);
    // Looks down -Z with +Y up in its node's frame.
    double pos[3] = {w[12], w[13], w[14]}, fwd[3] = {-w[8], -w[9], -w[10]},
           up[3] = {w[4], w[5], w[6]};
    double fl = std::sqrt(fwd[0] * fwd[0] + fwd[1] * fwd[1] + fwd[2] * fwd[2]);
    double ul = std::sqrt(up[0] * up[0] + up[1] * up[1] + up[2] * up[2]);
    double c[3] = {fwd[1] * up[2] - fwd[2] * up[1], fwd[2] * up[0] - fwd[0] * up[2],
                   fwd[0] * up[1] - fwd[1] * up[0]};
    double cl = std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    if (!(fl > 0 && ul > 0 && cl > 1e-6 * fl * ul) || !std::isfinite(fl * ul))
        return fail(e, "nodes[%d]: the camera's transform is degenerate", ni);
    for (int k = 0; k < 3; k++) {
        double target = pos[k] + fwd[k] / fl;
        if (!(std::fabs(pos[k]) < 1e30 && std::fabs(target) < 1e30))
            return fail(e, "nodes[%d]: the camera's position overflows a float", ni);
        cam.position[k] = (float)pos[k];
        cam.target[k] = (float)target;
        cam.up[k] = (float)(up[k] / ul);
    }
    if (cam.position[0] == cam.target[0] && cam.position[1] == cam.target[1] &&
        cam.position[2] == cam.target[2])
        return fail(e, "nodes[%d]: the camera is too far from the origin for float precision", ni);
    cam.fov_y = (float)(pc.yfov * 180.0 / pi);
    cam.near_z = (float)pc.znear;
    cam.far_z = (float)zfar;
    return true;
}

bool node_light(const Model &m, const tinygltf::Node &n, int ni, const Mat &w,
                std::vector<st_light_desc> &lights, std::string &e) {
    auto ext = n.extensions.find("KHR_lights_punctual");
    if (ext == n.extensions.end()) return true;
    const tinygltf::Value &v = ext->second;
    if (!v.IsObject() || !v.Has("light") || !v.Get("light").IsNumber())
        return fail(e, "nodes[%d].extensions.KHR_lights_punctual: expected {\"light\": index}", ni);
    double li = v.Get("light").GetNumberAsDouble();
    if (!(li >= 0 && li < (double)m.lights.size()) || li != std::floor(li))
        return fail(e, "nodes[%d].extensions.KHR_lights_punctual.light: %g does not exist", ni, li);
    const tinygltf::Light &l = m.lights[(size_t)li];
    st_light_desc d = {};
    if (l.type == "directional")
        d.type = ST_LIGHT_DIRECTIONAL;
    else if (l.type == "spot")
        d.type = ST_LIGHT_SPOT;
    else if (l.type != "point")
        return fail(e,
                    "KHR_lights_punctual.lights[%d]: type '%s' is not point, directional or spot",
                    (int)li, l.type.c_str());
    if (d.type != ST_LIGHT_POINT) {
        // Lights shine along the node's local -z.
        double dir[3] = {-w[8], -w[9], -w[10]};
        double len = std::sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
        if (!(len > 1e-12) || !std::isfinite(len))
            return fail(e, "nodes[%d]: the light's direction is degenerate (scaled to zero?)", ni);
        for (int k = 0; k < 3; k++)
            d.direction[k] = (float)(dir[k] / len);
    }
    if (d.type == ST_LIGHT_SPOT) {
        const double pi = 3.14159265358979323846;
        double inner = l.spot.innerConeAngle, outer = l.spot.outerConeAngle;
        if (!(outer > 0 && outer <= pi / 2 + 1e-9) || !(inner >= 0 && inner < outer))
            return fail(e,
                        "KHR_lights_punctual.lights[%d].spot: expected 0 <= innerConeAngle < "
                        "outerConeAngle "
                        "<= pi/2, got %g and %g",
                        (int)li, inner, outer);
        d.inner_angle = (float)inner;
        d.outer_angle = (float)std::min(outer, pi / 2);
    }
    double color[3] = {1, 1, 1};
    if (!l.color.empty()) {
        if (l.color.size() != 3 || !all_finite(l.color))
            return fail(e, "KHR_lights_punctual.lights[%d].color: expected 3 numbers", (int)li);
        std::copy(l.color.begin(), l.color.end(), color);
    }
    if (!std::isfinite(l.intensity) || l.intensity < 0)
        return fail(e, "KHR_lights_punctual.lights[%d].intensity: expected >= 0", (int)li);
    for (int k = 0; k < 3; k++) {
        if (color[k] < 0) return fail(e, "KHR_lights_punctual.lights[%d].color: negative", (int)li);
        // candela -> W/sr (point, spot) and lux -> W/m^2 (directional) at
        // 683 lm/W (Blender's exporter multiplies by it).
        double I = l.intensity / 683.0 * color[k];
        if (!(I <= std::numeric_limits<float>::max()) || !(std::fabs(w[12 + k]) < 1e30))
            return fail(e, "nodes[%d]: light overflows a float", ni);
        d.intensity[k] = (float)I;
        d.position[k] = (float)w[12 + k];
    }
    lights.push_back(d);
    return true;
}

bool check_extensions(const Model &m, std::string &e) {
    static const char *const ok[] = {"KHR_lights_punctual", "KHR_materials_emissive_strength",
                                     "KHR_texture_transform", "KHR_texture_basisu",
                                     "EXT_texture_webp"};
    for (const std::string &x : m.extensionsRequired) {
        bool known = false;
        for (const char *k : ok)
            known = known || x == k;
        if (!known) return fail(e, "extensionsRequired: '%s' is not supported", x.c_str());
    }
    return true;
}

struct Result {
    Meshes meshes;
    std::vector<st_light_desc> lights;
    bool has_camera = false;
    st_camera_desc camera = {};
};

// Copies every instance's primitives into meshes, after the caps: the
// triangles and bytes the instances would expand to are summed first, so
// 1000 nodes sharing one large mesh are refused before any copy is made.
bool expand(const std::vector<std::vector<Prim>> &prims,
            const std::vector<std::pair<size_t, Mat>> &inst, uint64_t tris_before, Result &r,
            std::string &e) {
    uint64_t tris = tris_before, bytes = 0, count = 0;
    for (const auto &[mi, w] : inst)
        for (const Prim &p : prims[mi]) {
            if (p.idx.empty()) continue;
            tris += p.idx.size() / 3;
            bytes += (p.pos.size() + p.nrm.size() + p.uv.size() + p.idx.size()) * 4;
            count++;
        }
    if (tris > ST_SCENE_MAX_TRIANGLES)
        return fail(e, "the scene would have %llu triangles, more than the limit of %llu",
                    (unsigned long long)tris, (unsigned long long)ST_SCENE_MAX_TRIANGLES);
    if (bytes > ST_SCENE_MAX_MESH_BYTES)
        return fail(e,
                    "its %zu node instances would expand to %llu MiB of triangle meshes, more than "
                    "the limit of %llu MiB",
                    inst.size(), (unsigned long long)(bytes >> 20),
                    (unsigned long long)(ST_SCENE_MAX_MESH_BYTES >> 20));
    if (count >= (uint64_t)std::numeric_limits<int>::max() / 2)
        return fail(e, "too many mesh instances");
    r.meshes.v.reserve((size_t)count);
    for (const auto &[mi, w] : inst)
        for (const Prim &p : prims[mi])
            if (!p.idx.empty() && !make_mesh(p, w, r.meshes, e)) return false;
    return true;
}

// Walks the node tree of the default scene (or every root node when the file
// has no scenes), instancing meshes, lights and the first camera.
bool walk(const Model &m, bool want_camera, uint64_t tris_before, Result &r, std::string &e) {
    const size_t nn = m.nodes.size();
    std::vector<int> parents(nn, 0);
    for (size_t i = 0; i < nn; i++)
        for (int c : m.nodes[i].children) {
            if (c < 0 || (size_t)c >= nn)
                return fail(e, "nodes[%zu].children: node %d does not exist", i, c);
            if (++parents[(size_t)c] > 1) return fail(e, "nodes[%d] has more than one parent", c);
        }
    std::vector<int> roots;
    if (!m.scenes.empty()) {
        int si = m.defaultScene < 0 ? 0 : m.defaultScene;
        if ((size_t)si >= m.scenes.size())
            return fail(e, "scene: %d does not exist", m.defaultScene);
        roots = m.scenes[(size_t)si].nodes;
    } else {
        for (size_t i = 0; i < nn; i++)
            if (!parents[i]) roots.push_back((int)i);
    }
    // Converted primitives per mesh, shared by every node that uses it.
    std::vector<std::vector<Prim>> prims(m.meshes.size());
    std::vector<bool> converted(m.meshes.size(), false), seen(nn, false);
    std::vector<std::pair<size_t, Mat>> inst; // (mesh, world) per node with a mesh
    // Explicit stack: a deep hierarchy must not overflow the C stack. Pushed
    // in reverse so children are visited in file order.
    std::vector<std::pair<int, Mat>> stack;
    for (size_t i = roots.size(); i-- > 0;)
        stack.emplace_back(roots[i], identity());
    while (!stack.empty()) {
        auto [ni, parent] = stack.back();
        stack.pop_back();
        if (ni < 0 || (size_t)ni >= nn) return fail(e, "scenes: node %d does not exist", ni);
        if (seen[(size_t)ni])
            return fail(e, "nodes[%d] is reached twice; the nodes must form a tree", ni);
        seen[(size_t)ni] = true;
        const tinygltf::Node &n = m.nodes[(size_t)ni];
        Mat local;
        if (!local_transform(n, ni, local, e)) return false;
        Mat w = mul(parent, local);
        if (n.mesh >= 0 || n.mesh < -1) {
            if ((size_t)n.mesh >= m.meshes.size())
                return fail(e, "nodes[%d].mesh: %d does not exist", ni, n.mesh);
            size_t mi = (size_t)n.mesh;
            if (!converted[mi]) {
                const tinygltf::Mesh &mesh = m.meshes[mi];
                prims[mi].resize(mesh.primitives.size());
                for (size_t p = 0; p < mesh.primitives.size(); p++)
                    if (!convert_primitive(m, (int)mi, (int)p, prims[mi][p], e)) return false;
                converted[mi] = true;
            }
            inst.emplace_back(mi, w); // expanded below, once the total is known
        }
        if (n.camera >= 0 || n.camera < -1) {
            if ((size_t)n.camera >= m.cameras.size())
                return fail(e, "nodes[%d].camera: %d does not exist", ni, n.camera);
            // Only perspective cameras; an orthographic one cannot be the pinhole.
            if (want_camera && !r.has_camera && m.cameras[(size_t)n.camera].type == "perspective") {
                if (!make_camera(m, n.camera, ni, w, r.camera, e)) return false;
                r.has_camera = true;
            }
        }
        if (!node_light(m, n, ni, w, r.lights, e)) return false;
        for (size_t i = n.children.size(); i-- > 0;)
            stack.emplace_back(n.children[i], w);
    }
    return expand(prims, inst, tris_before, r, e);
}

// Hands the result to the scene; all or nothing.
bool commit(Result &r, st_scene *scene, bool *has_camera, st_err *err) {
    const int meshes0 = scene->num_meshes, lights0 = scene->num_lights;
    bool ok = true;
    for (st_mesh &m : r.meshes.v) {
        // add_mesh takes the arrays, or frees them when it fails.
        if (ok)
            ok = st_scene_add_mesh(scene, &m, err);
        else
            st_mesh_free(&m);
        memset(&m, 0, sizeof m);
    }
    for (const st_light_desc &l : r.lights)
        if (ok) ok = st_scene_add_light(scene, &l, err);
    if (!ok) {
        for (int i = meshes0; i < scene->num_meshes; i++)
            st_mesh_free(&scene->meshes[i]);
        scene->num_meshes = meshes0;
        scene->num_lights = lights0;
        return false;
    }
    if (has_camera && !*has_camera && r.has_camera) {
        scene->camera = r.camera;
        *has_camera = true;
    }
    return true;
}

// tinygltf converts JSON (extras, extensions) recursively: deep nesting would
// overflow the stack, so it is refused before parsing. Counts brackets
// outside strings; malformed JSON is left to the parser.
bool nesting_ok(const unsigned char *json, size_t len) {
    int depth = 0;
    bool in_string = false;
    for (size_t i = 0; i < len; i++) {
        unsigned char c = json[i];
        if (in_string) {
            if (c == '\\')
                i++;
            else if (c == '"')
                in_string = false;
        } else if (c == '"') {
            in_string = true;
        } else if (c == '[' || c == '{') {
            if (++depth > 256) return false;
        } else if (c == ']' || c == '}') {
            depth--;
        }
    }
    return true;
}

// Image URIs are never opened (textures are not used), but they obey the
// same rule as buffers: an absolute path or a ".." above the folder, or a
// file that resolves (symlinks) outside it, is refused.
bool images_inside(const Model &model, const AssetFs &fs, std::string &e) {
    if (fs.anywhere) return true;
    for (size_t i = 0; i < model.images.size(); i++) {
        const std::string &uri = model.images[i].uri;
        if (uri.empty() || tinygltf::IsDataURI(uri)) continue;
        std::string d = tinygltf::dlib::urldecode(uri);
        if (has_control(d))
            return fail(e, "images[%zu]: URI contains a NUL or control character", i);
        bool out = d[0] == '/';
        int depth = 0;
        for (size_t p = 0; !out && p < d.size();) {
            size_t q = d.find('/', p);
            if (q == std::string::npos) q = d.size();
            std::string seg = d.substr(p, q - p);
            if (seg == "..")
                out = --depth < 0;
            else if (!seg.empty() && seg != ".")
                depth++;
            p = q + 1;
        }
        char real[PATH_MAX];
        std::string full = fs.base.empty() ? d : fs.base + "/" + d;
        if (!out && realpath(full.c_str(), real)) out = !inside(fs.root, real);
        if (out)
            return fail(e,
                        "images[%zu]: URI '%.300s' is outside the glTF file's folder '%.300s' "
                        "(--allow-outside-assets allows it)",
                        i, d.c_str(), fs.root.c_str());
    }
    return true;
}

bool load(const unsigned char *data, size_t len, const char *name, const char *base_dir,
          bool anywhere, st_scene *scene, bool *has_camera, st_err *err) {
    if (len == 0) return st_fail(err, ST_ERR_INPUT, "%s: empty file", name);
    if (len >= std::numeric_limits<unsigned int>::max())
        return st_fail(err, ST_ERR_INPUT, "%s: larger than 4 GiB", name);
    bool binary = len >= 4 && !memcmp(data, "glTF", 4);
    // The JSON of a .glb is its first chunk; a bad header is tinygltf's to report.
    const unsigned char *json = data;
    size_t json_len = len;
    if (binary && len >= 20) {
        uint32_t n = (uint32_t)data[12] | (uint32_t)data[13] << 8 | (uint32_t)data[14] << 16 |
                     (uint32_t)data[15] << 24;
        json += 20;
        json_len = std::min<size_t>(n, len - 20);
    }
    if (!nesting_ok(json, json_len))
        return st_fail(err, ST_ERR_INPUT, "%s: JSON nested deeper than 256 levels", name);
    AssetFs fs;
    fs.base = base_dir && base_dir[0] ? base_dir : ".";
    fs.anywhere = anywhere;
    char root[PATH_MAX];
    if (!anywhere && !realpath(fs.base.c_str(), root))
        return st_fail(err, ST_ERR_INPUT, "%s: folder '%s': %s", name, fs.base.c_str(),
                       strerror(errno));
    if (!anywhere) fs.root = root;
    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(skip_image, nullptr);
    loader.SetFsCallbacks(tinygltf::FsCallbacks{fs_exists, fs_expand, fs_read, fs_write, &fs});
    Model model;
    std::string terr, warn, e;
    bool ok =
        binary ? loader.LoadBinaryFromMemory(&model, &terr, &warn, data, (unsigned int)len, fs.base)
               : loader.LoadASCIIFromString(&model, &terr, &warn, (const char *)data,
                                            (unsigned int)len, fs.base);
    if (!ok && !fs.refused.empty())
        return st_fail(err, ST_ERR_INPUT, "%s: %s", name, fs.refused.c_str());
    if (!ok) return st_fail(err, ST_ERR_INPUT, "%s: %s", name, one_line(terr).c_str());
    Result r;
    if (!images_inside(model, fs, e) || !check_extensions(model, e) ||
        !walk(model, has_camera && !*has_camera, st_scene_triangle_count(scene), r, e))
        return st_fail(err, ST_ERR_INPUT, "%s: %s", name, e.c_str());
    if (!commit(r, scene, has_camera, err)) {
        st_err_prefix(err, "%s: ", name);
        return false;
    }
    // Image files are never opened, but they are the model's too: no output
    // may replace them either.
    for (const tinygltf::Image &im : model.images)
        if (!im.uri.empty() && !tinygltf::IsDataURI(im.uri)) {
            std::string d = tinygltf::dlib::urldecode(im.uri);
            fs.read.push_back(d[0] == '/' ? d : fs.base + "/" + d);
        }
    for (const std::string &f : fs.read)
        if (!st_scene_note_file(scene, f.c_str(), err)) return false;
    return true;
}

} // namespace

extern "C" bool st_gltf_load_memory(const void *data, size_t len, const char *name,
                                    const char *base_dir, st_scene *scene, bool *has_camera,
                                    st_err *err) {
    return st_gltf_load_memory_ex(data, len, name, base_dir, 0, scene, has_camera, err);
}

extern "C" bool st_gltf_load_memory_ex(const void *data, size_t len, const char *name,
                                       const char *base_dir, unsigned flags, st_scene *scene,
                                       bool *has_camera, st_err *err) {
    if (!name) name = "<glTF>";
    try {
        return load((const unsigned char *)data, len, name, base_dir,
                    (flags & ST_ASSETS_ANYWHERE) != 0, scene, has_camera, err);
    } catch (const std::bad_alloc &) {
        return st_fail(err, ST_ERR_RUNTIME, "%s: out of memory", name);
    } catch (const std::exception &x) {
        return st_fail(err, ST_ERR_INPUT, "%s: %s", name, x.what());
    } catch (...) {
        return st_fail(err, ST_ERR_INPUT, "%s: malformed glTF", name);
    }
}

extern "C" bool st_gltf_load(const char *path, st_scene *scene, bool *has_camera, st_err *err) {
    return st_gltf_load_ex(path, 0, scene, has_camera, err);
}

extern "C" bool st_gltf_load_ex(const char *path, unsigned flags, st_scene *scene, bool *has_camera,
                                st_err *err) {
    if (!path || !path[0]) return st_fail(err, ST_ERR_INPUT, "empty glTF path");
    try {
        std::vector<unsigned char> bytes;
        std::string e;
        if (!read_regular(path, bytes, e)) return st_fail(err, ST_ERR_INPUT, "%s", e.c_str());
        char dir[1024];
        st_path_dir(dir, sizeof dir, path);
        return st_gltf_load_memory_ex(bytes.data(), bytes.size(), path, dir, flags, scene,
                                      has_camera, err) &&
               st_scene_note_file(scene, path, err);
    } catch (const std::bad_alloc &) {
        return st_fail(err, ST_ERR_RUNTIME, "%s: out of memory", path);
    } catch (...) {
        return st_fail(err, ST_ERR_INPUT, "%s: cannot read", path);
    }
}
