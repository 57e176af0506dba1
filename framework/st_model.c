// ModelType/Model: one interleaved vertex buffer and one index buffer per
// type, uploaded once; models are ranges drawn with a base vertex.
#include "st_model.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    float p[3], n[3], uv[2];
} st_vertex;

// The inverse transpose of the model's 3x3 part up to a positive factor:
// its cofactor matrix times sign(det), scaled to a largest entry of 1 (every
// shader normalizes). Unlike the inverse it stays defined for a singular
// model: a glTF node scaled to 0 along a flat mesh's normal keeps that
// normal instead of turning it into NaN (a black surface).
static void normal_matrix(const float *M, float out[9]) {
    double a[3][3], cof[3][3], big = 0; // a[row][col]; M is column major
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            a[r][c] = M[c * 4 + r];
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++) {
            int r1 = (r + 1) % 3, r2 = (r + 2) % 3, c1 = (c + 1) % 3, c2 = (c + 2) % 3;
            cof[r][c] = a[r1][c1] * a[r2][c2] - a[r1][c2] * a[r2][c1];
            big = fmax(big, fabs(cof[r][c]));
        }
    double det = a[0][0] * cof[0][0] + a[0][1] * cof[0][1] + a[0][2] * cof[0][2];
    double s = (det < 0 ? -1.0 : 1.0) / (big > 0 ? big : 1.0);
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            out[c * 3 + r] = (float)(s * cof[r][c]); // column major
}

bool st_model_type_build(st_model_type *t, const char *name, const st_mesh *meshes, int n,
                         const float *uv1, st_model *models, st_err *err) {
    memset(t, 0, sizeof *t);
    snprintf(t->name, sizeof t->name, "%s", name);
    t->primitive = GL_TRIANGLES;
    t->stride = sizeof(st_vertex);
    t->attrs[0] = (st_vertex_attr){"st_position", ST_ATTR_POSITION, 3, offsetof(st_vertex, p)};
    t->attrs[1] = (st_vertex_attr){"st_normal", ST_ATTR_NORMAL, 3, offsetof(st_vertex, n)};
    t->attrs[2] = (st_vertex_attr){"st_uv1", ST_ATTR_UV1, 2, offsetof(st_vertex, uv)};
    t->num_attrs = 3;

    size_t nv = 0, ni = 0;
    for (int i = 0; i < n; i++) {
        nv += meshes[i].num_vertices;
        ni += (size_t)meshes[i].num_triangles * 3;
    }
    if (nv > INT32_MAX || ni > UINT32_MAX)
        return st_fail(err, ST_ERR_INPUT, "scene too large: %zu vertices, %zu indices", nv, ni);
    st_vertex *v = calloc(nv ? nv : 1, sizeof *v);
    uint32_t *idx = malloc((ni ? ni : 1) * sizeof *idx);
    if (!v || !idx) {
        free(v);
        free(idx);
        return st_fail(err, ST_ERR_RUNTIME, "out of memory for %zu vertices", nv);
    }
    size_t bv = 0, bi = 0;
    for (int i = 0; i < n; i++) {
        const st_mesh *m = &meshes[i];
        for (uint32_t k = 0; k < m->num_vertices; k++) {
            memcpy(v[bv + k].p, m->positions + 3 * k, sizeof v->p);
            memcpy(v[bv + k].n, m->normals + 3 * k, sizeof v->n);
            const float *uv = uv1 ? uv1 + 2 * (bv + k) : (m->uv1 ? m->uv1 + 2 * k : NULL);
            if (uv) memcpy(v[bv + k].uv, uv, sizeof v->uv);
        }
        memcpy(idx + bi, m->indices, (size_t)m->num_triangles * 3 * sizeof *idx);
        st_model *md = &models[i];
        memset(md, 0, sizeof *md);
        md->type = t;
        md->mesh = m;
        md->base_vertex = (int32_t)bv;
        md->first_index = (uint32_t)bi;
        md->index_count = m->num_triangles * 3;
        memcpy(md->model, m->model, sizeof md->model);
        normal_matrix(m->model, md->normal_matrix);
        memcpy(md->albedo, m->albedo, sizeof md->albedo);
        memcpy(md->emission, m->emission, sizeof md->emission);
        md->double_sided = m->double_sided;
        bv += m->num_vertices;
        bi += (size_t)m->num_triangles * 3;
    }
    bool ok = st_buffer_create(&t->vbo, GL_ARRAY_BUFFER, nv * sizeof *v, v, false, err) &&
              st_buffer_create(&t->ibo, GL_ELEMENT_ARRAY_BUFFER, ni * sizeof *idx, idx, false, err);
    free(v);
    free(idx);
    if (!ok) return false;
    glCreateVertexArrays(1, &t->vao);
    glVertexArrayVertexBuffer(t->vao, 0, t->vbo.id, 0, (GLsizei)t->stride);
    glVertexArrayElementBuffer(t->vao, t->ibo.id);
    for (int a = 0; a < t->num_attrs; a++) {
        glEnableVertexArrayAttrib(t->vao, t->attrs[a].location);
        glVertexArrayAttribFormat(t->vao, t->attrs[a].location, t->attrs[a].components, GL_FLOAT,
                                  GL_FALSE, (GLuint)t->attrs[a].offset);
        glVertexArrayAttribBinding(t->vao, t->attrs[a].location, 0);
    }
    return st_gl_check("model type", err);
}

void st_model_type_destroy(st_model_type *t) {
    if (t->vao) glDeleteVertexArrays(1, &t->vao);
    st_buffer_destroy(&t->vbo);
    st_buffer_destroy(&t->ibo);
    st_buffer_destroy(&t->instances);
    memset(t, 0, sizeof *t);
}

void st_model_type_draw(const st_model_type *t, const st_model *models, int n, st_shader *sh) {
    GLint l_model = st_shader_loc(sh, "st_model"), l_nm = st_shader_loc(sh, "st_normal_matrix"),
          l_alb = st_shader_loc(sh, "st_albedo"), l_em = st_shader_loc(sh, "st_emission"),
          l_ds = st_shader_loc(sh, "st_double_sided"), l_id = st_shader_loc(sh, "st_model_index");
    glBindVertexArray(t->vao);
    for (int i = 0; i < n; i++) {
        const st_model *m = &models[i];
        if (m->type != t || !m->index_count) continue;
        if (l_model >= 0) glUniformMatrix4fv(l_model, 1, GL_FALSE, m->model);
        if (l_nm >= 0) glUniformMatrix3fv(l_nm, 1, GL_FALSE, m->normal_matrix);
        if (l_alb >= 0) glUniform3fv(l_alb, 1, m->albedo);
        if (l_em >= 0) glUniform3fv(l_em, 1, m->emission);
        if (l_ds >= 0) glUniform1i(l_ds, m->double_sided);
        if (l_id >= 0) glUniform1i(l_id, i);
        glDrawElementsBaseVertex(t->primitive, (GLsizei)m->index_count, GL_UNSIGNED_INT,
                                 (void *)((size_t)m->first_index * sizeof(uint32_t)),
                                 m->base_vertex);
    }
}
