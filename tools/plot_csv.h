// The reader of strahl bench CSVs for `strahl plot` (tools/cmd_plot.c),
// separate so that the fuzz target (tests/fuzz/fuzz_csv.c) runs exactly it.
// Every string it keeps ends up in a gnuplot script: control characters are
// refused here, quotes are the script writer's to escape.
#ifndef ST_PLOT_CSV_H
#define ST_PLOT_CSV_H
#include "st_base.h"

#define ST_PLOT_MAX_ROWS 4096
#define ST_PLOT_MAX_PARAMS 8

typedef struct st_plot_row {
    char scene[128];
    int np;
    char name[ST_PLOT_MAX_PARAMS][64]; // "toth.samples"
    char value[ST_PLOT_MAX_PARAMS][64];
    double ms, err, x;
    int curve;
    bool is_default, is_baseline;
    bool noisy_ref; // ref_noise_warning = 1: the reference cannot resolve this error
} st_plot_row;

typedef struct st_plot_table {
    st_plot_row *rows; // ST_PLOT_MAX_ROWS of them
    int n;
    char metric[64];
    int noise_col; // 1 + the ref_noise_warning column of the last header (0: none seen)
} st_plot_table;

// Appends the rows of one CSV text (len bytes; `name` is used in messages)
// to t. Bad input: ST_ERR_INPUT naming name:line.
bool st_plot_parse_csv(const char *text, size_t len, const char *name, st_plot_table *t,
                       st_err *err);
// Reads path (a regular file within ST_CAP_TEXT) and parses it.
bool st_plot_read_csv(const char *path, st_plot_table *t, st_err *err);
// Whether s has a control character (bytes < 0x20 and 0x7f).
bool st_plot_has_control(const char *s);

#endif
