// The sousa shaders against plain C:
// - shaders/sousa/blur.frag, three passes with steps TAPS^-1, TAPS^-2,
//   TAPS^-3 on a synthetic depth mask at half the output size, the last
//   composing onto a synthetic image (tint, fade), matches the C chain of
//   thesis listing A.7 within 1e-3 (|gpu - C| / max(1, |C|)): light inside,
//   exactly at a pixel centre, off screen; TAPS and brightness at their
//   limits;
// - shaders/sousa/mask.frag turns a synthetic G-buffer (camera distance, -1
//   where empty) into linear depth / far, 1 where empty (thesis A.6), at full
//   and half resolution, within 1e-5.
#include "st_test_support.h"
#include "mitchell/godray_test.h"

static st_shader *blur, *compose, *mask_sh;
static double worst;

static void draw_pass(st_shader *sh, GLuint src, st_target *dst, const float light[2], int taps,
                      float step, float brightness) {
    st_target_bind(dst);
    st_shader_use(sh);
    st_shader_texture(sh, "u_src", GL_TEXTURE_2D, src);
    st_shader_set_vec2(sh, "u_out_size", (float)dst->width, (float)dst->height);
    st_shader_set_vec2(sh, "u_light_uv", light[0], light[1]);
    st_shader_set_int(sh, "u_taps", taps);
    st_shader_set_float(sh, "u_step", step);
    st_shader_set_float(sh, "u_brightness", brightness);
}

static void run_case(const char *what, const gimg *mask, const gimg *hdr, const float light[2],
                     int taps, float brightness, const float tint[3], float fade) {
    st_err err = {0};
    st_target t1 = {0}, t2 = {0}, out = {0};
    // Same as the module: R32F intermediate targets with a zero border.
    st_target_create(&t1, mask->w, mask->h, 1, GL_R32F, false, &err);
    st_target_create(&t2, mask->w, mask->h, 1, GL_R32F, false, &err);
    st_target_create(&out, hdr->w, hdr->h, 1, GL_RGBA32F, false, &err);
    GLuint tex[3] = {t1.color[0], t2.color[0], out.color[0]};
    for (int i = 0; i < 2; i++) {
        glTextureParameteri(tex[i], GL_TEXTURE_WRAP_S, GL_CLAMP_TO_BORDER);
        glTextureParameteri(tex[i], GL_TEXTURE_WRAP_T, GL_CLAMP_TO_BORDER);
        glTextureParameterfv(tex[i], GL_TEXTURE_BORDER_COLOR, (const float[4]){0, 0, 0, 0});
    }
    GLuint mask_tex = gl_texture_from(mask), hdr_tex = gl_texture_from(hdr);
    draw_pass(blur, mask_tex, &t1, light, taps, (float)pow(taps, -1), brightness);
    st_draw_fullscreen();
    draw_pass(blur, t1.color[0], &t2, light, taps, (float)pow(taps, -2), brightness);
    st_draw_fullscreen();
    draw_pass(compose, t2.color[0], &out, light, taps, (float)pow(taps, -3), brightness);
    st_shader_texture(compose, "st_hdr_in", GL_TEXTURE_2D, hdr_tex);
    st_shader_set_vec3(compose, "u_color", tint);
    st_shader_set_float(compose, "u_fade", fade);
    st_draw_fullscreen();
    CHECK(st_gl_check("sousa chain", &err), "%s: %s", what, err.msg);
    gimg gpu = gl_read(out.color[0], out.width, out.height, 4), ref = gimg_new(hdr->w, hdr->h, 4);
    ref_sousa(mask, hdr, light, taps, brightness, tint, fade, &ref);
    // The first pass alone too (the tap loop without the chain).
    gimg g1 = gl_read(t1.color[0], mask->w, mask->h, 1), r1 = gimg_new(mask->w, mask->h, 1);
    ref_sousa_pass(mask, light, taps, (float)pow(taps, -1), brightness, &r1);
    double d = gimg_max_err(&gpu, &ref, 3), d1 = gimg_max_err(&g1, &r1, 1), effect = 0;
    for (int i = 0; i < ref.w * ref.h; i++)
        for (int c = 0; c < 3; c++)
            effect = fmax(effect, ref.px[4 * i + c] - hdr->px[4 * i + c]);
    printf("%-42s pass 1 err %.3g, chain err %.3g (largest shaft value %.3g)\n", what, d1, d,
           effect);
    worst = fmax(worst, fmax(d, d1));
    CHECK(d <= 1e-3 && d1 <= 1e-3, "%s: |gpu - C| / max(1, |C|): chain %g, pass 1 %g", what, d, d1);
    CHECK(gimg_nonfinite(&gpu) == 0, "%s: non-finite output", what);
    free(gpu.px), free(ref.px), free(g1.px), free(r1.px);
    glDeleteTextures(1, &mask_tex);
    glDeleteTextures(1, &hdr_tex);
    st_target_destroy(&t1), st_target_destroy(&t2), st_target_destroy(&out);
}

// mask.frag on a synthetic G-buffer of a camera with known pose.
static void test_mask(int ms) {
    const int W = 48, H = 36;
    st_camera cam = {.position = {0.3f, 1.2f, 4},
                     .target = {0, 0.8f, 0},
                     .up = {0, 1, 0},
                     .fov_y = 50,
                     .near_z = 0.05f,
                     .far_z = 20,
                     .width = W,
                     .height = H};
    st_camera_update(&cam);
    gimg gb = gimg_new(W, H, 4);
    uint32_t seed = 99;
    for (int i = 0; i < W * H; i++) {
        float r = gt_rand(&seed);
        gb.px[4 * i + 3] = r < 0.2f    ? -1.0f
                           : r < 0.25f ? 30.0f
                                       : 0.5f + 15 * gt_rand(&seed); // -1: no surface
    }
    GLuint gtex = gl_texture_from(&gb);
    int mw = W / ms, mh = H / ms;
    st_err err = {0};
    st_target t = {0};
    st_target_create(&t, mw, mh, 1, GL_R32F, false, &err);
    st_target_bind(&t);
    st_shader_use(mask_sh);
    st_shader_texture(mask_sh, "st_gbuffer", GL_TEXTURE_2D, gtex);
    st_shader_set_vec2(mask_sh, "st_resolution", (float)W, (float)H);
    st_shader_set_vec2(mask_sh, "u_out_size", (float)mw, (float)mh);
    st_shader_set_mat4(mask_sh, "st_inv_view_proj", cam.inv_view_proj);
    st_shader_set_mat4(mask_sh, "st_view", cam.view);
    st_shader_set_vec3(mask_sh, "st_cam_pos", cam.position);
    st_shader_set_float(mask_sh, "st_far", cam.far_z);
    st_draw_fullscreen();
    gimg got = gl_read(t.color[0], mw, mh, 1);
    // C: z = distance * dot(ray through the pixel centre, view axis).
    double f[3] = {cam.target[0] - cam.position[0], cam.target[1] - cam.position[1],
                   cam.target[2] - cam.position[2]};
    st_v_norm(f);
    const double pos[3] = {cam.position[0], cam.position[1], cam.position[2]},
                 tgt[3] = {cam.target[0], cam.target[1], cam.target[2]}, up[3] = {0, 1, 0};
    st_test_cam tc = st_test_camera(pos, tgt, up, cam.fov_y, W, H);
    double worst_mask = 0, lo = 1, hi = 0;
    for (int y = 0; y < mh; y++)
        for (int x = 0; x < mw; x++) {
            double m = 0;
            for (int k = 0; k < 4; k++) {
                float u = (x + 0.5f) / mw + (k & 1 ? 0.25f : -0.25f) / mw,
                      v = (y + 0.5f) / mh + (k & 2 ? 0.25f : -0.25f) / mh;
                int px = (int)floorf(u * W), py = (int)floorf(v * H); // GL rows: 0 at the bottom
                double dist = gimg_at(&gb, px, py)[3], d[3];
                st_test_ray(&tc, px, H - 1 - py, d);
                double cosine = d[0] * f[0] + d[1] * f[1] + d[2] * f[2];
                double z = dist < 0 ? 1 : fmin(1, fmax(0, dist * cosine / cam.far_z));
                m += 0.25 * z;
            }
            double g = gimg_at(&got, x, y)[0];
            worst_mask = fmax(worst_mask, fabs(g - m));
            lo = fmin(lo, m), hi = fmax(hi, m);
        }
    printf("mask at 1/%d resolution (%dx%d): max |gpu - C| = %.3g, values %.3f..%.3f\n", ms, mw, mh,
           worst_mask, lo, hi);
    CHECK(worst_mask < 1e-5, "mask 1/%d: %g", ms, worst_mask);
    free(got.px);
    free(gb.px);
    glDeleteTextures(1, &gtex);
    st_target_destroy(&t);
}

int main(void) {
    st_err err = {0};
    st_context *ctx = st_test_context();
    blur = st_shader_load("common/fullscreen.vert", "sousa/blur.frag", NULL, &err);
    compose =
        blur ? st_shader_load("common/fullscreen.vert", "sousa/blur.frag", "SOUSA_COMPOSE 1", &err)
             : NULL;
    mask_sh =
        compose ? st_shader_load("common/fullscreen.vert", "sousa/mask.frag", NULL, &err) : NULL;
    CHECK(mask_sh != NULL, "load sousa shaders: %s", err.msg);
    if (!mask_sh) return st_test_summary("test_sousa_blur");

    test_mask(1);
    test_mask(2);

    // Output 80x60, mask 40x30: far background (1) with near objects (low
    // linear depth), a bar with a gap, and noise.
    const int W = 80, H = 60, MW = 40, MH = 30;
    gimg mask = gimg_new(MW, MH, 1), hdr = gimg_new(W, H, 4);
    uint32_t seed = 777;
    for (int y = 0; y < MH; y++)
        for (int x = 0; x < MW; x++) {
            float m = 1.0f;
            if (y < 8) m = 0.05f + 0.02f * x / MW;                         // floor
            if (x > 10 && x < 14 && !(y > 15 && y < 18)) m = 0.08f;        // a post with a gap
            if ((x - 28) * (x - 28) + (y - 20) * (y - 20) < 16) m = 0.12f; // a ball
            gimg_at(&mask, x, y)[0] = m * (0.9f + 0.1f * gt_rand(&seed));
        }
    for (int i = 0; i < W * H; i++)
        for (int c = 0; c < 4; c++)
            hdr.px[4 * i + c] = c == 3 ? 1 : 0.5f * gt_rand(&seed);
    const float white[3] = {1, 1, 1}, warm[3] = {1, 0.7f, 0.4f};
    const float inside[2] = {0.57f, 0.71f}, centre[2] = {37.5f / W, 44.5f / H},
                off[2] = {1.25f, 0.62f}, off2[2] = {-0.3f, -0.2f};
    run_case("thesis defaults (TAPS 6, brightness 0.19)", &mask, &hdr, inside, 6, 0.19f, white, 1);
    run_case("light at a pixel centre", &mask, &hdr, centre, 6, 0.19f, warm, 1);
    run_case("light off screen (uv 1.25, 0.62), fade 0.4", &mask, &hdr, off, 6, 0.19f, warm, 0.4f);
    run_case("light off screen (uv -0.3, -0.2)", &mask, &hdr, off2, 8, 0.15f, white, 1);
    run_case("TAPS 4", &mask, &hdr, inside, 4, 0.25f, white, 1);
    run_case("TAPS 12", &mask, &hdr, inside, 12, 0.1f, warm, 1);
    // Range limits (sousa.c): TAPS 2..32, brightness 0..1.
    run_case("TAPS 2, brightness 1 (minimum TAPS)", &mask, &hdr, inside, 2, 1, white, 1);
    run_case("TAPS 32, brightness 1 (maximum)", &mask, &hdr, inside, 32, 1, white, 1);
    run_case("TAPS 32, brightness 0", &mask, &hdr, centre, 32, 0, white, 1);
    printf("worst |gpu - C| / max(1, |C|) over all cases: %.3g\n", worst);

    free(mask.px);
    free(hdr.px);
    st_shader_destroy(blur);
    st_shader_destroy(compose);
    st_shader_destroy(mask_sh);
    st_context_destroy(ctx);
    return st_test_summary("test_sousa_blur");
}
