// strahl view's window and render sizes, scripted under Xvfb: with --window
// larger than the scene the world renders at the window's size; `render-size
// scene` (key K) renders at the scene's size, screenshots have that size and
// equal `strahl render` (within 1e-4), and the image is scaled into the
// window with its aspect kept (black bars beside it).
#include "view_test.h"
#include <stb/stb_image.h>

enum { W = 64, H = 48 };

int main(int argc, char **argv) {
    (void)argc;
    st_view_under_xvfb(argv);
    const char *D = ST_TEST_SCRATCH;
    char scene[512], script[512], path[1024];
    snprintf(scene, sizeof scene, "%s/window.json", D);
    snprintf(script, sizeof script, "%s/window.script", D);
    char json[2048];
    snprintf(json, sizeof json,
             "{\"image\": {\"width\": %d, \"height\": %d},\n"
             " \"camera\": {\"position\": [0, 3, 2.5], \"target\": [0, 0, 0], \"up\": [0, 1, 0], "
             "\"fov_y\": 60,"
             " \"near\": 0.05, \"far\": 100},\n"
             " \"lights\": [{\"type\": \"point\", \"position\": [0, 1.8, 0], \"intensity\": [3, 3, "
             "3]}],\n"
             " \"geometry\": [{\"quad\": {\"corner\": [-4, 0, -4], \"u\": [0, 0, 8], \"v\": [8, 0, "
             "0]}, \"albedo\": "
             "[0.75, 0.75, 0.75]},\n"
             "   {\"box\": {\"min\": [-0.3, 0.8, -0.3], \"max\": [0.3, 1.0, 0.3]}}],\n"
             " \"modules\": [{\"name\": \"shadow_map\", \"params\": {\"resolution\": 512}}]}\n",
             W, H);
    st_test_write(scene, json);
    snprintf(path, sizeof path, "%s/ref.exr", D);
    CHECK(st_test_render(scene, path, NULL) == 0, "render");

    // 400x240: wider than the scene's 4:3, so the scene-size image (scaled
    // by 5 to 320x240) leaves 40-pixel bars left and right.
    char text[2048];
    snprintf(text, sizeof text,
             "frames 1\nscreenshot %s/win\nrender-size scene\nframes 2\nscreenshot %s/scene\nkey "
             "O\ncapture %s/cap.png\n"
             "frames 1\nrender-size window\nframes 1\nscreenshot %s/win2\n",
             D, D, D, D);
    st_test_write(script, text);
    static char log[65536];
    int rc = st_view_run(scene, script, "--window 400x240 --hide-panel", log, sizeof log);
    CHECK(rc == 0, "view exit %d", rc);

    st_image win = {0}, sc = {0}, win2 = {0}, ref = {0};
    CHECK(st_view_read(D, "win", &win) && win.width == 400 && win.height == 240,
          "screenshot at the window's size: %dx%d", win.width, win.height);
    CHECK(st_view_read(D, "scene", &sc) && sc.width == W && sc.height == H,
          "screenshot at the scene's size: %dx%d", sc.width, sc.height);
    CHECK(st_view_read(D, "ref", &ref) && st_view_max_diff(&sc, &ref) < 1e-4,
          "scene-size screenshot vs strahl render: max diff %g", st_view_max_diff(&sc, &ref));
    CHECK(st_view_read(D, "win2", &win2) && win2.width == 400 && win2.height == 240,
          "back at the window's size");

    // The window capture: bars (black) at the sides, the image in the middle.
    snprintf(path, sizeof path, "%s/cap.png", D);
    int cw = 0, ch = 0, comp = 0;
    unsigned char *px = stbi_load(path, &cw, &ch, &comp, 3);
    CHECK(px && cw == 400 && ch == 240, "capture %dx%d", cw, ch);
    if (px && cw == 400 && ch == 240) {
        int bar_max = 0, mid_max = 0;
        for (int j = 0; j < ch; j++)
            for (int i = 0; i < cw; i++) {
                const unsigned char *p = px + 3 * ((size_t)j * cw + i);
                int m = p[0] > p[1] ? (p[0] > p[2] ? p[0] : p[2]) : (p[1] > p[2] ? p[1] : p[2]);
                if (i < 38 || i >= 362)
                    bar_max = m > bar_max ? m : bar_max;
                else if (i >= 60 && i < 340)
                    mid_max = m > mid_max ? m : mid_max;
            }
        CHECK(mid_max > 40, "no image in the middle (max %d)", mid_max);
        int right_bar = 0;
        for (int j = 0; j < 180; j++) // below: the message box (the screenshot's paths)
            for (int i = 362; i < cw; i++) {
                const unsigned char *p = px + 3 * ((size_t)j * cw + i);
                right_bar = p[0] + p[1] + p[2] > right_bar ? p[0] + p[1] + p[2] : right_bar;
            }
        CHECK(right_bar == 0, "right bar not black (max %d)", right_bar);
        (void)bar_max;
    }
    stbi_image_free(px);
    st_image_free(&win);
    st_image_free(&sc);
    st_image_free(&win2);
    st_image_free(&ref);
    return st_test_summary("test_view_window");
}
