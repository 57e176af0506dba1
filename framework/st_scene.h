// strahl: the scene description (JSON v1, see README.md) parsed into plain
// structs. Geometry is resolved (procedural shapes tessellated, glTF loaded)
// so the GPU world and the CPU reference read the same data.
#ifndef ST_SCENE_H
#define ST_SCENE_H
#include "st_base.h"

#ifdef __cplusplus
extern "C" {
#endif

#define ST_NAME_MAX 64

// Upper bound on a scene's triangles (procedural shapes plus glTF instances):
// absurd inputs fail with ST_ERR_INPUT instead of exhausting memory. The fuzz
// build lowers it.
#ifndef ST_SCENE_MAX_TRIANGLES
#define ST_SCENE_MAX_TRIANGLES (1ull << 27)
#endif
// Upper bound on the bytes one glTF's node instances expand to (positions,
// normals, UVs and indices copied per instance), summed before any copy.
#ifndef ST_SCENE_MAX_MESH_BYTES
#define ST_SCENE_MAX_MESH_BYTES (2ull << 30)
#endif

typedef struct st_camera_desc {
    float position[3], target[3], up[3];
    float fov_y; // full vertical field of view, degrees
    float near_z, far_z;
} st_camera_desc;

// Light types. Zero-initialised descriptors are point lights.
typedef enum {
    ST_LIGHT_POINT = 0,
    ST_LIGHT_DIRECTIONAL,
    ST_LIGHT_SPOT,
    ST_LIGHT_TYPE_COUNT
} st_light_type;
// Bit (1u << type) per type, for what a technique supports.
#define ST_LIGHT_BIT(type) (1u << (unsigned)(type))
#define ST_LIGHT_BITS_ALL                                                                          \
    (ST_LIGHT_BIT(ST_LIGHT_POINT) | ST_LIGHT_BIT(ST_LIGHT_DIRECTIONAL) |                           \
     ST_LIGHT_BIT(ST_LIGHT_SPOT))

typedef struct st_light_desc {
    float position[3]; // point, spot
    // Point: radiant intensity, W/sr per channel. Spot: the same on its axis.
    // Directional: irradiance on a surface facing the light, W/m^2.
    float intensity[3];
    st_light_type type;
    float direction[3];             // directional, spot: unit direction the light travels
    float inner_angle, outer_angle; // spot: half-angles from the axis, radians (glTF's falloff)
    // Directional: full angle of the sun's disc, radians; 0 = ST_SUN_ANGULAR_DIAMETER. Only the
    // screen-space god-ray techniques draw the disc; lighting and shadows treat the sun as one
    // direction (st_light_angular_diameter resolves the default).
    float angular_diameter;
} st_light_desc;

// The sun's mean angular diameter seen from the earth, 0.53 degrees in radians.
#define ST_SUN_ANGULAR_DIAMETER 0.00925024503f
float st_light_angular_diameter(const st_light_desc *l); // directional lights only

const char *st_light_type_name(st_light_type type); // "point", "directional", "spot"

// A still image's pixel filter (docs/physics.md): point, the radiance through
// the pixel's centre (one rasterised frame; the zero value, for scenes made in
// code), or box, the mean radiance over the pixel's square (the scene file's
// default: "image": {"filter": "box"}).
typedef enum { ST_FILTER_POINT = 0, ST_FILTER_BOX } st_pixel_filter;
const char *st_filter_name(st_pixel_filter f); // "point", "box"
bool st_filter_parse(const char *s, st_pixel_filter *out);

typedef enum { ST_PHASE_ISOTROPIC = 0, ST_PHASE_RAYLEIGH, ST_PHASE_HG } st_phase_kind;

// medium.density: how the medium's density varies in space. sigma_s and
// sigma_a are scaled by it (docs/physics.md "Heterogeneous media").
typedef enum {
    ST_DENSITY_UNIFORM = 0, // no "density" key: the homogeneous medium, density 1
    ST_DENSITY_HEIGHT,      // exponential height fog e^(-falloff (y - base))
    ST_DENSITY_GRID         // an OpenVDB float grid, trilinear between voxel centres
} st_density_kind;

// A float grid densified over its active voxels' bounding box plus a ring of
// zero voxels, so the trilinear density falls to 0 at the block's faces and
// is 0 outside it. Voxel (i, j, k) of the block has index coordinate
// lo + (i, j, k); its centre is at that index coordinate (OpenVDB's
// convention), placed in the world by the affine map to_world.
typedef struct st_density_grid {
    int n[3];                // voxels per axis (>= 3), x fastest in values
    int lo[3];               // index coordinate of values[0]
    float *values;           // n[0] n[1] n[2] finite values >= 0
    double to_world[12];     // 3x4 row major: world = M (i, j, k, 1)
    double to_index[12];     // its inverse
    double bmin[3], bmax[3]; // world bounds of the block (density 0 outside)
    double max_value;        // largest voxel value: bounds the trilinear density
} st_density_grid;

typedef struct st_density_desc {
    st_density_kind kind;
    double base, falloff;  // ST_DENSITY_HEIGHT: y0 [m] and k >= 0 [1/m]
    st_density_grid *grid; // ST_DENSITY_GRID: owned by the scene
} st_density_desc;

typedef struct st_medium_desc {
    bool present;
    float sigma_s[3], sigma_a[3]; // 1/m
    st_phase_kind phase;
    float g; // HG asymmetry, clamped to |g| <= 0.999 by the parser
} st_medium_desc;

// One triangle mesh. Positions/normals are in object space; `model` (column
// major, as cglm/GL) places it in the world. Normals are per vertex.
typedef struct st_mesh {
    char name[ST_NAME_MAX];
    float *positions;  // 3 * num_vertices
    float *normals;    // 3 * num_vertices
    float *uv1;        // 2 * num_vertices (lightmap UVs, TEXCOORD_1) or NULL
    uint32_t *indices; // 3 * num_triangles
    uint32_t num_vertices, num_triangles;
    float model[16];
    float albedo[3];
    float emission[3]; // outgoing radiance of a Lambertian emitter
    bool double_sided;
} st_mesh;

typedef enum { ST_VALUE_NUMBER = 0, ST_VALUE_BOOL, ST_VALUE_STRING } st_value_type;

typedef struct st_value {
    st_value_type type;
    double number; // also 0/1 for bools
    char str[ST_NAME_MAX];
} st_value;

typedef struct st_param_setting {
    char name[ST_NAME_MAX];
    st_value value;
    char set_arg[128]; // the --set argument that gave the value ("": the scene file)
} st_param_setting;

typedef struct st_module_setting {
    char name[ST_NAME_MAX];
    st_param_setting *params;
    int num_params;
} st_module_setting;

typedef struct st_scene {
    char path[1024]; // the scene file
    char dir[1024];  // its folder; relative asset paths resolve here
    int width, height;
    st_camera_desc camera;
    st_light_desc *lights;
    int num_lights;
    st_mesh *meshes;
    int num_meshes;
    st_medium_desc medium;
    // Radiance [W/(m^2 sr)] of what camera rays see where they leave the scene
    // ("background" key; black when absent): drawn behind all geometry, at the far
    // plane (so a medium dims it like a surface there), and the sky that mitchell and
    // sousa blur as their emitter. It lights no surface (no environment lighting).
    float background[3];
    bool has_background;
    st_module_setting *modules;
    int num_modules;
    int mesh_capacity, light_capacity; // allocated lengths, grown by st_scene_add_*
    st_pixel_filter filter;            // "image.filter"; box when the file does not say
    // medium.density (kind ST_DENSITY_UNIFORM without one). Here and not in
    // st_medium_desc because fields of st_scene are only appended (plugin ABI).
    st_density_desc density;
    // "inscatter_overlay": true lets two techniques that compute the medium's
    // in-scattering (plugins providing ST_CAP_INSCATTER) run in one world, each
    // adding its light: a comparison overlay, never a physical image.
    bool inscatter_overlay;
    // No camera in the file or its glTF files: ST_AUTO_CAMERA framed the
    // geometry's bounds (st_scene_auto_camera).
    bool camera_auto;
    // Every file of the scene: the scene file, each glTF with its buffers
    // and image files (never opened, still the model's), a VDB; path as
    // opened, st_dev/st_ino when loaded. Outputs are checked against them
    // (st_scene_check_output), so no render overwrites its own input.
    struct st_scene_file *files;
    int num_files;
} st_scene;

typedef struct st_scene_file {
    char *path;
    uint64_t dev, ino;
} st_scene_file;
// Notes that the scene read `path` (its identity now); false only when out
// of memory. A path that cannot be stat'ed is skipped.
bool st_scene_note_file(st_scene *scene, const char *path, st_err *err);
// The output check that needs the loaded scene (st_check_output runs before
// it): `path` must not be any file of the scene. `flag` ("-o",
// "capture") starts the message, which names the asset (ST_ERR_INPUT).
bool st_scene_check_output(const st_scene *scene, const char *flag, const char *path, st_err *err);
// Frees the list (st_scene_free calls it).
void st_scene_files_free(st_scene *scene);

// Parses and validates a scene file. Strict: unknown keys, wrong types,
// NaN/Inf, out-of-range values and missing files fail with an ST_ERR_INPUT
// message naming the file and key path ("scene.json: geometry[2].quad.u: ...").
bool st_scene_load(const char *path, st_scene *out, st_err *err);
// How a scene is loaded. Zero: the defaults.
enum {
    // glTF buffer and image URIs may resolve outside the glTF file's folder
    // tree (by default such a URI is refused: a downloaded model must not
    // read /etc/passwd into a render). The scene file's own paths are free.
    ST_ASSETS_ANYWHERE = 1u << 0,
    // A scene with no camera (neither the "camera" key nor a glTF camera) gets
    // one that frames its geometry (st_scene_auto_camera) instead of an error.
    ST_AUTO_CAMERA = 1u << 1,
};
typedef struct st_scene_opts {
    unsigned flags; // ST_ASSETS_*
} st_scene_opts;
bool st_scene_load_ex(const char *path, const st_scene_opts *opts, st_scene *out, st_err *err);
// Same from a string already in memory; `path` is used for messages and as
// the base of relative asset paths.
bool st_scene_parse(const char *json, size_t len, const char *path, st_scene *out, st_err *err);
bool st_scene_parse_ex(const char *json, size_t len, const char *path, const st_scene_opts *opts,
                       st_scene *out, st_err *err);
void st_scene_free(st_scene *scene);

// Applies "MODULE.PARAM=VALUE" (command line --set). The module must be in the
// scene. VALUE is a number, true/false, or a string.
bool st_scene_set(st_scene *scene, const char *assignment, st_err *err);

// Looks up a module setting by name (NULL if the scene does not load it).
st_module_setting *st_scene_module(st_scene *scene, const char *name);
// Adds or replaces one parameter (param must be an identifier < 64 chars).
bool st_module_setting_put(st_module_setting *m, const char *param, const st_value *value,
                           st_err *err);

// Appends a copy of a mesh (takes ownership of its arrays; on failure they
// are freed).
bool st_scene_add_mesh(st_scene *scene, const st_mesh *mesh, st_err *err);
bool st_scene_add_light(st_scene *scene, const st_light_desc *light, st_err *err);

// Procedural shapes (world-space vertices, identity model matrix).
void st_mesh_quad(st_mesh *m, const float corner[3], const float u[3], const float v[3]);
void st_mesh_box(st_mesh *m, const float mn[3], const float mx[3], bool inward);
// UV sphere with outward normals: `rings` latitude bands (>= 2), `segments`
// longitude slices (>= 3); 2 * segments * (rings - 1) triangles (single
// triangles at the poles, no degenerate ones). Both are clamped to 16384.
void st_mesh_sphere(st_mesh *m, const float center[3], float radius, int rings, int segments);
// The shape constructors leave positions == NULL when out of memory.
void st_mesh_free(st_mesh *m);
uint64_t st_scene_triangle_count(const st_scene *scene);
// World-space bounds of every mesh's vertices; false for a scene without any.
bool st_scene_bounds(const st_scene *scene, double lo[3], double hi[3]);
// A camera that sees the whole of the bounds lo..hi: 50 degrees vertical field
// of view, looking at their centre from above and in front (+z, +y, +x), far
// enough that the bounding sphere fits the view's height.
st_camera_desc st_scene_auto_camera(const double lo[3], const double hi[3]);

// glTF 2.0 (.gltf or .glb, told apart by the magic; tinygltf behind a C API,
// st_gltf.cpp): appends one mesh per primitive and node instance, and the
// point lights (KHR_lights_punctual, candela / 683 -> W/sr). If has_camera is
// not NULL and *has_camera is false, the first perspective camera met in the
// node tree becomes scene->camera and *has_camera is set. All or nothing: on
// failure the scene is left as it was.
// Buffer and image URIs must resolve inside the glTF file's folder tree
// unless flags has ST_ASSETS_ANYWHERE; a refused URI is named in the error.
bool st_gltf_load(const char *path, st_scene *scene, bool *has_camera, st_err *err);
bool st_gltf_load_ex(const char *path, unsigned flags, st_scene *scene, bool *has_camera,
                     st_err *err);
// Same from bytes in memory; `name` is used in messages, external buffers
// resolve against `base_dir`.
bool st_gltf_load_memory(const void *data, size_t len, const char *name, const char *base_dir,
                         st_scene *scene, bool *has_camera, st_err *err);
bool st_gltf_load_memory_ex(const void *data, size_t len, const char *name, const char *base_dir,
                            unsigned flags, st_scene *scene, bool *has_camera, st_err *err);

// OpenVDB (st_vdb.cpp, OpenVDB behind a C API): reads float grid `grid` of
// the .vdb file at `path` into *out (values densified, see st_density_grid),
// placed by the grid's own index-to-world map followed by world = translate +
// scale * p. Strict: a regular file under ST_VDB_MAX_FILE_BYTES, the grid
// present (the message lists the file's grids), of type float, with an
// affine transform, background 0, at most ST_VDB_MAX_VOXELS voxels in its
// active bounding box and every value there finite and >= 0. Messages name
// the file and the grid; the caller prefixes the key path.
#define ST_VDB_MAX_FILE_BYTES (1ull << 30)
#ifndef ST_VDB_MAX_VOXELS
#define ST_VDB_MAX_VOXELS (1ull << 25)
#endif
bool st_vdb_load(const char *path, const char *grid, const double translate[3],
                 const double scale[3], st_density_grid *out, st_err *err);
void st_density_grid_free(st_density_grid *g);

#ifdef __cplusplus
}
#endif
#endif
