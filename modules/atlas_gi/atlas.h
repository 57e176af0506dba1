// atlas_gi: the CPU side of the texture atlas. Either takes every mesh's
// TEXCOORD_1 as it is, or generates an atlas: charts of connected,
// near-coplanar triangles projected onto their mean plane, rotated to their
// minimal bounding rectangle, scaled by one world-area-proportional density
// and shelf-packed with gutters. Then rasterizes every triangle exactly
// (polygon clipping against each texel square) to get each texel's world
// area, and lists the texels a GPU rasterizer would miss (centre outside
// every triangle) so the G-buffer pass can draw them as points: coverage is
// conservative, every triangle with area gets at least one texel.
//
// No GL here: the plugin and the tests share this file.
#ifndef ATLAS_GI_ATLAS_H
#define ATLAS_GI_ATLAS_H
#include "st_scene.h"

typedef struct atlas_opts {
    int size;                // W = H when fitting to a size (texels_per_meter == 0)
    double texels_per_meter; // > 0: fixed density, the atlas is the smallest power of two that
                             // holds it
    int max_size;            // the largest atlas allowed
    int gutter; // empty texels on each side of a chart (>= 2: one dilated ring + one free)
    double
        chart_angle_deg; // largest angle between a triangle's normal and its chart's plane normal
    bool use_uv1;        // the atlas is the meshes' TEXCOORD_1 (every mesh must have it)
    bool keep_chart_map; // keep per-texel chart ids (tests)
} atlas_opts;

// One side of one scene mesh with its vertices split along chart borders,
// uv1 = the atlas position in [0,1]^2. Triangle order is the scene mesh's.
typedef struct atlas_mesh {
    int scene_mesh;
    bool back;          // the back side of a double-sided mesh (normals and winding flipped)
    st_mesh mesh;       // object space, the scene mesh's model matrix and material
    uint32_t first_tri; // into atlas.tris
} atlas_mesh;

// A texel whose centre lies in no triangle: drawn as a point with these
// world attributes (area-weighted centroid and normal of its covered part).
typedef struct atlas_point {
    int x, y;
    float pos[3], nrm[3];
    int amesh; // atlas mesh the covered part belongs to
} atlas_point;

typedef struct atlas {
    int width, height;
    double texels_per_meter; // generated atlases: the density used; 0 for TEXCOORD_1
    int num_charts;
    atlas_mesh *meshes;
    int num_meshes;
    // Per texel, row 0 = GL's bottom row.
    float *area;         // world area in m^2 the texel stands for (0: gutter)
    int32_t *chart;      // chart id or -1 (only with keep_chart_map)
    int32_t *chart_mesh; // scene mesh of each chart (only with keep_chart_map)
    // Per atlas-mesh triangle, for the regular pass' uv lookup: world v0, e1,
    // e2 and the three atlas uvs, 16 floats (v0.xyz uv0.x, e1.xyz uv0.y, e2.xyz uv1.x, uv1.y uv2.xy
    // 0).
    float *tris;
    uint32_t num_tris;
    // The same triangles as the regular pass reads them, 12 floats each:
    // (v0.xyz, uv0.x), (gu.xyz, uv0.y), (gv.xyz, 0) with the atlas uv of a
    // point p on the triangle uv0 + (dot(p - v0, gu), dot(p - v0, gv)); gu x gv
    // points to the side's front (charts keep their orientation).
    float *lookup;
    // Per scene mesh: first entry of its front and back triangles in tris (-1: none).
    int32_t *mesh_base;
    atlas_point *points;
    int num_points;
    // Invariants, measured while rasterizing.
    double surface_area;   // sum of world triangle areas (both sides of double-sided meshes)
    double texel_area_sum; // sum of area[]
    long overlap_texels;   // texels covered by two charts, or twice by one
    long uncovered_tris;   // triangles with area but no texel
    long valid_texels;     // texels with area > 0
} atlas;

bool atlas_build(atlas *a, const st_mesh *meshes, int num_meshes, const atlas_opts *o, st_err *err);
void atlas_free(atlas *a);
// Does every mesh with triangles carry TEXCOORD_1?
bool atlas_meshes_have_uv1(const st_mesh *meshes, int num_meshes);

#endif
