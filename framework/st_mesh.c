// Procedural meshes: quad, box, UV sphere. Vertices are generated in world
// space with an identity model matrix, flat normals per face for quads and
// boxes, analytic normals for spheres. Triangles wind counter-clockwise seen
// from the front (the side the normal points to).
#include "st_scene.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

static const float st_default_albedo = 0.75f;

// Zeroes the mesh, sets the defaults and allocates its arrays; returns false
// (mesh left empty) when out of memory.
static bool mesh_alloc(st_mesh *m, const char *name, uint32_t nv, uint32_t nt) {
    memset(m, 0, sizeof *m);
    strncpy(m->name, name, sizeof m->name - 1);
    for (int i = 0; i < 16; i++)
        m->model[i] = (i % 5 == 0) ? 1.0f : 0.0f;
    for (int c = 0; c < 3; c++)
        m->albedo[c] = st_default_albedo;
    m->positions = malloc((size_t)nv * 3 * sizeof(float));
    m->normals = malloc((size_t)nv * 3 * sizeof(float));
    m->indices = malloc((size_t)nt * 3 * sizeof(uint32_t));
    if (!m->positions || !m->normals || !m->indices) {
        st_mesh_free(m);
        return false;
    }
    m->num_vertices = nv;
    m->num_triangles = nt;
    return true;
}

// Writes quad `q` (4 vertices at 4q, 2 triangles at 2q) with normal
// normalize(u x v). Computed in double so thin quads keep an exact normal.
static void put_quad(st_mesh *m, uint32_t q, const float c[3], const float u[3], const float v[3]) {
    double n[3] = {(double)u[1] * v[2] - (double)u[2] * v[1],
                   (double)u[2] * v[0] - (double)u[0] * v[2],
                   (double)u[0] * v[1] - (double)u[1] * v[0]};
    double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (len > 0)
        for (int k = 0; k < 3; k++)
            n[k] /= len;
    float *p = m->positions + 12 * q, *nn = m->normals + 12 * q;
    for (int k = 0; k < 3; k++) {
        p[0 + k] = c[k];
        p[3 + k] = c[k] + u[k];
        p[6 + k] = c[k] + u[k] + v[k];
        p[9 + k] = c[k] + v[k];
        for (int j = 0; j < 4; j++)
            nn[3 * j + k] = (float)n[k];
    }
    uint32_t b = 4 * q, *t = m->indices + 6 * q;
    t[0] = b, t[1] = b + 1, t[2] = b + 2;
    t[3] = b, t[4] = b + 2, t[5] = b + 3;
}

void st_mesh_quad(st_mesh *m, const float corner[3], const float u[3], const float v[3]) {
    if (!mesh_alloc(m, "quad", 4, 2)) return;
    put_quad(m, 0, corner, u, v);
}

void st_mesh_box(st_mesh *m, const float mn[3], const float mx[3], bool inward) {
    if (!mesh_alloc(m, "box", 24, 12)) return;
    const float dx = mx[0] - mn[0], dy = mx[1] - mn[1], dz = mx[2] - mn[2];
    // Per face: corner, then u, v with u x v pointing outward.
    const float f[6][3][3] = {
        {{mn[0], mn[1], mn[2]}, {0, 0, dz}, {0, dy, 0}}, // -x
        {{mx[0], mn[1], mn[2]}, {0, dy, 0}, {0, 0, dz}}, // +x
        {{mn[0], mn[1], mn[2]}, {dx, 0, 0}, {0, 0, dz}}, // -y
        {{mn[0], mx[1], mn[2]}, {0, 0, dz}, {dx, 0, 0}}, // +y
        {{mn[0], mn[1], mn[2]}, {0, dy, 0}, {dx, 0, 0}}, // -z
        {{mn[0], mn[1], mx[2]}, {dx, 0, 0}, {0, dy, 0}}, // +z
    };
    // Swapping u and v flips both the normal and the winding.
    for (uint32_t i = 0; i < 6; i++)
        put_quad(m, i, f[i][0], inward ? f[i][2] : f[i][1], inward ? f[i][1] : f[i][2]);
    // mn + (mx - mn) can round away from mx: every coordinate is set to
    // exactly mn or mx, so faces meeting at an edge share bit-identical
    // corners (watertight: the exact ray test of regular.frag lets no pixel
    // through a gap of one float step between two faces).
    for (uint32_t v = 0; v < 24; v++)
        for (int k = 0; k < 3; k++) {
            float *p = &m->positions[3 * v + k];
            *p = *p == mn[k] ? mn[k] : mx[k];
        }
}

void st_mesh_sphere(st_mesh *m, const float center[3], float radius, int rings, int segments) {
    // Clamped so the counts stay within 32 bits (the parser rejects more).
    rings = rings < 2 ? 2 : rings > 16384 ? 16384 : rings;
    segments = segments < 3 ? 3 : segments > 16384 ? 16384 : segments;
    const uint32_t R = (uint32_t)rings, S = (uint32_t)segments;
    if (!mesh_alloc(m, "sphere", (R + 1) * (S + 1), 2 * S * (R - 1))) return;
    const double pi = 3.14159265358979323846;
    for (uint32_t i = 0; i <= R; i++) {
        // Exact poles, so the pole vertices of every segment coincide.
        double th = pi * i / R;
        double st = (i == 0 || i == R) ? 0.0 : sin(th), ct = i == 0 ? 1.0 : i == R ? -1.0 : cos(th);
        for (uint32_t j = 0; j <= S; j++) {
            double ph = 2.0 * pi * (j % S) / S;
            // -sin(phi) for z makes (ring, ring+1, segment+1) wind CCW from outside.
            double n[3] = {st * cos(ph), ct, -st * sin(ph)};
            size_t v = 3 * ((size_t)i * (S + 1) + j);
            for (int k = 0; k < 3; k++) {
                m->normals[v + k] = (float)n[k];
                m->positions[v + k] = (float)(center[k] + (double)radius * n[k]);
            }
        }
    }
    uint32_t *t = m->indices;
    for (uint32_t i = 0; i < R; i++) {
        for (uint32_t j = 0; j < S; j++) {
            uint32_t a = i * (S + 1) + j, b = a + S + 1, c = b + 1, d = a + 1;
            if (i != R - 1) t[0] = a, t[1] = b, t[2] = c, t += 3; // skips the south pole
            if (i != 0) t[0] = a, t[1] = c, t[2] = d, t += 3;     // skips the north pole
        }
    }
}

void st_mesh_free(st_mesh *m) {
    if (!m) return;
    free(m->positions);
    free(m->normals);
    free(m->uv1);
    free(m->indices);
    memset(m, 0, sizeof *m);
}
