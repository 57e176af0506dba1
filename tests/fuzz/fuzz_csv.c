// libFuzzer target: the bench-CSV reader of `strahl plot` (tools/plot_csv.c)
// on arbitrary bytes. Must never crash, leak or hang; every string it keeps
// is free of control characters (they would break the gnuplot script).
#include "plot_csv.h"
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    static st_plot_row rows[ST_PLOT_MAX_ROWS];
    st_plot_table t = {.rows = rows};
    st_err e = {0};
    if (st_plot_parse_csv((const char *)data, size, "fuzz.csv", &t, &e)) {
        for (int i = 0; i < t.n; i++) {
            const st_plot_row *r = &rows[i];
            if (st_plot_has_control(r->scene)) abort();
            for (int k = 0; k < r->np; k++)
                if (st_plot_has_control(r->name[k]) || st_plot_has_control(r->value[k])) abort();
        }
    }
    return 0;
}
