// The reference's image loop: one view ray per pixel centre, spp samples of
// the stochastic terms, rows handed out to all cores.
#define _POSIX_C_SOURCE 200809L
#include "ref.h"
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#include "st_vec3.h"

typedef struct {
    double pos[3], f[3], r[3], u[3];
    double tan_half, aspect;
} ref_camera;

typedef struct {
    const st_ref_geometry *geo;
    const st_ref_options *opt;
    ref_camera cam;
    st_image *out;
    atomic_int next_row, rows_done;
} ref_job;

static bool camera_setup(const st_scene *sc, ref_camera *c, st_err *err) {
    const st_camera_desc *d = &sc->camera;
    double up[3];
    for (int k = 0; k < 3; k++) {
        c->pos[k] = d->position[k];
        c->f[k] = (double)d->target[k] - d->position[k];
        up[k] = d->up[k];
    }
    st_cross3(c->r, c->f, up);
    double lf = st_normalize3(c->f), lr = st_normalize3(c->r);
    if (!(lf > 0 && isfinite(lf)) || !(lr > 0 && isfinite(lr)))
        return st_fail(err, ST_ERR_INPUT,
                       "%s: camera: target equals position or up is parallel to the view",
                       sc->path);
    st_cross3(c->u, c->r, c->f);
    c->tan_half = tan(0.5 * d->fov_y * ST_PI / 180.0);
    c->aspect = (double)sc->width / sc->height;
    return true;
}

// The contract's pinhole: pixel (i, j), j = 0 the top row, through its centre.
static void camera_ray(const ref_camera *c, int i, int j, int w, int h, double dir[3]) {
    double x = (2.0 * (i + 0.5) / w - 1.0) * c->tan_half * c->aspect;
    double y = (1.0 - 2.0 * (j + 0.5) / h) * c->tan_half;
    for (int k = 0; k < 3; k++)
        dir[k] = c->f[k] + x * c->r[k] + y * c->u[k];
    st_normalize3(dir);
}

static void render_pixel(const ref_job *job, int i, int j) {
    const st_ref_geometry *g = job->geo;
    const st_ref_options *o = job->opt;
    const st_scene *sc = g->desc;
    const int w = job->out->width, h = job->out->height;
    double dir[3];
    camera_ray(&job->cam, i, j, w, h, dir);
    // near/far clip like the rasterizer: planes at view depth, so along this
    // ray at depth / cos(angle to the view axis). A view ray that hits
    // nothing within them is marched to the far plane.
    double cos_axis = st_dot3(dir, job->cam.f);
    double t_near = sc->camera.near_z / cos_axis, t_far = sc->camera.far_z / cos_axis;
    st_ref_surface x = st_ref_intersect(g, job->cam.pos, dir, t_near, t_far);
    double s = x.hit ? x.t : t_far;

    const bool want_direct = o->aov == ST_REF_COMBINED || o->aov == ST_REF_DIRECT;
    const bool want_indirect = (o->aov == ST_REF_COMBINED || o->aov == ST_REF_INDIRECT) &&
                               o->bounces > 0 && x.hit && x.lit_side;
    const bool want_inscatter =
        (o->aov == ST_REF_COMBINED || o->aov == ST_REF_INSCATTER) && sc->medium.present;
    double direct[3] = {0, 0, 0}, T[3] = {1, 1, 1};
    // A varying density makes the transmittances (view ray, light paths)
    // random estimates: direct light and T are then drawn per sample below.
    const bool varies = sc->medium.present && st_density_varies(&sc->density);
    if (want_direct && !varies) st_ref_direct(g, &x, NULL, direct);
    // A ray that hits nothing sees the background at the far plane (dimmed by T below).
    if (want_direct && !x.hit)
        for (int c = 0; c < 3; c++)
            direct[c] = sc->background[c];
    if (sc->medium.present && !varies)
        for (int c = 0; c < 3; c++)
            T[c] = exp(-((double)sc->medium.sigma_s[c] + sc->medium.sigma_a[c]) * s);

    st_ref_rng rng;
    st_ref_rng_seed(&rng, o->seed, (uint64_t)j * (uint64_t)w + (uint64_t)i);
    const int spp = o->spp > 0 ? o->spp : 1;
    // Welford's running mean and squared deviations, per channel.
    double mean[3] = {0, 0, 0}, m2[3] = {0, 0, 0};
    const bool stochastic = want_indirect || want_inscatter || varies;
    const int n = stochastic ? spp : 1; // direct light alone has no noise
    for (int k = 0; k < n; k++) {
        double ind[3] = {0, 0, 0}, ins[3] = {0, 0, 0}, v[3];
        if (varies && want_direct && x.hit) st_ref_direct(g, &x, &rng, direct);
        if (varies) st_ref_transmittance(g, job->cam.pos, dir, 0.0, s, &rng, T);
        if (want_indirect) st_ref_indirect(g, o, &x, o->bounces, &rng, ind);
        if (want_inscatter) st_ref_inscatter(g, o, job->cam.pos, dir, s, &rng, ins);
        for (int c = 0; c < 3; c++) {
            switch (o->aov) {
            case ST_REF_DIRECT:
                v[c] = direct[c];
                break;
            case ST_REF_INDIRECT:
                v[c] = ind[c];
                break;
            case ST_REF_INSCATTER:
                v[c] = ins[c];
                break;
            case ST_REF_COMBINED:
            default:
                v[c] = (direct[c] + ind[c]) * T[c] + ins[c];
                break;
            }
            double delta = v[c] - mean[c];
            mean[c] += delta / (k + 1);
            m2[c] += delta * (v[c] - mean[c]);
        }
    }
    float *px = st_image_px(job->out, i, j);
    for (int c = 0; c < 3; c++) {
        px[c] = (float)mean[c];
        // Standard error of the mean; 0 where it cannot be estimated (1 sample).
        px[3 + c] = n > 1 ? (float)sqrt(m2[c] / (n - 1) / n) : 0.0f;
    }
}

static void *worker(void *arg) {
    ref_job *job = arg;
    for (;;) {
        int j = atomic_fetch_add(&job->next_row, 1);
        if (j >= job->out->height) break;
        for (int i = 0; i < job->out->width; i++)
            render_pixel(job, i, j);
        atomic_fetch_add(&job->rows_done, 1);
    }
    return NULL;
}

static int thread_count(const st_ref_options *o, int rows) {
    long n = o->threads > 0 ? o->threads : sysconf(_SC_NPROCESSORS_ONLN);
    if (n < 1) n = 1;
    if (n > rows) n = rows;
    if (n > 256) n = 256;
    return (int)n;
}

bool st_ref_render(const st_scene *scene, const st_ref_options *o, st_image *out, st_err *err) {
    memset(out, 0, sizeof *out);
    ref_job job;
    memset(&job, 0, sizeof job);
    if (scene->width < 1 || scene->height < 1)
        return st_fail(err, ST_ERR_INPUT, "image size %dx%d", scene->width, scene->height);
    if (!camera_setup(scene, &job.cam, err)) return false;
    st_ref_geometry geo;
    if (!st_ref_geometry_build(&geo, scene, err)) return false;
    if (!st_image_alloc(out, scene->width, scene->height, 6, err)) {
        st_ref_geometry_free(&geo);
        return false;
    }
    job.geo = &geo;
    job.opt = o;
    job.out = out;
    atomic_init(&job.next_row, 0);
    atomic_init(&job.rows_done, 0);

    const int nt = thread_count(o, scene->height);
    pthread_t th[256];
    int started = 0;
    for (; started < nt; started++)
        if (pthread_create(&th[started], NULL, worker, &job)) break;
    if (started == 0) worker(&job); // no threads to be had: render here
    while (atomic_load(&job.rows_done) < scene->height) {
        nanosleep(&(struct timespec){0, 10 * 1000 * 1000},
                  NULL); // cheap; keeps small renders snappy
        if (o->progress) o->progress(o->progress_user, atomic_load(&job.rows_done), scene->height);
    }
    for (int k = 0; k < started; k++)
        pthread_join(th[k], NULL);
    if (o->progress) o->progress(o->progress_user, scene->height, scene->height);
    st_ref_geometry_free(&geo);
    return true;
}
