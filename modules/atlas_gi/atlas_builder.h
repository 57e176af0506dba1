// atlas_gi: the CPU atlas builder's working state, shared by its three files
// (private; the interface is atlas.h):
//   atlas_charts.c    world triangles, charts (or TEXCOORD_1) and packing
//   atlas_coverage.c  exact texel coverage: areas, overlaps, the points the
//                     rasterizer misses
//   atlas.c           atlas_build: the steps in order, the split meshes and
//                     the triangle tables
#ifndef ATLAS_GI_ATLAS_BUILDER_H
#define ATLAS_GI_ATLAS_BUILDER_H
#include "atlas.h"
#include <math.h>

// One triangle of one side, in world space.
typedef struct wtri {
    double p[3][3];  // corners
    double nv[3][3]; // world vertex normals
    double n[3];     // unit geometric normal (0 when degenerate)
    double area;     // m^2
} wtri;

typedef struct side {
    int mesh;
    bool back;
    uint32_t first, count; // triangles in the global list
} side;

typedef struct chart {
    int side;
    double w, h; // extent in metres after rotation
    int x0, y0;  // packed position: lower left of the padded rectangle (texels)
    int wt, ht;  // padded size in texels
} chart;

typedef struct builder {
    const st_mesh *meshes;
    int num_meshes;
    const atlas_opts *o;
    side *sides;
    int num_sides;
    wtri *tris;
    uint32_t num_tris;
    double extent;
    int32_t *tri_chart;
    double (*c2)[3][2]; // per corner: chart-plane coordinates (m)
    double (*uv)[3][2]; // per corner: atlas coordinates (texels)
    chart *charts;
    int num_charts;
    bool *single; // triangles forced into charts of their own (their chart folded)
} builder;

// Per-texel coverage while rasterizing (atlas_coverage.c).
typedef struct cover_ctx {
    builder *B;
    atlas *A;
    float *cover;      // atlas-space coverage per texel (1 = full)
    uint8_t *inside;   // a triangle's rasterizer covers the centre
    int32_t *chart;    // owner chart per texel
    uint8_t *conflict; // texel claimed by two charts
    bool *tri_hit;
    // pass 2
    int32_t *pidx;
    double (*acc)[8]; // per point: weight, position, normal, heaviest piece
    int32_t *amesh_of_tri;
} cover_ctx;

static inline double dot3(const double *a, const double *b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
static inline void cross3(const double *a, const double *b, double *o) {
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}
static inline double norm3(double *v) {
    double l = sqrt(dot3(v, v));
    if (l > 0)
        for (int k = 0; k < 3; k++)
            v[k] /= l;
    return l;
}

// atlas_charts.c
// Every side of every mesh as world triangles (B->sides, B->tris, B->extent).
bool ab_gather_triangles(builder *B, st_err *err);
// Charts every side (or takes TEXCOORD_1) and lays the atlas out: B->uv,
// B->tri_chart, A's size and density.
bool ab_make_layout(builder *B, atlas *A, st_err *err);

// atlas_coverage.c
// Rasterizes every triangle exactly into fresh per-texel buffers: A->area,
// C->cover, C->inside, C->chart, C->conflict, C->tri_hit. Returns whether a
// generated chart folded over itself (its triangles are marked single).
bool ab_cover(builder *B, atlas *A, cover_ctx *C, bool *folded, st_err *err);
// The invariants measured from the coverage (A->surface_area and friends).
void ab_invariants(const builder *B, atlas *A, const cover_ctx *C);
// The texels no rasterizer sample reaches, as points (A->points).
bool ab_points(builder *B, atlas *A, cover_ctx *C, st_err *err);
void ab_cover_free(cover_ctx *C);
#endif
