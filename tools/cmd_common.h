// Shared pieces of the subcommands: scene loading with --set/--size, and
// argument parsing helpers that report bad input the same way everywhere.
#ifndef ST_CMD_COMMON_H
#define ST_CMD_COMMON_H
#include "st_image.h"
#include "st_scene.h"

// Parses "WxH" (1..16384 each).
bool st_parse_size(const char *s, int *w, int *h);
// Parses a positive integer within [lo, hi].
bool st_parse_int(const char *s, long lo, long hi, long *out);
// Consumes a scene-loading option shared by render, reference, bench, view
// and info (--allow-outside-assets: glTF URIs may leave the glTF's folder;
// --auto-camera: a scene without a camera gets one framing its geometry;
// --overlay: the scene's "inscatter_overlay"); false when arg is not one.
bool st_cmd_scene_option(const char *arg);
// Consumes the shared options with a value, --enable MODULE[,MODULE] and
// --disable MODULE[,MODULE] (repeatable; st_scene_switch_modules applies them
// in st_load_scene_with); *known: opt was one.
bool st_cmd_scene_value(const char *opt, const char *v, bool *known, st_err *err);
// Help text of the shared scene options, for each command's --help.
#define ST_CMD_SCENE_HELP                                                                          \
    "  --enable MODULE[,MODULE]  switch techniques on (repeatable): added to the scene's\n"        \
    "                           modules with what they require (toth brings shadow_map);\n"        \
    "                           --set then reaches them (default: the scene's modules)\n"          \
    "  --disable MODULE[,MODULE] switch techniques off (repeatable; applied before --enable)\n"    \
    "  --overlay                let two in-scattering techniques (toth, froxel) add their\n"       \
    "                           light to one image, for a comparison overlay (default:\n"          \
    "                           refused, exit 2; the scene key \"inscatter_overlay\": true)\n"     \
    "  --auto-camera            a scene without a camera (a glTF without one) gets one that\n"     \
    "                           frames its geometry (default: refused)\n"

// How a subcommand's arguments are read by st_cmd_walk_args: -h/--help
// prints `help`; `value` consumes "OPTION VALUE" pairs (sets *known when it
// took OPTION); `flag` takes an option without a value (false: not one); the
// one argument that is not an option is the scene. `usage` follows the
// message for an unexpected argument ("" for none).
typedef struct st_argv_spec {
    const char *help, *usage;
    bool (*value)(void *ctx, const char *opt, const char *v, bool *known, st_err *err);
    bool (*flag)(void *ctx, const char *opt);
} st_argv_spec;
// Walks argv[1..argc) for spec into ctx and *scene; *help: -h was given.
bool st_cmd_walk_args(const st_argv_spec *spec, void *ctx, int argc, char **argv,
                      const char **scene, bool *help, st_err *err);
// Loads a scene (with the options above) and applies --set assignments and a
// --size override.
bool st_load_scene_with(const char *path, char **sets, int num_sets, int width, int height,
                        st_scene *scene, st_err *err);
// Prints a warning to stderr when the reference's noise is more than a third
// of the error it measures (st_metrics_noise_dominates), with the spp that
// would bring it to a third (ref_spp 0: unknown). Returns whether it warned.
bool st_warn_reference_noise(const char *cmd, const char *ref_path, const st_metrics *m,
                             int ref_spp);
// The pixel filter an EXR was made with: its strahl.filter attribute, or
// "point" without one (files from before the box filter sampled centres).
const char *st_exr_filter(const st_exr_meta *meta);
// Warns on stderr when A and B were made with different pixel filters.
// Returns whether it warned.
bool st_warn_filter_mismatch(const char *cmd, const char *a_path, const st_exr_meta *a,
                             const char *b_path, const st_exr_meta *b);
// Progress of a long command on stderr: on a terminal a bar with the
// elapsed time and an ETA (redrawn at most 4 times a second, from 1 s on);
// otherwise nothing until st_progress_end's one summary line.
typedef struct st_progress_bar {
    const char *label; // "reference", "bench"
    const char *unit;  // what is counted: "rows", "settings"
    int total;
    double t0, last;
    bool tty, drawn;
} st_progress_bar;
void st_progress_begin(st_progress_bar *p, const char *label, const char *unit, int total);
// done of total finished; item (may be NULL) names what runs now.
void st_progress_update(st_progress_bar *p, int done, const char *item);
// Ends the bar (terminal) or prints "strahl LABEL: DONE UNIT in T s[, extra]".
void st_progress_end(st_progress_bar *p, int done, const char *extra);
// The time-against-error plot of bench CSVs (tools/cmd_plot.c); metric names
// the error column when the CSVs have no header (NULL: from the header);
// baseline "M.P=V,..." marks that setting (NULL: none).
bool st_plot_csv(const char *const *csvs, int n, const char *out, const char *metric,
                 const char *baseline, const char *title, st_err *err);
// Checks of plot arguments before any work: --baseline is M.P=V[,M.P=V...],
// a title has no control characters (each string goes into a gnuplot script).
bool st_plot_check_baseline(const char *baseline, st_err *err);
bool st_plot_check_title(const char *title, st_err *err);
// s with every control character written as \xHH (at most n - 1 bytes into
// buf): text read from a file (an EXR attribute) goes into messages.
const char *st_printable(const char *s, char *buf, size_t n);
// Prints "strahl CMD: message" and returns the exit code for err.
int st_report(const char *cmd, const st_err *err);

#endif
