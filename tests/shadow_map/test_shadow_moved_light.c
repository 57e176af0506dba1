// shadow_map after st_world_set_light: the cube's clip planes follow the
// light. The box-over-floor scene starts with the light at 1.8 m, where
// every vertex lies within 6.4 m of it; then the light moves 8 m up, which
// puts the box and the whole floor beyond that distance. A far plane fixed
// when the module was created cut all of it out of the cube (no shadow
// at all after the move). After the move every floor pixel robustly inside
// the box's exact shadow must be black and every robustly lit one within 1%
// of the closed form, and the moved world's image must equal that of a world
// created with the light already there.
#include "st_test_support.h"
#include "st_test_render.h"
#include "st_world.h"

static const double I0 = 3.0, LP0[3] = {0.4, 1.8, 0.2}, RHO = 0.75;
static const double I1 = 60.0, LP1[3] = {0.5, 8.0, 0.3};
static const double BMIN[3] = {-0.3, 0.8, -0.3}, BMAX[3] = {0.3, 1.0, 0.3};

// Opens the shared shadow scene with the light at lp and renders one frame.
static st_world *open_world(const double lp[3], double I, st_scene *sc, st_image *img) {
    char path[512];
    snprintf(path, sizeof path, "%s/moved_light.json", ST_TEST_SCRATCH);
    st_test_write_shadow_scene(path, lp, I, RHO, BMIN, BMAX, "{\"name\": \"shadow_map\"}");
    st_err err = {0};
    st_world *w = NULL;
    bool ok = st_scene_load(path, sc, &err) && (w = st_world_create(sc, NULL, &err)) &&
              st_world_frame(w, &err) && st_world_read(w, img, &err);
    CHECK(ok, "world with the light at (%g, %g, %g): %s", lp[0], lp[1], lp[2], err.msg);
    return w;
}

// Floor pixels against the exact shadow of the light at LP1: counts of
// shadowed and lit pixels decided, and of those that disagree.
static int check_floor(const st_image *img, int *shadowed, int *lit) {
    const double cam[3] = {0, 3, 2.5}, tgt[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    st_test_cam c = st_test_camera(cam, tgt, up, 60, 96, 96);
    int bad = 0;
    *shadowed = *lit = 0;
    for (int j = 0; j < 96; j++)
        for (int i = 0; i < 96; i++) {
            double d[3];
            st_test_ray(&c, i, j, d);
            if (d[1] >= 0 || st_test_ray_box(c.pos, d, BMIN, BMAX) >= 0) continue; // the box
            double t = -c.pos[1] / d[1], p[3];
            for (int k = 0; k < 3; k++)
                p[k] = c.pos[k] + t * d[k];
            if (fabs(p[0]) > 3.9 || fabs(p[2]) > 3.9) continue;
            int s = st_test_shadow_state(p, 2.5 * t * 2 * c.tan_half / 96, LP1, BMIN, BMAX);
            if (s < 0) continue;
            double l[3] = {LP1[0] - p[0], LP1[1] - p[1], LP1[2] - p[2]};
            double d2 = l[0] * l[0] + l[1] * l[1] + l[2] * l[2];
            double e = RHO / M_PI * I1 * (l[1] / sqrt(d2)) / d2, v = st_image_px(img, i, j)[0];
            if (s == 1)
                (*shadowed)++, bad += v != 0.0;
            else
                (*lit)++, bad += fabs(v - e) > 0.01 * e;
        }
    return bad;
}

int main(void) {
    st_context *ctx = st_test_context();
    st_scene sa = {0}, sb = {0};
    st_image before = {0}, moved = {0}, fresh = {0};
    st_world *w = open_world(LP0, I0, &sa, &before);
    if (w) {
        const float lp[3] = {(float)LP1[0], (float)LP1[1], (float)LP1[2]},
                    li[3] = {(float)I1, (float)I1, (float)I1};
        st_err err = {0};
        bool ok = st_world_set_light(w, 0, lp, li, &err) && st_world_frame(w, &err) &&
                  st_world_read(w, &moved, &err);
        CHECK(ok, "move the light: %s", err.msg);
    }
    if (moved.data) {
        int shadowed, lit, bad = check_floor(&moved, &shadowed, &lit);
        printf("light moved from 1.8 m to 8 m above the floor: %d floor pixels off the exact "
               "shadow (%d decided shadowed, %d lit)\n",
               bad, shadowed, lit);
        CHECK(shadowed > 40, "shadowed floor pixels decided: %d", shadowed);
        CHECK(lit > 3000, "lit floor pixels decided: %d", lit);
        CHECK(bad == 0, "after the move: %d floor pixels off the exact shadow", bad);
    }
    st_world *w2 = open_world(LP1, I1, &sb, &fresh);
    if (moved.data && fresh.data) {
        double worst = 0;
        for (int j = 0; j < 96; j++)
            for (int i = 0; i < 96; i++)
                for (int k = 0; k < 3; k++)
                    worst = fmax(worst,
                                 fabs(st_image_px(&moved, i, j)[k] - st_image_px(&fresh, i, j)[k]));
        printf("moved light vs a world created there: largest difference %.3g\n", worst);
        CHECK(worst <= 1e-6, "moved light gives the fresh world's image (%.3g)", worst);
    }
    st_image_free(&before);
    st_image_free(&moved);
    st_image_free(&fresh);
    st_world_destroy(w);
    st_world_destroy(w2);
    st_scene_free(&sa);
    st_scene_free(&sb);
    st_context_destroy(ctx);
    return st_test_summary("test_shadow_moved_light");
}
