// The test support library (tests/support, linked into every test by
// st_add_test): scaffolding that several test programs need. Functions here
// return what they found; the calling test CHECKs it (the CHECK counters are
// per test program, in st_test.h).
#ifndef ST_TEST_SUPPORT_H
#define ST_TEST_SUPPORT_H
#ifndef _GNU_SOURCE
#define _GNU_SOURCE // as st_test.h: popen, M_PI
#endif
#include "st_gl.h"
#include "st_image.h"
#include "st_scene.h"
#include <cjson/cJSON.h>

// A headless GL context; on failure prints why and exits 1 (nothing to test).
st_context *st_test_context(void);

// Renders the scene file in this process as `strahl render SCENE --filter
// point` does (frames until every progressive module has converged, at most
// strahl render's 2000), the image into img (free it): for tests that render
// many small scenes, where a process start-up per scene costs more than the
// render. Needs a current context (st_test_context). False with err set.
bool st_test_render_here(const char *scene, st_image *img, st_err *err);
// The same with exactly `frames` frames, as `strahl render --frames N`.
bool st_test_render_frames_here(const char *scene, int frames, st_image *img, st_err *err);

// Runs `strahl render SCENE -o OUT --stats=json --filter point EXTRA` and parses
// its output (point: frames of a static scene redo nothing; `--filter box` in
// EXTRA overrides it).
// *rc gets the exit code; NULL when the output is not JSON.
cJSON *st_test_stats_json(const char *scene, const char *out, const char *extra, int *rc);

// Is floor point p (y = 0) in the shadow that the box [bmin, bmax] casts from
// a point light at lp? 1 robustly shadowed, 0 robustly lit, -1 near the edge
// (the 4 neighbours at distance `jitter` disagree).
int st_test_shadow_state(const double p[3], double jitter, const double lp[3], const double bmin[3],
                         const double bmax[3]);

// Writes the shadow scene those tests share: 96x96, the camera at (0, 3, 2.5)
// looking at the origin with fov 60, an 8 m floor quad of albedo rho at
// y = 0, the box [bmin, bmax] above it, a point light of intensity I at lp,
// and `modules` as the scene's "modules" array entries.
void st_test_write_shadow_scene(const char *path, const double lp[3], double I, double rho,
                                const double bmin[3], const double bmax[3], const char *modules);

// Adds an emitter (radiance 1) to sc: a ns-gon of the same area as the disk
// of radius R, centred on the y axis at height h, facing -y (toward a
// receiver at the origin). poly (may be NULL) receives its ns corners.
bool st_test_add_disk(st_scene *sc, int ns, double R, double h, double (*poly)[3], st_err *err);

// The five walls of the 2 m Cornell box around the origin (floor, ceiling,
// back white; left red, right green; open toward +z), as entries of a scene's
// "geometry" array, each followed by a comma and a newline.
#define ST_TEST_CORNELL_WALLS                                                                      \
    "  {\"quad\": {\"corner\": [-1, 0, -1], \"u\": [0, 0, 2], \"v\": [2, 0, 0]}, "                 \
    "\"albedo\": [0.75, 0.75, 0.75]},\n"                                                           \
    "  {\"quad\": {\"corner\": [-1, 2, -1], \"u\": [2, 0, 0], \"v\": [0, 0, 2]}, "                 \
    "\"albedo\": [0.75, 0.75, 0.75]},\n"                                                           \
    "  {\"quad\": {\"corner\": [-1, 0, -1], \"u\": [2, 0, 0], \"v\": [0, 2, 0]}, "                 \
    "\"albedo\": [0.75, 0.75, 0.75]},\n"                                                           \
    "  {\"quad\": {\"corner\": [-1, 0, -1], \"u\": [0, 2, 0], \"v\": [0, 0, 2]}, "                 \
    "\"albedo\": [0.75, 0.1, 0.1]},\n"                                                             \
    "  {\"quad\": {\"corner\": [1, 0, -1], \"u\": [0, 0, 2], \"v\": [0, 2, 0]}, "                  \
    "\"albedo\": [0.1, 0.75, 0.1]},\n"
// ... and its two blocks (the short and the tall one), grey, no trailing comma.
#define ST_TEST_CORNELL_BLOCKS                                                                     \
    "  {\"box\": {\"min\": [0.1, 0, -0.1], \"max\": [0.7, 0.6, 0.5]}, \"albedo\": [0.75, 0.75, "   \
    "0.75]},\n"                                                                                    \
    "  {\"box\": {\"min\": [-0.7, 0, -0.7], \"max\": [-0.1, 1.2, -0.1]}, \"albedo\": [0.75, "      \
    "0.75, "                                                                                       \
    "0.75]}\n"

#endif
