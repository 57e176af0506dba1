// strahl view: the interactive viewer's state and its parts. Everything the
// keyboard, the mouse and the parameter panel can do goes through the
// actions in view_actions.c, and a script (view_script.c) calls the same
// actions between frames, so scripted sessions exercise the interactive code
// path: one frame function (view_frame.c) renders the world, the display
// pass and the overlay for both.
//
// The overlay is drawn by the viewer itself (view_gl.c: coloured quads and
// stb_easy_font text in one streamed vertex buffer) rather than Dear ImGui:
// Debian's libimgui-dev ships a static library with its own GL loader, and
// the controls needed here (sliders, checkboxes, a text field, tables) are a
// few hundred lines that need no extra link dependency.
#ifndef ST_VIEW_H
#define ST_VIEW_H
#include "st_world.h"
#include <stdio.h>

#define VIEW_MAX_MODS 32
#define VIEW_MAX_ROWS 128

// Camera controller: the pose is kept as position/target/up exactly as set
// (so a scripted `camera` equals the same pose in a scene file), and orbit
// and fly moves are computed from it.
typedef struct view_cam {
    float pos[3], target[3], up[3];
    bool fly;    // false: orbit around the target; true: first-person look
    float speed; // metres per second for WASD
} view_cam;

void view_cam_init(view_cam *c, const st_camera_desc *d);
// Degrees. Orbit mode turns the camera around the target, fly mode turns the
// view direction around the camera.
void view_cam_rotate(view_cam *c, float dyaw, float dpitch);
// Metres along the view direction, the camera's right and the up vector.
void view_cam_move(view_cam *c, float fwd, float right, float up);
// Scales the camera-target distance (orbit zoom); > 0.
void view_cam_dolly(view_cam *c, float factor);

// One vertex of the overlay: pixel position (top-left origin), RGBA8.
typedef struct view_vtx {
    float x, y;
    uint32_t rgba;
} view_vtx;

#define VIEW_RGBA(r, g, b, a)                                                                      \
    ((uint32_t)(r) | (uint32_t)(g) << 8 | (uint32_t)(b) << 16 | (uint32_t)(a) << 24)

typedef struct view_gl {
    GLuint display_prog, ui_prog, ui_vao, ui_vbo, empty_vao;
    GLint d_img, d_scale, d_fb, d_off, ui_size;
    view_vtx *v;
    int n, cap;
    size_t vbo_bytes;
    float scale; // UI scale (text and layout)
} view_gl;

bool view_gl_init(view_gl *g, st_err *err);
void view_gl_free(view_gl *g);
// Draws the world's HDR image to the window: 2^exposure, clamp, sRGB, as
// st_image_write_png does.
// The image (img_w x img_h) scaled into the framebuffer, aspect kept (bars).
void view_gl_display(view_gl *g, GLuint tex, int img_w, int img_h, int fb_w, int fb_h,
                     float exposure);
void view_ui_rect(view_gl *g, float x, float y, float w, float h, uint32_t rgba);
float view_ui_text(view_gl *g, float x, float y, const char *s, uint32_t rgba); // returns width
float view_ui_text_width(const view_gl *g, const char *s);
float view_ui_line(const view_gl *g); // line height in pixels
// Moves the rectangle whose 6 vertices start at `first` (drawn earlier as a
// placeholder, e.g. a background sized once its content is laid out).
void view_ui_patch_rect(view_gl *g, int first, float x, float y, float w, float h);
void view_ui_flush(view_gl *g, int fb_w, int fb_h);
// The window's back buffer (image + overlay) as an 8-bit PNG.
bool view_gl_capture(const char *path, int fb_w, int fb_h, st_err *err);

typedef enum { VIEW_RAN = 0, VIEW_SKIPPED, VIEW_CULLED } view_pass_state;

// One pass of the last frame, for the overlay and `stats`.
typedef struct view_pass_row {
    char module[ST_NAME_MAX], pass[ST_NAME_MAX];
    view_pass_state state;
    float gpu_ms, cpu_ms;    // this frame (0 unless it ran)
    double gpu_med, cpu_med; // median over the samples since the last reset
    uint32_t runs, skipped, culled;
} view_pass_row;

// Parameter values of a module that was switched off, restored when it is
// switched on again (the world reloads a module with the scene's values).
typedef struct view_memory {
    char name[ST_NAME_MAX];
    double params[ST_MAX_PARAMS];
    int num_params;
} view_memory;

// A panel control's rectangle last frame (module row or parameter slider),
// written to `stats` so scripts can aim the mouse at it.
typedef struct view_widget {
    char module[ST_NAME_MAX], param[ST_NAME_MAX]; // param "" = the module's on/off row
    float x, y, w, h;
} view_widget;

typedef struct view {
    st_context *ctx;
    void *win; // GLFWwindow
    st_scene *scene;
    st_world *world;
    view_gl gl;
    view_cam cam, cam_home;
    bool cam_dirty;

    // Every module that can be switched: installed plugins plus loaded ones,
    // sorted; keys 1..9, 0 switch the first ten.
    char mods[VIEW_MAX_MODS][ST_NAME_MAX];
    int num_mods;
    view_memory memory[VIEW_MAX_MODS];
    int num_memory;
    // The G and I keys' modules, by their declared kind (view_kinds.c):
    // godrays[0] = "off", then the god-ray techniques by name; gi_module ""
    // when no GI module is installed.
    char godrays[VIEW_MAX_MODS + 1][ST_NAME_MAX];
    int num_godrays;
    char gi_module[ST_NAME_MAX];
    int godray; // index into godrays (0 = off)
    int gi;     // index into view_gi_modes (0 = off)

    bool show_panel, show_stats, show_help;
    float exposure;
    float panel_scroll;
    // Panel keyboard focus: a parameter of a loaded module.
    char sel_mod[ST_NAME_MAX];
    int sel_param;
    bool editing, edit_fresh; // fresh: the first typed character replaces the text
    char edit[64];
    // Mouse (framebuffer pixels), per-frame button events for the panel.
    double mx, my, wheel;
    bool mouse_down[3], mouse_pressed[3];
    int drag_owner; // 0 none, 1 camera, 2 panel slider
    char drag_mod[ST_NAME_MAX];
    int drag_param;
    double last_mx, last_my;
    bool over_panel;
    float panel_x; // left edge of the panel last frame
    view_widget widgets[VIEW_MAX_ROWS];
    int num_widgets;

    char message[512]; // transient status line
    double message_until;
    char error[1024]; // sticky: last shader / frame error until fixed

    // Last frame.
    view_pass_row rows[VIEW_MAX_ROWS];
    int num_rows;
    uint32_t *prev_totals;
    int num_prev;
    double frame_ms, world_ms, frame_ms_avg, last_time;
    uint64_t frames;
    int fb_w, fb_h;
    // The world renders at the window's size, or (fixed_size: `--size`, key
    // K, script `render-size`) at render_w x render_h, scaled into the window
    // with its aspect kept, so screenshots have that size.
    bool fixed_size;
    int render_w, render_h;
    bool frame_failed;

    bool script; // no vsync, no held-key movement timing from the clock
    bool quit;
    bool want_capture;
    char capture_path[1024];
    char shot_dir[1024];
    // The scene file and the running script (NULL: none): the viewer never
    // writes over them (view_check_output).
    const char *scene_path, *script_path;
    int shot_counter;
} view;

extern const char *const view_gi_modes[5]; // off, direct, indirect, combined, atlas

// ---- what a module is to the viewer (view_kinds.c) -----------------------
typedef enum { VIEW_KIND_OTHER, VIEW_KIND_GODRAYS, VIEW_KIND_GI } view_kind;
view_kind view_plugin_kind(const st_plugin *p);
// A GI module's display switch: its first enum parameter with an "indirect"
// choice (-1: none).
int view_gi_display_param(const st_plugin *p);
// Fills v->godrays and v->gi_module from v->mods.
void view_classify_modules(view *v);

// ---- actions (view_actions.c) -------------------------------------------
void view_message(view *v, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
void view_refresh_modules(view *v);
bool view_enable(view *v, const char *module, bool on, st_err *err);
bool view_toggle_module(view *v, int index, st_err *err);
bool view_cycle_godrays(view *v, st_err *err);
bool view_cycle_gi(view *v, st_err *err);
// Sets a parameter from text: a number, true/false, or an enum choice name.
bool view_set_param_text(view *v, const char *module, const char *param, const char *text,
                         st_err *err);
bool view_set_param(view *v, const char *module, const char *param, double value, st_err *err);
// Hot reload: on failure the old shaders stay and v->error shows why.
bool view_reload(view *v);
// Linear HDR EXR and sRGB PNG of the world's final image (not the window).
// `base` may end in .exr or .png or have no extension.
bool view_screenshot(view *v, const char *base, st_err *err);
// The checks of a command's -o for every file the viewer writes (`what`
// starts the message): an allowed extension (exts), a folder that takes a
// new file, and not the scene file, a file the scene was read from (glTF,
// buffers, VDB) or the running script (ST_ERR_INPUT).
bool view_check_output(const view *v, const char *what, const char *path, const char *const *exts,
                       st_err *err);
bool view_write_stats(view *v, const char *path, st_err *err);
void view_set_camera(view *v, const float pos[3], const float target[3]);
// A key press (GLFW key code and modifier bits), from GLFW or a script.
bool view_key(view *v, int key, int mods, st_err *err);
void view_char(view *v, unsigned codepoint);
int view_key_from_name(const char *name, int *mods);
const char *view_help_text(const view *v);

// ---- frame (view_frame.c) ----------------------------------------------
// One iteration: events, camera, resize, world frame, display, overlay, swap.
bool view_frame(view *v, st_err *err);
void view_install_callbacks(view *v);
// Mouse input in framebuffer pixels (button 0 left, 1 right, 2 middle), from
// the GLFW callbacks or a script; the next frame acts on it.
void view_mouse_button(view *v, int button, bool down);
void view_mouse_move(view *v, double x, double y);
void view_mouse_wheel(view *v, double dy);

// ---- overlay (view_overlay.c) --------------------------------------------
// Builds the stats table, the panel (and handles its mouse input), the help
// box and the message lines.
void view_overlay(view *v);
// Parameter slider mapping (view_param.c; log scale for wide positive ranges).
double view_param_to_t(const st_param_def *d, double value);
double view_param_from_t(const st_param_def *d, double t);

// ---- script (view_script.c) ---------------------------------------------
// Runs a script already opened as f (path names it in messages; f is
// closed); returns an exit code (0 ok, 1 failed expectation or
// runtime error, 2 bad script).
int view_run_script(view *v, const char *path, FILE *f);

#endif
