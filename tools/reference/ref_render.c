// The reference's image loop: spp samples per pixel, each with its view ray
// (the pixel centre for the point filter, a stratified point of the pixel's
// square for the box filter), rows handed out to all cores.
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
    atomic_bool failed; // a worker had no memory: rows are skipped, the render fails
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

// The contract's pinhole: pixel (i, j), j = 0 the top row, through the point
// (u, v) of its square (0.5, 0.5 the centre; v down the image).
static void camera_ray(const ref_camera *c, int i, int j, double u, double v, int w, int h,
                       double dir[3]) {
    double x = (2.0 * (i + u) / w - 1.0) * c->tan_half * c->aspect;
    double y = (1.0 - 2.0 * (j + v) / h) * c->tan_half;
    for (int k = 0; k < 3; k++)
        dir[k] = c->f[k] + x * c->r[k] + y * c->u[k];
    st_normalize3(dir);
}

// What one view ray sees: the surface it hits (or none), its direct light and
// the view ray's transmittance; the stochastic terms come per sample.
typedef struct {
    double dir[3], s, direct[3], T[3];
    st_ref_surface x;
} ref_view;

static void view_ray(const ref_job *job, int i, int j, double u, double v, ref_view *r) {
    const st_ref_geometry *g = job->geo;
    const st_ref_options *o = job->opt;
    const st_scene *sc = g->desc;
    camera_ray(&job->cam, i, j, u, v, job->out->width, job->out->height, r->dir);
    // near/far clip like the rasterizer: planes at view depth, so along this
    // ray at depth / cos(angle to the view axis). A view ray that hits
    // nothing within them is marched to the far plane.
    double cos_axis = st_dot3(r->dir, job->cam.f);
    double t_near = sc->camera.near_z / cos_axis, t_far = sc->camera.far_z / cos_axis;
    r->x = st_ref_intersect(g, job->cam.pos, r->dir, t_near, t_far);
    r->s = r->x.hit ? r->x.t : t_far;
    const bool want_direct = o->aov == ST_REF_COMBINED || o->aov == ST_REF_DIRECT;
    const bool varies = sc->medium.present && st_density_varies(&sc->density);
    for (int c = 0; c < 3; c++)
        r->direct[c] = 0, r->T[c] = 1;
    // A varying density makes the transmittances (view ray, light paths)
    // random estimates: direct light and T are then drawn per sample.
    if (want_direct && !varies) st_ref_direct(g, &r->x, NULL, r->direct);
    // A ray that hits nothing sees the background at the far plane (dimmed by T below).
    if (want_direct && !r->x.hit)
        for (int c = 0; c < 3; c++)
            r->direct[c] = sc->background[c];
    if (sc->medium.present && !varies)
        for (int c = 0; c < 3; c++)
            r->T[c] = exp(-((double)sc->medium.sigma_s[c] + sc->medium.sigma_a[c]) * r->s);
}

// The box filter's strata: an m x m grid over the pixel's square with at
// least 4 samples per cell (m = floor(sqrt(n / 4)), at most ST_REF_MAX_GRID),
// so each cell's own variance is estimated with 3 or more degrees of freedom
// (with 1, the standard error of an edge pixel, where one or two cells vary,
// would be too often far too small); the n - r m^2 samples past
// r whole passes over the grid are uniform over the square. Every sample is
// uniform over the square, so their mean is the box filter's value.
#define ST_REF_MAX_GRID 64
static int grid_size(int n) {
    int m = (int)floor(sqrt(n / 4.0));
    while (4 * (m + 1) * (m + 1) <= n)
        m++;
    return m < 1 ? 1 : m > ST_REF_MAX_GRID ? ST_REF_MAX_GRID : m;
}

// Sample k's point (u, v) of the square, and its cell (-1: past the passes).
static int pixel_point(int k, int m, int whole, st_ref_rng *rng, double *u, double *v) {
    double a = st_ref_rng_uniform(rng), b = st_ref_rng_uniform(rng);
    if (k >= whole) {
        *u = a, *v = b;
        return -1;
    }
    int q = k % (m * m);
    *u = (q % m + a) / m, *v = (q / m + b) / m;
    return q;
}

// What a pixel's samples need to know.
typedef struct {
    bool box, want_direct, want_indirect, want_inscatter, varies;
    int n; // samples (1 where nothing in the pixel is random)
} pixel_plan;

// One sample's value v of the pixel, its view ray already in r.
static void sample_value(const ref_job *job, const pixel_plan *pl, ref_view *r, st_ref_rng *rng,
                         double v[3]) {
    const st_ref_geometry *g = job->geo;
    const st_ref_options *o = job->opt;
    double ind[3] = {0, 0, 0}, ins[3] = {0, 0, 0};
    if (pl->varies && pl->want_direct && r->x.hit) st_ref_direct(g, &r->x, rng, r->direct);
    if (pl->varies) st_ref_transmittance(g, job->cam.pos, r->dir, 0.0, r->s, rng, r->T);
    if (pl->want_indirect && r->x.hit && r->x.lit_side)
        st_ref_indirect(g, o, &r->x, o->bounces, rng, ind);
    if (pl->want_inscatter) st_ref_inscatter(g, o, job->cam.pos, r->dir, r->s, rng, ins);
    for (int c = 0; c < 3; c++) {
        switch (o->aov) {
        case ST_REF_DIRECT:
            v[c] = r->direct[c];
            break;
        case ST_REF_INDIRECT:
            v[c] = ind[c];
            break;
        case ST_REF_INSCATTER:
            v[c] = ins[c];
            break;
        case ST_REF_COMBINED:
        default:
            v[c] = (r->direct[c] + ind[c]) * r->T[c] + ins[c];
            break;
        }
    }
}

// Independent samples (PCG32), the box filter's over its stratified grid;
// the standard error from the cells' own variances.
static void pixel_independent(const ref_job *job, const pixel_plan *pl, ref_view *r,
                              st_ref_rng *rng, double *cells, int i, int j, float *px) {
    const int n = pl->n;
    const int m = grid_size(n), whole = n / (m * m) * (m * m), per_cell = n / (m * m);
    // Welford's running mean and squared deviations, per channel.
    double mean[3] = {0, 0, 0}, m2[3] = {0, 0, 0}, v[3];
    if (pl->box) memset(cells, 0, sizeof(double) * 6 * (size_t)(m * m));
    for (int k = 0; k < n; k++) {
        int cell = -1;
        if (pl->box) {
            double u, w;
            cell = pixel_point(k, m, whole, rng, &u, &w);
            view_ray(job, i, j, u, w, r);
        }
        sample_value(job, pl, r, rng, v);
        for (int c = 0; c < 3; c++) {
            double delta = v[c] - mean[c];
            mean[c] += delta / (k + 1);
            m2[c] += delta * (v[c] - mean[c]);
            if (cell >= 0) cells[6 * cell + c] += v[c], cells[6 * cell + 3 + c] += v[c] * v[c];
        }
    }
    for (int c = 0; c < 3; c++) {
        px[c] = (float)mean[c];
        // Standard error of the mean; 0 where it cannot be estimated (1 sample).
        double var_mean = n > 1 ? m2[c] / (n - 1) / n : 0;
        if (pl->box && n > 1 && per_cell >= 4) {
            // Stratified: the cells' own variances (r = per_cell samples each),
            // plus the uniform rest with the pixel's variance.
            double within = 0;
            for (int q = 0; q < m * m; q++) {
                double s1 = cells[6 * q + c], s2 = cells[6 * q + 3 + c];
                within += fmax(0.0, (s2 - s1 * s1 / per_cell) / (per_cell - 1)) * per_cell;
            }
            var_mean = (within + (n - whole) * m2[c] / (n - 1)) / ((double)n * n);
        }
        px[3 + c] = (float)sqrt(var_mean);
    }
}

// Owen-scrambled Sobol points in ST_REF_BATCHES independent batches, each
// with its own scrambles: the samples of a batch are correlated (that is
// what stratifies them), the batches are not, so the batch means give an
// honest standard error (B - 1 degrees of freedom) of their mean, the
// pixel's value. Sample k is in batch k mod B, so a pixel's batches differ
// in size by at most one sample; each batch mean is unbiased by itself.
#define ST_REF_BATCHES 16
static void pixel_sobol(const ref_job *job, const pixel_plan *pl, ref_view *r, st_ref_rng *rng,
                        int i, int j, float *px) {
    const int n = pl->n, nb = n < ST_REF_BATCHES ? n : ST_REF_BATCHES;
    const uint64_t pixel = (uint64_t)j * (uint64_t)job->out->width + (uint64_t)i;
    const uint64_t key = st_ref_rng_hash(job->opt->seed, pixel);
    double mean[3] = {0, 0, 0}, m2[3] = {0, 0, 0}, v[3];
    for (int b = 0; b < nb; b++) {
        const int size = n / nb + (b < n % nb);
        const uint64_t bkey = st_ref_rng_hash(key, (uint64_t)b);
        double sum[3] = {0, 0, 0};
        for (int k = 0; k < size; k++) {
            st_ref_rng_start_sample(rng, bkey, (uint32_t)k, (uint32_t)size);
            if (pl->box) {
                double u = st_ref_rng_uniform(rng), w = st_ref_rng_uniform(rng);
                view_ray(job, i, j, u, w, r);
            }
            sample_value(job, pl, r, rng, v);
            for (int c = 0; c < 3; c++)
                sum[c] += v[c];
        }
        for (int c = 0; c < 3; c++) { // Welford over the batch means
            double bm = sum[c] / size, delta = bm - mean[c];
            mean[c] += delta / (b + 1);
            m2[c] += delta * (bm - mean[c]);
        }
    }
    for (int c = 0; c < 3; c++) {
        px[c] = (float)mean[c];
        px[3 + c] = (float)(nb > 1 ? sqrt(m2[c] / (nb - 1) / nb) : 0.0);
    }
}

static void render_pixel(const ref_job *job, double *cells, int i, int j) {
    const st_ref_options *o = job->opt;
    const st_scene *sc = job->geo->desc;
    pixel_plan pl = {.box = o->filter == ST_FILTER_BOX};
    st_ref_rng rng;
    st_ref_rng_seed(&rng, o->seed, (uint64_t)j * (uint64_t)job->out->width + (uint64_t)i);
    ref_view r;
    if (!pl.box) view_ray(job, i, j, 0.5, 0.5, &r); // one view ray for every sample
    pl.want_direct = o->aov == ST_REF_COMBINED || o->aov == ST_REF_DIRECT;
    pl.want_indirect = (o->aov == ST_REF_COMBINED || o->aov == ST_REF_INDIRECT) && o->bounces > 0;
    pl.want_inscatter =
        (o->aov == ST_REF_COMBINED || o->aov == ST_REF_INSCATTER) && sc->medium.present;
    // Direct light through the centre alone has no noise; over the pixel or
    // through a varying density it has.
    pl.varies = sc->medium.present && st_density_varies(&sc->density);
    const bool stochastic =
        pl.box || pl.varies || pl.want_inscatter || (pl.want_indirect && r.x.hit && r.x.lit_side);
    pl.n = stochastic ? (o->spp > 0 ? o->spp : 1) : 1;
    float *px = st_image_px(job->out, i, j);
    if (o->sampler == ST_REF_SAMPLER_INDEPENDENT)
        pixel_independent(job, &pl, &r, &rng, cells, i, j, px);
    else
        pixel_sobol(job, &pl, &r, &rng, i, j, px);
}

static void *worker(void *arg) {
    ref_job *job = arg;
    // Per-cell sums of the box filter's strata (render_pixel).
    double *cells = malloc(sizeof(double) * 6 * ST_REF_MAX_GRID * ST_REF_MAX_GRID);
    if (!cells) atomic_store(&job->failed, true);
    for (;;) {
        int j = atomic_fetch_add(&job->next_row, 1);
        if (j >= job->out->height) break;
        for (int i = 0; cells && i < job->out->width; i++)
            render_pixel(job, cells, i, j);
        atomic_fetch_add(&job->rows_done, 1);
    }
    free(cells);
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
    atomic_init(&job.failed, false);

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
    if (atomic_load(&job.failed)) {
        st_image_free(out);
        return st_fail(err, ST_ERR_RUNTIME, "out of memory for the pixel strata");
    }
    return true;
}
