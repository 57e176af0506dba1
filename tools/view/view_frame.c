// One frame of strahl view, shared by the interactive loop and scripts:
// input, camera, resize, the world's frame, the per-pass table, display,
// overlay, optional window capture, swap.
#define _GNU_SOURCE
#include "view.h"
#include <GLFW/glfw3.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static view *from(GLFWwindow *w) {
    return glfwGetWindowUserPointer(w);
}

static void on_key(GLFWwindow *w, int key, int scancode, int action, int mods) {
    (void)scancode;
    if (action == GLFW_RELEASE) return;
    view *v = from(w);
    // Repeats only where holding a key makes sense: nudging and deleting text.
    if (action == GLFW_REPEAT && key != GLFW_KEY_LEFT && key != GLFW_KEY_RIGHT &&
        key != GLFW_KEY_BACKSPACE && key != GLFW_KEY_UP && key != GLFW_KEY_DOWN)
        return;
    st_err err = {0};
    if (!view_key(v, key, mods, &err)) view_message(v, "%s", err.msg);
}

static void on_char(GLFWwindow *w, unsigned c) {
    view_char(from(w), c);
}

// Window coordinates -> framebuffer pixels (they differ on HiDPI screens).
static void to_fb(GLFWwindow *w, double *x, double *y) {
    int ww, wh, fw, fh;
    glfwGetWindowSize(w, &ww, &wh);
    glfwGetFramebufferSize(w, &fw, &fh);
    if (ww > 0 && wh > 0) *x *= (double)fw / ww, *y *= (double)fh / wh;
}

void view_mouse_button(view *v, int b, bool down) {
    if (b < 0 || b > 2) return;
    if (down) {
        v->mouse_down[b] = v->mouse_pressed[b] = true;
        // A drag belongs to the panel if it starts there, else to the camera.
        if (!v->drag_owner) v->drag_owner = v->over_panel ? 2 : 1;
        v->last_mx = v->mx, v->last_my = v->my;
    } else {
        v->mouse_down[b] = false;
        if (!v->mouse_down[0] && !v->mouse_down[1] && !v->mouse_down[2]) v->drag_owner = 0;
    }
}

void view_mouse_move(view *v, double x, double y) {
    v->mx = x, v->my = y;
}
void view_mouse_wheel(view *v, double dy) {
    v->wheel += dy;
}

static void on_button(GLFWwindow *w, int button, int action, int mods) {
    (void)mods;
    int b = button == GLFW_MOUSE_BUTTON_LEFT     ? 0
            : button == GLFW_MOUSE_BUTTON_RIGHT  ? 1
            : button == GLFW_MOUSE_BUTTON_MIDDLE ? 2
                                                 : -1;
    view_mouse_button(from(w), b, action == GLFW_PRESS);
}

static void on_cursor(GLFWwindow *w, double x, double y) {
    to_fb(w, &x, &y);
    view_mouse_move(from(w), x, y);
}

static void on_scroll(GLFWwindow *w, double dx, double dy) {
    (void)dx;
    view_mouse_wheel(from(w), dy);
}

void view_install_callbacks(view *v) {
    GLFWwindow *w = v->win;
    glfwSetWindowUserPointer(w, v);
    glfwSetKeyCallback(w, on_key);
    glfwSetCharCallback(w, on_char);
    glfwSetMouseButtonCallback(w, on_button);
    glfwSetCursorPosCallback(w, on_cursor);
    glfwSetScrollCallback(w, on_scroll);
}

// Mouse drags and held movement keys move the camera; the panel takes the
// mouse when the drag started over it (view_overlay handles that part).
static void camera_input(view *v, double dt) {
    GLFWwindow *w = v->win;
    if (v->drag_owner == 1) {
        double dx = v->mx - v->last_mx, dy = v->my - v->last_my;
        if (dx || dy) {
            if (v->mouse_down[0] && !v->cam.fly)
                view_cam_rotate(&v->cam, (float)(0.3 * dx), (float)(0.3 * dy));
            else if (v->mouse_down[0])
                view_cam_rotate(&v->cam, (float)(0.2 * dx), (float)(-0.2 * dy));
            if (v->mouse_down[1] || v->mouse_down[2]) {
                float d[3] = {v->cam.target[0] - v->cam.pos[0], v->cam.target[1] - v->cam.pos[1],
                              v->cam.target[2] - v->cam.pos[2]};
                float dist = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
                float k = 1.5f * dist / (float)(v->fb_h > 0 ? v->fb_h : 1);
                view_cam_move(&v->cam, 0, (float)(-dx) * k, (float)dy * k);
            }
            v->cam_dirty = true;
        }
    }
    v->last_mx = v->mx, v->last_my = v->my;
    if (v->wheel != 0 && !v->over_panel) {
        if (v->cam.fly)
            v->cam.speed *= powf(1.2f, (float)v->wheel);
        else
            view_cam_dolly(&v->cam, powf(0.9f, (float)v->wheel));
        v->cam_dirty = !v->cam.fly || v->cam_dirty;
    }
    if (v->editing) return; // typed text is not movement
    float f = 0, r = 0, u = 0;
    f += glfwGetKey(w, GLFW_KEY_W) == GLFW_PRESS;
    f -= glfwGetKey(w, GLFW_KEY_S) == GLFW_PRESS;
    r += glfwGetKey(w, GLFW_KEY_D) == GLFW_PRESS;
    r -= glfwGetKey(w, GLFW_KEY_A) == GLFW_PRESS;
    u += glfwGetKey(w, GLFW_KEY_E) == GLFW_PRESS;
    u -= glfwGetKey(w, GLFW_KEY_Q) == GLFW_PRESS;
    if (f || r || u) {
        bool fast = glfwGetKey(w, GLFW_KEY_LEFT_SHIFT) == GLFW_PRESS ||
                    glfwGetKey(w, GLFW_KEY_RIGHT_SHIFT) == GLFW_PRESS;
        // Clamp dt so a stall does not throw the camera across the scene.
        float s = v->cam.speed * (float)(dt < 0.1 ? dt : 0.1) * (fast ? 5.0f : 1.0f);
        view_cam_move(&v->cam, f * s, r * s, u * s);
        v->cam_dirty = true;
    }
}

// Which passes took part in this frame: a pass's counters move by one for
// every frame it is in the pass list.
static void collect_rows(view *v) {
    int n = st_world_num_pass_stats(v->world);
    if (n > v->num_prev) {
        uint32_t *p = realloc(v->prev_totals, (size_t)n * sizeof *p);
        if (!p) return;
        for (int i = v->num_prev; i < n; i++)
            p[i] = 0;
        v->prev_totals = p;
        v->num_prev = n;
    }
    v->num_rows = 0;
    bool full = false;
    for (int i = 0; i < n; i++) {
        const st_pass_stats *s = st_world_pass_stats(v->world, i);
        uint32_t total = s->runs + s->skipped + s->culled;
        bool active = total != v->prev_totals[i];
        v->prev_totals[i] = total;
        full |= s->num_samples >= ST_STATS_MAX_SAMPLES - 1;
        if (!active || v->num_rows >= VIEW_MAX_ROWS) continue;
        view_pass_row *r = &v->rows[v->num_rows++];
        snprintf(r->module, sizeof r->module, "%s", s->module);
        snprintf(r->pass, sizeof r->pass, "%s", s->pass);
        r->state = s->ran_last_frame ? VIEW_RAN : s->culled_last_frame ? VIEW_CULLED : VIEW_SKIPPED;
        r->gpu_ms = r->cpu_ms = 0;
        if (r->state == VIEW_RAN && s->num_samples > 0) {
            r->gpu_ms = s->gpu_ms[s->num_samples - 1];
            r->cpu_ms = s->cpu_ms[s->num_samples - 1];
        }
        r->gpu_med = st_median_f(s->gpu_ms, s->num_samples);
        r->runs = s->runs, r->skipped = s->skipped, r->culled = s->culled;
    }
    // Samples are capped; start a new window so "last" stays the last frame.
    if (full) st_world_reset_samples(v->world);
}

bool view_frame(view *v, st_err *err) {
    GLFWwindow *w = v->win;
    double now = glfwGetTime();
    double dt = v->last_time > 0 ? now - v->last_time : 0;
    v->last_time = now;
    glfwPollEvents();
    if (glfwWindowShouldClose(w)) v->quit = true;
    camera_input(v, dt);
    if (v->cam_dirty) {
        st_world_set_camera(v->world, v->cam.pos, v->cam.target, v->cam.up);
        v->cam_dirty = false;
    }
    int fw, fh;
    glfwGetFramebufferSize(w, &fw, &fh);
    if (fw < 1 || fh < 1) { // minimised: nothing to draw, wait for events
        for (int b = 0; b < 3; b++)
            v->mouse_pressed[b] = false;
        v->wheel = 0;
        if (!v->script) glfwWaitEventsTimeout(0.1);
        return true;
    }
    v->fb_w = fw, v->fb_h = fh;
    const st_camera *c = st_world_camera(v->world);
    const int rw = v->fixed_size ? v->render_w : fw, rh = v->fixed_size ? v->render_h : fh;
    if ((c->width != rw || c->height != rh) && !st_world_resize(v->world, rw, rh, err))
        return false;

    double t0 = st_now_ms();
    st_err ferr = {0};
    bool ok = st_world_frame(v->world, &ferr);
    glFinish();
    v->world_ms = st_now_ms() - t0;
    if (!ok) {
        // Shown, and the loop goes on with the last good image; a script stops.
        snprintf(v->error, sizeof v->error, "frame failed: %.1000s", ferr.msg);
        if (!v->frame_failed) fprintf(stderr, "strahl view: %s\n", v->error);
        v->frame_failed = true;
        if (v->script) {
            *err = ferr;
            return false;
        }
    } else if (v->frame_failed) {
        v->frame_failed = false;
        v->error[0] = 0;
    }
    collect_rows(v);
    v->frames++;

    view_gl_display(&v->gl, st_world_camera(v->world)->current, rw, rh, fw, fh, v->exposure);
    view_overlay(v);
    view_ui_flush(&v->gl, fw, fh);
    for (int b = 0; b < 3; b++)
        v->mouse_pressed[b] = false;
    v->wheel = 0;
    if (v->want_capture) {
        v->want_capture = false;
        st_err cerr = {0};
        if (view_gl_capture(v->capture_path, fw, fh, &cerr))
            view_message(v, "window capture: %s", v->capture_path);
        else if (v->script)
            return *err = cerr, false;
        else
            view_message(v, "%s", cerr.msg);
    }
    if (!st_gl_check("viewer overlay", err)) return false;
    glfwSwapBuffers(w);
    double end = glfwGetTime();
    v->frame_ms = (end - now) * 1000.0;
    v->frame_ms_avg = v->frame_ms_avg > 0 ? 0.9 * v->frame_ms_avg + 0.1 * v->frame_ms : v->frame_ms;
    return true;
}
