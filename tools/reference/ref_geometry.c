// The reference's geometry: every mesh transformed to world space (in
// double, kept for shading) and handed to one Embree scene (in float, for
// ray casting), plus an area CDF over all triangles for area sampling.
#include "ref.h"
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "st_vec3.h"

// World positions and normals of one mesh. Normals go through the inverse
// transpose of the model's 3x3 part, as cofactors times the sign of the
// determinant (a mirroring model flips them with the winding; the length
// does not matter, they are normalized). A singular model (a glTF node
// scaled to 0 on one axis) keeps the normal of what it flattens, as on the GPU
// (framework/st_model.c).
static bool transform_mesh(const st_mesh *m, double *pos, double *nrm) {
    const float *M = m->model; // column major: M[col * 4 + row]
    double a[3][3];
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            a[r][c] = M[c * 4 + r];
    double cof[3][3];
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++) {
            int r1 = (r + 1) % 3, r2 = (r + 2) % 3, c1 = (c + 1) % 3, c2 = (c + 2) % 3;
            cof[r][c] = a[r1][c1] * a[r2][c2] - a[r1][c2] * a[r2][c1];
        }
    double det = a[0][0] * cof[0][0] + a[0][1] * cof[0][1] + a[0][2] * cof[0][2];
    if (!isfinite(det)) return false;
    double sign = det < 0 ? -1.0 : 1.0;
    static const float no_normal[3] = {0, 0, 0}; // a zero normal falls back to the geometric one
    for (uint32_t v = 0; v < m->num_vertices; v++) {
        const float *p = m->positions + 3 * v, *n = m->normals ? m->normals + 3 * v : no_normal;
        for (int r = 0; r < 3; r++) {
            pos[3 * v + r] = a[r][0] * p[0] + a[r][1] * p[1] + a[r][2] * p[2] + M[12 + r];
            nrm[3 * v + r] = sign * (cof[r][0] * n[0] + cof[r][1] * n[1] + cof[r][2] * n[2]);
        }
        st_normalize3(nrm + 3 * v);
    }
    return true;
}

static void rtc_error_message(RTCDevice dev, st_err *err, const char *what) {
    st_fail(err, ST_ERR_RUNTIME, "embree: %s failed (error %d)", what, (int)rtcGetDeviceError(dev));
}

// The per-mesh and per-triangle arrays (freed by st_ref_geometry_free).
static bool alloc_arrays(st_ref_geometry *g, st_err *err) {
    size_t nm = (size_t)(g->num_meshes > 0 ? g->num_meshes : 1);
    g->pos = calloc(nm, sizeof *g->pos);
    g->nrm = calloc(nm, sizeof *g->nrm);
    g->ng = calloc(nm, sizeof *g->ng);
    size_t nt = (size_t)(g->num_tris > 0 ? g->num_tris : 1);
    g->cdf = malloc(nt * sizeof *g->cdf);
    g->tri_mesh = malloc(nt * sizeof *g->tri_mesh);
    g->tri_prim = malloc(nt * sizeof *g->tri_prim);
    if (!g->pos || !g->nrm || !g->ng || !g->cdf || !g->tri_mesh || !g->tri_prim)
        return st_fail(err, ST_ERR_RUNTIME, "out of memory for %llu triangles",
                       (unsigned long long)g->num_tris);
    return true;
}

// Mesh i in world space (double), checked: its indices and model matrix.
static bool load_mesh(st_ref_geometry *g, const st_mesh *m, int i, st_err *err) {
    g->pos[i] = malloc((size_t)m->num_vertices * 3 * sizeof(double) + 1);
    g->nrm[i] = malloc((size_t)m->num_vertices * 3 * sizeof(double) + 1);
    g->ng[i] = malloc((size_t)m->num_triangles * 3 * sizeof(double) + 1);
    if (!g->pos[i] || !g->nrm[i] || !g->ng[i])
        return st_fail(err, ST_ERR_RUNTIME, "out of memory for mesh '%s'", m->name);
    for (uint32_t k = 0; k < 3 * m->num_triangles; k++)
        if (m->indices[k] >= m->num_vertices)
            return st_fail(err, ST_ERR_INPUT, "mesh %d ('%s'): vertex index %u out of range", i,
                           m->name, m->indices[k]);
    if (!transform_mesh(m, g->pos[i], g->nrm[i]))
        return st_fail(err, ST_ERR_INPUT, "mesh %d ('%s'): model matrix is not finite", i, m->name);
    return true;
}

// The running state of the triangle loop: the next triangle's index in the
// area CDF, the area so far and the world bounds of all vertices.
typedef struct build_state {
    uint64_t tri;
    double area, lo[3], hi[3];
} build_state;

// Mesh i's Embree geometry (float), its facet normals and its triangles'
// entries in the area CDF.
static bool add_mesh(st_ref_geometry *g, const st_mesh *m, int i, build_state *b, st_err *err) {
    RTCGeometry geo = rtcNewGeometry(g->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    float *vb = rtcSetNewGeometryBuffer(geo, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                        3 * sizeof(float), m->num_vertices);
    unsigned *ib = rtcSetNewGeometryBuffer(geo, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                           3 * sizeof(unsigned), m->num_triangles);
    if (!vb || !ib) {
        rtcReleaseGeometry(geo);
        rtc_error_message(g->device, err, "vertex buffer");
        return false;
    }
    for (uint32_t v = 0; v < 3 * m->num_vertices; v++) {
        vb[v] = (float)g->pos[i][v];
        b->lo[v % 3] = fmin(b->lo[v % 3], g->pos[i][v]);
        b->hi[v % 3] = fmax(b->hi[v % 3], g->pos[i][v]);
    }
    for (uint32_t t = 0; t < m->num_triangles; t++) {
        const uint32_t *ix = m->indices + 3 * t;
        for (int k = 0; k < 3; k++)
            ib[3 * t + k] = ix[k];
        const double *p0 = g->pos[i] + 3 * ix[0], *p1 = g->pos[i] + 3 * ix[1],
                     *p2 = g->pos[i] + 3 * ix[2];
        double e1[3], e2[3], *n = g->ng[i] + 3 * t;
        for (int k = 0; k < 3; k++)
            e1[k] = p1[k] - p0[k], e2[k] = p2[k] - p0[k];
        st_cross3(n, e1, e2);
        b->area += 0.5 * st_normalize3(n); // degenerate triangles add nothing and are never picked
        g->cdf[b->tri] = b->area;
        g->tri_mesh[b->tri] = i;
        g->tri_prim[b->tri] = t;
        b->tri++;
    }
    rtcCommitGeometry(geo);
    rtcAttachGeometryByID(g->scene, geo, (unsigned)i); // geomID == mesh index
    rtcReleaseGeometry(geo);
    return true;
}

// What the bounds give (ray offset, centre, radius), the medium's sigma_t
// and each sun's entry into the medium.
static bool finish(st_ref_geometry *g, const st_scene *scene, const build_state *b, st_err *err) {
    g->total_area = b->area;
    double diag = 0.0;
    for (int k = 0; k < 3; k++)
        diag += (b->hi[k] - b->lo[k]) * (b->hi[k] - b->lo[k]);
    diag = sqrt(diag);
    // Tolerances along rays (ties, back-side exits, a light resting on a
    // surface): far above float rounding of positions (~1e-7 relative) and
    // far below any feature a test measures. Not the origin offset of
    // secondary rays (st_ref_offset), which scales with the coordinates.
    g->eps = isfinite(diag) && diag > 0 ? 1e-5 * diag : 1e-6;
    st_medium_sigma_t(&scene->medium, g->sigma_t);
    for (int k = 0; k < 3; k++)
        g->center[k] = 0.5 * (b->lo[k] + b->hi[k]);
    g->radius = 0.5 * diag;
    g->light_entry =
        calloc(scene->num_lights ? (size_t)scene->num_lights : 1, sizeof *g->light_entry);
    if (!g->light_entry) return st_fail(err, ST_ERR_RUNTIME, "out of memory");
    for (int i = 0; i < scene->num_lights; i++)
        if (scene->lights[i].type == ST_LIGHT_DIRECTIONAL)
            g->light_entry[i] = st_directional_entry(scene, scene->lights[i].direction);
    return true;
}

bool st_ref_geometry_build(st_ref_geometry *g, const st_scene *scene, st_err *err) {
    memset(g, 0, sizeof *g);
    g->desc = scene;
    g->num_meshes = scene->num_meshes;
    g->num_tris = st_scene_triangle_count(scene);
    g->device = rtcNewDevice(NULL);
    if (!g->device) return st_fail(err, ST_ERR_RUNTIME, "embree: cannot create a device");
    g->scene = rtcNewScene(g->device);
    // Robust mode: rays through shared edges of closed boxes must not leak.
    rtcSetSceneFlags(g->scene, RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION);
    rtcSetSceneBuildQuality(g->scene, RTC_BUILD_QUALITY_HIGH);
    build_state b = {0, 0.0, {INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
    bool ok = alloc_arrays(g, err);
    for (int i = 0; ok && i < g->num_meshes; i++) {
        const st_mesh *m = &scene->meshes[i];
        ok = load_mesh(g, m, i, err);
        // A mesh without triangles has nothing to trace; mesh indices stay geomIDs.
        if (ok && m->num_triangles > 0) ok = add_mesh(g, m, i, &b, err);
    }
    if (ok) {
        rtcCommitScene(g->scene);
        if (rtcGetDeviceError(g->device) != RTC_ERROR_NONE) {
            rtc_error_message(g->device, err, "scene build");
            ok = false;
        }
    }
    if (ok) ok = finish(g, scene, &b, err);
    if (!ok) st_ref_geometry_free(g);
    return ok;
}

void st_ref_geometry_free(st_ref_geometry *g) {
    if (g->scene) rtcReleaseScene(g->scene);
    if (g->device) rtcReleaseDevice(g->device);
    for (int i = 0; i < g->num_meshes; i++) {
        if (g->pos) free(g->pos[i]);
        if (g->nrm) free(g->nrm[i]);
        if (g->ng) free(g->ng[i]);
    }
    free(g->pos);
    free(g->nrm);
    free(g->ng);
    free(g->cdf);
    free(g->light_entry);
    free(g->tri_mesh);
    free(g->tri_prim);
    memset(g, 0, sizeof *g);
}

// A surface record for triangle `prim` of mesh `mi` at barycentrics (u, v)
// (p = (1-u-v) p0 + u p1 + v p2), normals as on its front side.
static st_ref_surface make_surface(const st_ref_geometry *g, int mi, uint32_t prim, double u,
                                   double v) {
    st_ref_surface s = {0};
    const st_mesh *m = &g->desc->meshes[mi];
    const uint32_t *ix = m->indices + 3 * prim;
    const double w[3] = {1.0 - u - v, u, v};
    for (int k = 0; k < 3; k++) {
        for (int j = 0; j < 3; j++) {
            s.p[k] += w[j] * g->pos[mi][3 * ix[j] + k];
            s.n[k] += w[j] * g->nrm[mi][3 * ix[j] + k];
        }
        s.ng[k] = g->ng[mi][3 * prim + k];
    }
    st_normalize3(s.n);
    // The winding decides the front (as glFrontFace(GL_CCW) on the GPU); the
    // shading normal only shapes cosines and is kept on the geometric side.
    if (st_dot3(s.n, s.ng) <= 0.0) memcpy(s.n, s.ng, sizeof s.n);
    s.hit = true;
    s.mesh = m;
    s.geom = mi;
    s.prim = prim;
    return s;
}

// Turns the normals toward the side seen from `toward_viewer`; that side
// reflects and emits if it is the front or the mesh is double-sided.
static void face_viewer(st_ref_surface *s, const double toward_viewer[3]) {
    bool front = st_dot3(s->ng, toward_viewer) > 0.0;
    if (!front)
        for (int k = 0; k < 3; k++)
            s->n[k] = -s->n[k], s->ng[k] = -s->ng[k];
    s->lit_side = front || s->mesh->double_sided;
}

// A ray query's context: the geometry and which hits the filter drops.
typedef struct {
    struct RTCIntersectContext ctx; // first: Embree hands it back to the filter
    const st_ref_geometry *g;
    float back_until; // back-side hits nearer than this (ray units) are dropped
    bool lit_only;    // drop hits on the side of a one-sided surface that does not reflect
} ref_ctx;

// Context filter. A hit from behind within back_until of the origin is the
// ray leaving a solid it started in: a point on the seam where two boxes
// meet can lie inside the neighbouring box by float rounding, and its
// shadow and bounce rays would otherwise be trapped there.
// (Embree's RTCRayN/RTCHitN accessors are C++ only; the packets are
// structures of arrays: dir_x/y/z at rows 4-6 and tfar, the hit's distance
// during the filter, at row 8 of the ray; primID and geomID at rows 5 and 6
// of the hit, rtcore_ray.h.)
static void ref_filter(const struct RTCFilterFunctionNArguments *a) {
    const ref_ctx *c = (const ref_ctx *)a->context;
    const unsigned N = a->N, *hit = (const unsigned *)a->hit;
    const float *ray = (const float *)a->ray;
    for (unsigned i = 0; i < N; i++) {
        if (a->valid[i] != -1) continue;
        unsigned geom = hit[6 * N + i], prim = hit[5 * N + i];
        const double *ng = c->g->ng[geom] + 3 * prim;
        double dn = ng[0] * ray[4 * N + i] + ng[1] * ray[5 * N + i] + ng[2] * ray[6 * N + i];
        if (dn <= 0.0) continue;
        if (ray[8 * N + i] < c->back_until ||
            (c->lit_only && !c->g->desc->meshes[geom].double_sided))
            a->valid[i] = 0;
    }
}

static void ref_ctx_init(ref_ctx *c, const st_ref_geometry *g, double back_until, bool lit_only) {
    *c = (ref_ctx){.g = g, .back_until = (float)back_until, .lit_only = lit_only};
    rtcInitIntersectContext(&c->ctx);
    c->ctx.filter = ref_filter;
}

// The nearest hit in [tmin, tmax] (lit_side_only: on a side that reflects).
static bool nearest(const st_ref_geometry *g, const double o[3], const double d[3], double tmin,
                    double tmax, bool lit_side_only, struct RTCRayHit *rh) {
    double len = sqrt(st_dot3(d, d));
    ref_ctx c;
    ref_ctx_init(&c, g, tmin + 2.0 * g->eps / (len > 0 ? len : 1), lit_side_only);
    memset(rh, 0, sizeof *rh);
    rh->ray.org_x = (float)o[0], rh->ray.org_y = (float)o[1], rh->ray.org_z = (float)o[2];
    rh->ray.dir_x = (float)d[0], rh->ray.dir_y = (float)d[1], rh->ray.dir_z = (float)d[2];
    rh->ray.tnear = (float)tmin;
    rh->ray.tfar = (float)tmax;
    rh->ray.mask = 0xffffffffu;
    rh->hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh->hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(g->scene, &c.ctx, rh);
    return rh->hit.geomID != RTC_INVALID_GEOMETRY_ID;
}

st_ref_surface st_ref_intersect(const st_ref_geometry *g, const double o[3], const double d[3],
                                double tmin, double tmax) {
    st_ref_surface none = {0};
    struct RTCRayHit rh;
    if (!nearest(g, o, d, tmin, tmax, false, &rh)) return none;
    // A ray exactly through an edge where closed boxes meet (a room's corner
    // of wall boxes) ties the visible face with the hidden faces in contact,
    // and Embree may return a hidden one, seen from its back: black. A tie
    // goes to a side that reflects, if one lies within float rounding.
    if (!g->desc->meshes[rh.hit.geomID].double_sided) {
        const double *ng = g->ng[rh.hit.geomID] + 3 * rh.hit.primID;
        double len = sqrt(st_dot3(d, d)), w = 1e-2 * g->eps / (len > 0 ? len : 1);
        struct RTCRayHit lit;
        if (st_dot3(ng, d) > 0.0 &&
            nearest(g, o, d, fmax(tmin, rh.ray.tfar - w), fmin(tmax, rh.ray.tfar + w), true, &lit))
            rh = lit;
    }
    double back[3] = {-d[0], -d[1], -d[2]};
    st_ref_surface s = make_surface(g, (int)rh.hit.geomID, rh.hit.primID, rh.hit.u, rh.hit.v);
    face_viewer(&s, back);
    // The distance in the ray's units, from the double position on the triangle.
    double dd = st_dot3(d, d), t = 0.0;
    for (int k = 0; k < 3; k++)
        t += (s.p[k] - o[k]) * d[k];
    s.t = t / dd;
    return s;
}

int st_ref_intersect_all(const st_ref_geometry *g, const double o[3], const double d[3],
                         double tmin, double tmax, st_ref_surface *out, int max) {
    int n = 0;
    double t = tmin;
    while (n < max) {
        st_ref_surface s = st_ref_intersect(g, o, d, t, tmax);
        if (!s.hit) break;
        out[n++] = s;
        // Past this hit by the scene epsilon (d is unit here): a ray through
        // an edge shared by two triangles counts the surface once.
        t = s.t + g->eps;
    }
    return n;
}

bool st_ref_occluded(const st_ref_geometry *g, const double from[3], const double to[3]) {
    double d[3] = {to[0] - from[0], to[1] - from[1], to[2] - from[2]};
    double len = st_normalize3(d);
    if (!(len > g->eps)) return false;
    ref_ctx c; // d is unit: back_until in metres
    ref_ctx_init(&c, g, 2.0 * g->eps, false);
    struct RTCRay r;
    memset(&r, 0, sizeof r);
    r.org_x = (float)from[0], r.org_y = (float)from[1], r.org_z = (float)from[2];
    r.dir_x = (float)d[0], r.dir_y = (float)d[1], r.dir_z = (float)d[2];
    r.tnear = 0.0f;
    r.tfar = (float)(len - g->eps); // a light resting on a surface still lights it
    r.mask = 0xffffffffu;
    rtcOccluded1(g->scene, &c.ctx, &r);
    return r.tfar < 0.0f; // Embree sets tfar = -inf on a hit
}

bool st_ref_light_visible(const st_ref_geometry *g, const double from[3], const double at[3],
                          const st_incident *in) {
    double to[3];
    if (isfinite(in->dist)) {
        for (int k = 0; k < 3; k++)
            to[k] = at[k] + in->dist * in->to_light[k]; // the light itself
    } else { // past every triangle: beyond the bounding sphere
        double c[3] = {from[0] - g->center[0], from[1] - g->center[1], from[2] - g->center[2]};
        double len = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]) + g->radius + 2.0 * g->eps + 1.0;
        for (int k = 0; k < 3; k++)
            to[k] = from[k] + len * in->to_light[k];
    }
    return !st_ref_occluded(g, from, to);
}

// Secondary rays used to start 1e-5 x the scene's diagonal above the surface
// (g->eps). That also shifted them sideways: a shadow ray passing a shadow
// boundary closer than ~1e-4 m (godrays_hidden_hole, a floor point 1.3e-5 m
// inside the hole's edge) was blocked from the lifted point and lit from the
// point itself. The offset only has to clear float rounding (Waechter and
// Binder, Ray Tracing Gems ch. 6): p is computed in double on the exact
// triangle, so the error is Embree's float copy of the vertices and of the
// origin (half an ulp each) and its intersection arithmetic relative to the
// origin, all a few ulps of the largest coordinate of the triangle and of p.
// 2^-19 of that is 8-16 float ulps. Back-side hits within 2 g->eps (an
// origin inside a neighbouring box at a seam) are still dropped by the filter.
void st_ref_offset(const st_ref_geometry *g, const st_ref_surface *s, double out[3]) {
    double scale = FLT_MIN;
    const uint32_t *ix = g->desc->meshes[s->geom].indices + 3 * s->prim;
    for (int k = 0; k < 3; k++) {
        scale = fmax(scale, fabs(s->p[k]));
        for (int j = 0; j < 3; j++)
            scale = fmax(scale, fabs(g->pos[s->geom][3 * ix[j] + k]));
    }
    const double d = ldexp(scale, -19);
    for (int k = 0; k < 3; k++)
        out[k] = s->p[k] + d * s->ng[k];
}

st_ref_surface st_ref_sample_area(const st_ref_geometry *g, st_ref_rng *rng,
                                  const double viewer[3]) {
    st_ref_surface none = {0};
    if (g->num_tris == 0 || !(g->total_area > 0)) return none;
    double x = st_ref_rng_uniform(rng) * g->total_area;
    uint64_t lo = 0, hi = g->num_tris - 1;
    while (lo < hi) { // first triangle whose cumulative area exceeds x
        uint64_t mid = lo + (hi - lo) / 2;
        if (g->cdf[mid] > x)
            hi = mid;
        else
            lo = mid + 1;
    }
    // Uniform on the triangle: sqrt warping of two uniforms (Shirley).
    double r1 = sqrt(st_ref_rng_uniform(rng)), r2 = st_ref_rng_uniform(rng);
    double u = r1 * (1.0 - r2), v = r1 * r2;
    st_ref_surface s = make_surface(g, g->tri_mesh[lo], g->tri_prim[lo], u, v);
    double to_viewer[3] = {viewer[0] - s.p[0], viewer[1] - s.p[1], viewer[2] - s.p[2]};
    face_viewer(&s, to_viewer);
    s.t = sqrt(st_dot3(to_viewer, to_viewer));
    return s;
}
