// The thesis' Table 1 on this machine, plus the costs atlas_gi promises.
//   bench_atlas_gi [--frames F] [--sizes 512,1024] [--samples 10,25,...] SCENE.json...
// For every scene, atlas size and sample count: the median time of the
// gather pass (GPU timer query; the G-buffer is built once, the gather runs
// every frame by accumulating with tolerance 0), and the frame rate the
// thesis reports (gather + regular pass). Then, with the result cached:
// frames where only the camera moves (by 1 mm, same view, and along an
// orbit) against frames where nothing changes, and against no atlas_gi.
// Timings on llvmpipe are CPU times of the software rasterizer; compare them
// as ratios within one run.
#define _POSIX_C_SOURCE 200809L
#include "atlas.h"
#include "st_world.h"
#include "gi_bench.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const st_pass_stats *pass(st_world *w, const char *module, const char *name) {
    for (int i = 0; i < st_world_num_pass_stats(w); i++) {
        const st_pass_stats *s = st_world_pass_stats(w, i);
        if (!strcmp(s->module, module) && !strcmp(s->pass, name)) return s;
    }
    return NULL;
}

static bool frame(st_world *w, double *ms) {
    st_err err = {0};
    double t0 = st_now_ms();
    if (!st_world_frame(w, &err)) {
        fprintf(stderr, "frame: %s\n", err.msg);
        return false;
    }
    glFinish();
    if (ms) *ms = st_now_ms() - t0;
    return true;
}

static st_world *open_world(const st_scene *sc, int atlas, int samples, bool accumulate) {
    st_err err = {0};
    st_world_opts o = {.timing = true};
    st_world *w = st_world_create(sc, &o, &err);
    if (!w) {
        fprintf(stderr, "%s: %s\n", sc->path, err.msg);
        return NULL;
    }
    bool ok = st_world_set_param(w, "atlas_gi", "atlas_size", atlas, &err) &&
              st_world_set_param(w, "atlas_gi", "samples", samples, &err) &&
              st_world_set_param(w, "atlas_gi", "progressive", accumulate, &err) &&
              st_world_set_param(w, "atlas_gi", "tolerance", 0, &err) &&
              st_world_set_param(w, "atlas_gi", "max_frames", 65536, &err);
    if (!ok) {
        fprintf(stderr, "%s: %s\n", sc->path, err.msg);
        st_world_destroy(w);
        return NULL;
    }
    return w;
}

// The share of atlas texels that stand for surface (as the plugin builds it).
static double occupancy(const st_scene *sc, int size) {
    atlas a;
    st_err err = {0};
    atlas_opts o = {.size = size,
                    .max_size = 4096,
                    .gutter = 2,
                    .chart_angle_deg = 30,
                    .use_uv1 = atlas_meshes_have_uv1(sc->meshes, sc->num_meshes)};
    if (!atlas_build(&a, sc->meshes, sc->num_meshes, &o, &err)) return NAN;
    double f = (double)a.valid_texels / ((double)a.width * a.height);
    atlas_free(&a);
    return f;
}

int main(int argc, char **argv) {
    int frames = 3, sizes[8] = {512, 1024}, nsizes = 2, samples[16] = {10, 25, 50, 100, 200, 400},
        nsamples = 6;
    const char *scenes[8];
    int nscenes = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--frames") && i + 1 < argc)
            frames = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--sizes") && i + 1 < argc)
            nsizes = gi_parse_list(argv[++i], sizes, 8);
        else if (!strcmp(argv[i], "--samples") && i + 1 < argc)
            nsamples = gi_parse_list(argv[++i], samples, 16);
        else if (nscenes < 8)
            scenes[nscenes++] = argv[i];
    }
    if (!nscenes || frames < 1) {
        fprintf(stderr, "usage: bench_atlas_gi [--frames F] [--sizes 512,1024] [--samples "
                        "10,25,...] SCENE.json...\n");
        return 2;
    }
    st_err err = {0};
    st_context *ctx = st_context_create_headless(&err);
    if (!ctx) {
        fprintf(stderr, "%s\n", err.msg);
        return 1;
    }
    printf("renderer: %s\n", st_context_renderer());
    static double gather_ms[8][8][16];
    uint64_t tris[8] = {0};
    static double occ[8][8];
    st_scene sc_all[8];
    for (int s = 0; s < nscenes; s++) {
        memset(&sc_all[s], 0, sizeof sc_all[s]);
        if (!st_scene_load(scenes[s], &sc_all[s], &err)) {
            fprintf(stderr, "%s\n", err.msg);
            return 2;
        }
        tris[s] = st_scene_triangle_count(&sc_all[s]);
        for (int a = 0; a < nsizes; a++)
            occ[s][a] = occupancy(&sc_all[s], sizes[a]);
    }
    printf("%-16s %9s %9s %5s %14s %14s %10s %9s\n", "scene", "triangles", "atlas", "N",
           "gather ms (med)", "regular ms", "fps", "occupied");
    // Every scene's world lives at once and their frames alternate, so a
    // change in the machine's load hits all scenes alike.
    for (int a = 0; a < nsizes; a++)
        for (int k = 0; k < nsamples; k++) {
            st_world *ws[8];
            for (int s = 0; s < nscenes; s++) {
                ws[s] = open_world(&sc_all[s], sizes[a], samples[k], true);
                if (!ws[s]) return 1;
                frame(ws[s], NULL); // the atlas, the G-buffer, shader compilation
                frame(ws[s], NULL);
                st_world_reset_samples(ws[s]);
            }
            for (int f = 0; f < frames; f++)
                for (int s = 0; s < nscenes; s++)
                    frame(ws[s], NULL);
            for (int s = 0; s < nscenes; s++) {
                const char *base =
                    strrchr(scenes[s], '/') ? strrchr(scenes[s], '/') + 1 : scenes[s];
                const st_pass_stats *g = pass(ws[s], "atlas_gi", "gather"),
                                    *r = pass(ws[s], "world", "regular");
                double gm = st_median_f(g->gpu_ms, g->num_samples),
                       rm = st_median_f(r->gpu_ms, r->num_samples);
                gather_ms[s][a][k] = gm;
                printf("%-16s %9llu %4dx%-4d %5d %14.2f %14.2f %10.2f %9.3f\n", base,
                       (unsigned long long)tris[s], sizes[a], sizes[a], samples[k], gm, rm,
                       1000.0 / (gm + rm), occ[s][a]);
                st_world_destroy(ws[s]);
            }
            fflush(stdout);
        }
    for (int s = 0; s < nscenes; s++) {
        st_scene sc = sc_all[s];
        const char *base = strrchr(scenes[s], '/') ? strrchr(scenes[s], '/') + 1 : scenes[s];
        // Visibility's cost (BVH rays per sample), off and on interleaved, and
        // an atlas rebuild (what a geometry change costs: charts, packing,
        // exact coverage, G-buffer).
        {
            int nvis = samples[nsamples > 3 ? 3 : nsamples - 1];
            st_world *wv[2];
            for (int v = 0; v < 2; v++) {
                wv[v] = open_world(&sc, sizes[0], nvis, true);
                if (!wv[v] || !st_world_set_param(wv[v], "atlas_gi", "visibility", v, &err))
                    return 1;
                frame(wv[v], NULL);
                frame(wv[v], NULL);
                st_world_reset_samples(wv[v]);
            }
            for (int f = 0; f < frames; f++)
                frame(wv[0], NULL), frame(wv[1], NULL);
            double ms[2];
            for (int v = 0; v < 2; v++) {
                const st_pass_stats *g = pass(wv[v], "atlas_gi", "gather");
                ms[v] = st_median_f(g->gpu_ms, g->num_samples);
            }
            double rebuild[3];
            for (int r = 0; r < 3; r++) {
                st_world_invalidate(wv[0], ST_CHANGE_GEOMETRY);
                st_world_reset_samples(wv[0]);
                frame(wv[0], NULL);
                const st_pass_stats *gb = pass(wv[0], "atlas_gi", "gbuffer");
                rebuild[r] = gb->num_samples ? gb->cpu_ms[gb->num_samples - 1] : NAN;
            }
            printf("%s: atlas %d, %d samples: gather %.2f ms without visibility, %.2f ms with "
                   "(%.2fx); "
                   "atlas rebuild + G-buffer after a geometry change %.1f ms\n",
                   base, sizes[0], nvis, ms[0], ms[1], ms[1] / ms[0], st_median_d(rebuild, 3));
            st_world_destroy(wv[0]);
            st_world_destroy(wv[1]);
        }
        // Cached result: frames where only the camera moves against frames
        // where nothing changes, and against the same scene without atlas_gi,
        // interleaved frame by frame across two live worlds so both see the
        // same machine load.
        st_world *w = open_world(&sc, sizes[0], samples[0], false);
        st_scene plain_sc = {0};
        if (!w || !st_scene_load(scenes[s], &plain_sc, &err)) return 1;
        for (int m = 0; m < plain_sc.num_modules; m++)
            if (!strcmp(plain_sc.modules[m].name, "atlas_gi")) {
                free(plain_sc.modules[m].params);
                plain_sc.modules[m--] = plain_sc.modules[--plain_sc.num_modules];
            }
        st_world_opts o = {.timing = true};
        st_world *wp = st_world_create(&plain_sc, &o, &err);
        if (!wp) {
            fprintf(stderr, "%s\n", err.msg);
            return 1;
        }
        for (int i = 0; i < 3; i++)
            frame(w, NULL), frame(wp, NULL);
        int n = 61;
        double *t[5];
        for (int k = 0; k < 5; k++)
            t[k] = malloc((size_t)n * sizeof(double));
        st_camera *c = st_world_camera(w);
        float pos[3], tgt[3], up[3];
        memcpy(pos, c->position, sizeof pos);
        memcpy(tgt, c->target, sizeof tgt);
        memcpy(up, c->up, sizeof up);
        for (int i = 0; i < n; i++) {
            float p[3] = {pos[0] + ((i & 1) ? 0.001f : -0.001f), pos[1], pos[2]},
                  q[3] = {pos[0], pos[1], pos[2]};
            float ang = 0.35f * sinf(0.7f * (float)i), dx = pos[0] - tgt[0], dz = pos[2] - tgt[2];
            q[0] = tgt[0] + cosf(ang) * dx + sinf(ang) * dz;
            q[2] = tgt[2] - sinf(ang) * dx + cosf(ang) * dz;
            frame(w, &t[0][i]); // unchanged
            st_world_set_camera(w, p, tgt, up);
            frame(w, &t[1][i]); // camera moved 1 mm
            st_world_set_camera(wp, p, tgt, up);
            frame(wp, &t[2][i]); // no atlas_gi, camera moved 1 mm
            st_world_set_camera(w, q, tgt, up);
            frame(w, &t[3][i]); // orbit
            st_world_set_camera(wp, q, tgt, up);
            frame(wp, &t[4][i]);
            st_world_set_camera(w, pos, tgt, up);
            st_world_set_camera(wp, pos, tgt, up);
            frame(w, NULL);
            frame(wp, NULL);
        }
        double m[5];
        for (int k = 0; k < 5; k++)
            m[k] = st_median_d(t[k], n), free(t[k]);
        printf("%s: atlas_gi cached (atlas %d), median frame ms over %d interleaved rounds: "
               "unchanged %.3f, "
               "camera moved 1 mm %.3f (ratio %.3f), orbit %.3f; without atlas_gi: 1 mm %.3f, "
               "orbit %.3f "
               "(cached atlas_gi / none: %.3fx, %.3fx); atlas passes ran: gbuffer %u, gather %u\n",
               base, sizes[0], n, m[0], m[1], m[1] / m[0], m[3], m[2], m[4], m[1] / m[2],
               m[3] / m[4], pass(w, "atlas_gi", "gbuffer")->runs,
               pass(w, "atlas_gi", "gather")->runs);
        st_world_destroy(wp);
        st_world_destroy(w);
        st_scene_free(&plain_sc);
        st_scene_free(&sc_all[s]);
    }
    if (nscenes >= 2)
        for (int a = 0; a < nsizes; a++)
            for (int k = 0; k < nsamples; k++)
                printf("gather time ratio %s / %s (%llu vs %llu triangles), atlas %d, %d samples: "
                       "%.3f "
                       "(occupancy %.3f vs %.3f)\n",
                       scenes[1], scenes[0], (unsigned long long)tris[1],
                       (unsigned long long)tris[0], sizes[a], samples[k],
                       gather_ms[1][a][k] / gather_ms[0][a][k], occ[1][a], occ[0][a]);
    st_context_destroy(ctx);
    return 0;
}
