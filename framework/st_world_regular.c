// The world's regular pass: its program (and the background's), built for
// the lights, the medium, the pixel filter and the loaded modules' includes.
#include "st_world_regular.h"
#include "st_world_state.h"
#include <stdio.h>

bool st_world_build_regular(st_world *w, st_err *err) {
    char defines[1024];
    // Exact primary visibility (regular.geom) only with the point filter: a
    // pixel is then one sample at its centre, which the rasteriser's edge
    // snapping (1/256 px on llvmpipe) can put on the wrong side of a
    // silhouette for the whole pixel. Under the box filter it moves at most
    // that sliver of an edge pixel's area, well inside the filter's
    // tolerance, and the geometry stage costs 4.3x the frame on a 161k-
    // triangle scene on llvmpipe (docs/physics.md, "Primary visibility").
    bool exact = w->opts.filter == ST_FILTER_POINT;
    int n = snprintf(defines, sizeof defines, "%s%s", w->light_defines,
                     exact ? "ST_EXACT_PRIMARY 1\n" : "");
    for (int m = 0; m < w->num_mods; m++)
        if (w->mods[m]->p->regular_include)
            n += snprintf(defines + n, sizeof defines - (size_t)n, "#include \"%s\"\n",
                          w->mods[m]->p->regular_include);
    st_shader *sh =
        exact ? st_shader_load_gs("common/regular.vert", "common/regular.geom",
                                  "common/regular.frag", defines, err)
              : st_shader_load("common/regular.vert", "common/regular.frag", defines, err);
    if (!sh) return false;
    st_shader *bg = NULL;
    if (w->scene->has_background) {
        bg = st_shader_load("common/fullscreen.vert", "common/background.frag", w->light_defines,
                            err);
        if (!bg) {
            st_shader_destroy(sh);
            return false;
        }
    }
    st_shader_destroy(w->regular);
    st_shader_destroy(w->background);
    w->regular = sh;
    w->background = bg;
    return true;
}
