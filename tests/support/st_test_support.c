// See st_test_support.h.
#include "st_test_support.h"
#include "st_test_render.h"
#include "st_world.h"

st_context *st_test_context(void) {
    st_err err = {0};
    st_context *ctx = st_context_create_headless(&err);
    if (!ctx) {
        fprintf(stderr, "FAIL: headless GL context: %s\n", err.msg);
        exit(1);
    }
    return ctx;
}

bool st_test_render_here(const char *scene, st_image *img, st_err *err) {
    return st_test_render_frames_here(scene, 0, img, err);
}

bool st_test_render_frames_here(const char *scene, int frames, st_image *img, st_err *err) {
    st_scene sc = {0};
    if (!st_scene_load(scene, &sc, err)) return false;
    sc.filter = ST_FILTER_POINT;
    st_world_opts o = {.filter = sc.filter};
    if (frames > 0) o.filter_max_frames = frames, o.filter_tolerance = -1; // as --frames N
    st_world *w = st_world_create(&sc, &o, err);
    bool ok = w != NULL;
    st_progress pr = {0};
    for (int f = 0; ok && f < (frames > 0 ? frames : 2000); f++)
        if (!(ok = st_world_frame(w, err)) ||
            (frames <= 0 && (!st_world_progress(w, &pr) || pr.converged)))
            break;
    ok = ok && st_world_read(w, img, err);
    st_world_destroy(w);
    st_scene_free(&sc);
    return ok;
}

cJSON *st_test_stats_json(const char *scene, const char *out, const char *extra, int *rc) {
    static char buf[1 << 16];
    char cmd[4096];
    snprintf(cmd, sizeof cmd, "%s render %s -o %s --stats=json --filter point %s 2>/dev/null",
             ST_TEST_STRAHL, scene, out, extra ? extra : "");
    *rc = st_test_capture(buf, sizeof buf, cmd);
    return cJSON_Parse(buf);
}

void st_test_write_shadow_scene(const char *path, const double lp[3], double I, double rho,
                                const double bmin[3], const double bmax[3], const char *modules) {
    char json[2048];
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": 96, \"height\": 96},\n"
             " \"camera\": {\"position\": [0, 3, 2.5], \"target\": [0, 0, 0], \"up\": [0, 1, 0], "
             "\"fov_y\": 60, \"near\": 0.05, \"far\": 100},\n"
             " \"lights\": [{\"type\": \"point\", \"position\": [%g, %g, %g], \"intensity\": [%g, "
             "%g, %g]}],\n"
             " \"geometry\": [{\"quad\": {\"corner\": [-4, 0, -4], \"u\": [0, 0, 8], \"v\": [8, 0, "
             "0]}, \"albedo\": [%g, %g, %g]},\n"
             "   {\"box\": {\"min\": [%g, %g, %g], \"max\": [%g, %g, %g]}}],\n"
             " \"modules\": [%s]}\n",
             lp[0], lp[1], lp[2], I, I, I, rho, rho, rho, bmin[0], bmin[1], bmin[2], bmax[0],
             bmax[1], bmax[2], modules);
    st_test_write(path, json);
}

int st_test_shadow_state(const double p[3], double jitter, const double lp[3], const double bmin[3],
                         const double bmax[3]) {
    int in = 0;
    const double off[5][2] = {{0, 0}, {1, 0}, {-1, 0}, {0, 1}, {0, -1}};
    for (int k = 0; k < 5; k++) {
        double q[3] = {p[0] + off[k][0] * jitter, 0, p[2] + off[k][1] * jitter};
        double d[3] = {lp[0] - q[0], lp[1] - q[1], lp[2] - q[2]};
        double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        for (int c = 0; c < 3; c++)
            d[c] /= len;
        double t = st_test_ray_box(q, d, bmin, bmax);
        in += t >= 0 && t < len;
    }
    return in == 5 ? 1 : in == 0 ? 0 : -1;
}

bool st_test_add_disk(st_scene *sc, int ns, double R, double h, double (*poly)[3], st_err *err) {
    st_mesh m = {0};
    snprintf(m.name, sizeof m.name, "disk");
    m.num_vertices = (uint32_t)ns + 1, m.num_triangles = (uint32_t)ns;
    m.positions = malloc(sizeof(float) * 3 * m.num_vertices);
    m.normals = malloc(sizeof(float) * 3 * m.num_vertices);
    m.indices = malloc(sizeof(uint32_t) * 3 * m.num_triangles);
    if (!m.positions || !m.normals || !m.indices) {
        free(m.positions), free(m.normals), free(m.indices);
        return st_fail(err, ST_ERR_RUNTIME, "out of memory");
    }
    double r = R * sqrt(2 * M_PI / (ns * sin(2 * M_PI / ns))); // same area as the disk
    m.positions[0] = 0, m.positions[1] = (float)h, m.positions[2] = 0;
    for (int k = 0; k < ns; k++) {
        double a = 2 * M_PI * k / ns, x = r * cos(a), z = r * sin(a);
        if (poly) poly[k][0] = x, poly[k][1] = h, poly[k][2] = z;
        float *v = m.positions + 3 * (k + 1);
        v[0] = (float)x, v[1] = (float)h, v[2] = (float)z;
        // (centre, k, k + 1) winds to face -y, toward the receiver.
        m.indices[3 * k] = 0, m.indices[3 * k + 1] = 1 + (uint32_t)k,
                      m.indices[3 * k + 2] = 1 + (uint32_t)((k + 1) % ns);
    }
    for (uint32_t k = 0; k < m.num_vertices; k++)
        m.normals[3 * k] = 0, m.normals[3 * k + 1] = -1, m.normals[3 * k + 2] = 0;
    for (int k = 0; k < 16; k++)
        m.model[k] = k % 5 == 0;
    m.emission[0] = m.emission[1] = m.emission[2] = 1;
    return st_scene_add_mesh(sc, &m, err);
}
