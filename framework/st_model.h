// strahl: ModelType and Model (thesis: ModelType, VertexAttribute,
// InstanceAttribute, Model): models of one type share one vertex and one
// index buffer. Part of the plugin SDK (a plugin may build its own type).
#ifndef ST_MODEL_H
#define ST_MODEL_H
#include "st_gpu.h"
#include "st_scene.h"
#include "st_shader.h"

#ifdef __cplusplus
extern "C" {
#endif

// Where one attribute lives in an interleaved vertex (thesis: VertexAttribute).
typedef struct st_vertex_attr {
    const char *name; // shader variable, e.g. "st_position"
    GLuint location;
    int components; // floats
    size_t offset;  // bytes into the vertex
} st_vertex_attr;

// Per-instance attribute (thesis: InstanceAttribute), divisor 1.
typedef struct st_instance_attr {
    const char *name;
    GLuint location;
    int components;
    size_t offset;
} st_instance_attr;

#define ST_MAX_ATTRS 8

// Models of one type share one vertex buffer and one index buffer.
typedef struct st_model_type {
    char name[ST_NAME_MAX];
    st_vertex_attr attrs[ST_MAX_ATTRS];
    int num_attrs;
    size_t stride;
    st_instance_attr inst_attrs[ST_MAX_ATTRS];
    int num_inst_attrs;
    size_t inst_stride;
    GLenum primitive;
    st_buffer vbo, ibo, instances;
    GLuint vao;
} st_model_type;

typedef struct st_model {
    st_model_type *type;
    const st_mesh *mesh; // the scene mesh it came from
    int32_t base_vertex;
    uint32_t first_index, index_count;
    float model[16], normal_matrix[9];
    float albedo[3], emission[3];
    bool double_sided;
} st_model;

// The standard layout: st_position (0, vec3), st_normal (1, vec3), st_uv1 (2, vec2).
enum { ST_ATTR_POSITION = 0, ST_ATTR_NORMAL = 1, ST_ATTR_UV1 = 2 };

// Builds one model type with the standard layout from meshes; `uv1` may
// override each mesh's lightmap UVs (2 floats per vertex, concatenated in mesh
// order) for modules that generate their own atlas. models[i] gets mesh i.
bool st_model_type_build(st_model_type *t, const char *name, const st_mesh *meshes, int n,
                         const float *uv1, st_model *models, st_err *err);
void st_model_type_destroy(st_model_type *t);
// Draws models with `sh` bound, setting st_model, st_normal_matrix, st_albedo,
// st_emission, st_double_sided per model.
void st_model_type_draw(const st_model_type *t, const st_model *models, int n, st_shader *sh);

#ifdef __cplusplus
}
#endif
#endif
