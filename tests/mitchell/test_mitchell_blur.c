// The mitchell blur shader (shaders/mitchell/blur.frag) on a synthetic
// occlusion image matches the plain C loop of thesis listing A.4 within 1e-3:
// light inside, exactly at a pixel centre, off screen; parameters at their
// defaults, at their range limits and in between; occlusion image at a
// fraction of the output size (bilinear taps between texels). Error measure:
// |gpu - C| / max(1, |C|) per value (absolute up to 1, relative above).
#include "st_test_support.h"
#include "mitchell/godray_test.h"

static st_shader *sh;
static GLuint occ_tex, hdr_tex;
static st_target target;
static double worst;

static void run_case(const char *what, const gimg *occ, const gimg *hdr, const mitchell_args *a) {
    st_target_bind(&target);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    st_shader_use(sh);
    st_shader_texture(sh, "st_hdr_in", GL_TEXTURE_2D, hdr_tex);
    st_shader_texture(sh, "u_occlusion", GL_TEXTURE_2D, occ_tex);
    st_shader_set_vec2(sh, "u_out_size", (float)target.width, (float)target.height);
    st_shader_set_vec2(sh, "u_light_uv", a->light[0], a->light[1]);
    st_shader_set_int(sh, "u_samples", a->n);
    st_shader_set_float(sh, "u_density", a->density);
    st_shader_set_float(sh, "u_decay", a->decay);
    st_shader_set_float(sh, "u_weight", a->weight);
    st_shader_set_float(sh, "u_exposure", a->exposure);
    st_shader_set_float(sh, "u_fade", a->fade);
    st_draw_fullscreen();
    st_err err = {0};
    CHECK(st_gl_check("blur", &err), "%s: %s", what, err.msg);
    gimg gpu = gl_read(target.color[0], target.width, target.height, 4);
    gimg ref = gimg_new(target.width, target.height, 4);
    ref_mitchell(occ, hdr, a, &ref);
    double d = gimg_max_err(&gpu, &ref, 3);
    double peak = 0;
    for (int i = 0; i < ref.w * ref.h; i++)
        for (int c = 0; c < 3; c++)
            peak = fmax(peak, ref.px[4 * i + c]);
    printf("%-44s max err = %.3g (peak %.3g)\n", what, d, peak);
    if (d > worst) worst = d;
    CHECK(d <= 1e-3, "%s: max |gpu - C| / max(1, |C|) = %g", what, d);
    CHECK(gimg_nonfinite(&gpu) == 0, "%s: non-finite output", what);
    free(gpu.px);
    free(ref.px);
}

int main(void) {
    st_err err = {0};
    st_context *ctx = st_test_context();
    sh = st_shader_load("common/fullscreen.vert", "mitchell/blur.frag", NULL, &err);
    CHECK(sh != NULL, "load blur shader: %s", err.msg);
    if (!sh) return st_test_summary("test_mitchell_blur");

    // Output 64x48, occlusion at half size (like the module's resolution
    // parameter): a tinted light disc, a sky band, black occluder bars with a
    // gap, and random speckle so every tap's bilinear weights matter.
    const int W = 64, H = 48, OW = 32, OH = 24;
    gimg occ = gimg_new(OW, OH, 4), hdr = gimg_new(W, H, 4);
    uint32_t seed = 12345;
    for (int y = 0; y < OH; y++)
        for (int x = 0; x < OW; x++) {
            float *p = gimg_at(&occ, x, y);
            float dx = x + 0.5f - 20.3f, dy = y + 0.5f - 15.7f;
            float rgb[3] = {0, 0, 0};
            if (dx * dx + dy * dy < 9.0f)
                rgb[0] = 1.0f, rgb[1] = 0.8f, rgb[2] = 0.5f; // light disc
            else if (y > 18)
                rgb[0] = 0.2f, rgb[1] = 0.3f, rgb[2] = 0.6f; // sky
            if ((x / 3) % 3 == 1 && y > 6 && y < 21 && !(y > 12 && y < 15))
                rgb[0] = rgb[1] = rgb[2] = 0; // bars
            float sp = gt_rand(&seed);
            if (sp > 0.9f) rgb[0] += 2 * sp, rgb[1] += sp, rgb[2] += 0.5f * sp;
            p[0] = rgb[0], p[1] = rgb[1], p[2] = rgb[2], p[3] = 1;
        }
    for (int i = 0; i < W * H; i++)
        for (int c = 0; c < 4; c++)
            hdr.px[4 * i + c] = c == 3 ? 1 : gt_rand(&seed);
    occ_tex = gl_texture_from(&occ);
    hdr_tex = gl_texture_from(&hdr);
    CHECK(st_target_create(&target, W, H, 1, GL_RGBA32F, false, &err), "target: %s", err.msg);

    const float inside[2] = {0.63f, 0.66f};
    // Exactly the centre of output pixel (40, 31): a zero step there.
    const float centre[2] = {40.5f / W, 31.5f / H};
    mitchell_args a = {
        {inside[0], inside[1]}, 100, 1.4f, 1.0f, 1.0f, 0.01921f, 1.0f}; // thesis defaults
    run_case("thesis defaults (n 100, density 1.4)", &occ, &hdr, &a);
    a.density = 1, a.n = 37, a.decay = 0.95f, a.weight = 2.5f, a.exposure = 0.02f;
    run_case("n 37, density 1, decay 0.95, weight 2.5", &occ, &hdr, &a);
    a.light[0] = centre[0], a.light[1] = centre[1];
    run_case("light at a pixel centre", &occ, &hdr, &a);
    a.light[0] = 1.3f, a.light[1] = 0.4f, a.fade = 0.37f;
    run_case("light off screen (uv 1.3, 0.4), fade 0.37", &occ, &hdr, &a);
    a.light[0] = -0.2f, a.light[1] = -0.45f;
    run_case("light off screen (uv -0.2, -0.45)", &occ, &hdr, &a);
    // Range limits of every parameter (mitchell.c): n 1..512, density
    // 1..1000, decay 0..1, weight 0..100, exposure 0..100.
    mitchell_args lo = {{inside[0], inside[1]}, 1, 1, 0, 0, 0, 1};
    run_case("all parameters at their minimum", &occ, &hdr, &lo);
    mitchell_args hi = {{inside[0], inside[1]}, 512, 1000, 1, 100, 100, 1};
    run_case("all parameters at their maximum", &occ, &hdr, &hi);
    mitchell_args big = {{inside[0], inside[1]}, 512, 1, 1, 1, 1e-4f, 1};
    run_case("n 512, density 1 (taps reach the light)", &occ, &hdr, &big);

    printf("worst |gpu - C| / max(1, |C|) over all cases: %.3g\n", worst);
    free(occ.px);
    free(hdr.px);
    st_target_destroy(&target);
    st_shader_destroy(sh);
    st_context_destroy(ctx);
    return st_test_summary("test_mitchell_blur");
}
