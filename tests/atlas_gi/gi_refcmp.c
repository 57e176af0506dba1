// gi_refcmp IMAGE.exr REFERENCE.exr [BLOCK]: noise-corrected relMSE and
// NRMSE of an image against a `strahl reference` EXR (benchmarks; see
// gi_refcmp.h). One line of JSON.
#include "gi_refcmp.h"
#include <stdio.h>
#include <stdlib.h>

int main(int argc, char **argv) {
    if (argc < 3) {
        fprintf(stderr, "usage: gi_refcmp IMAGE.exr REFERENCE.exr [BLOCK]\n");
        return 2;
    }
    gi_refcmp m = {0};
    st_err err = {0};
    if (!gi_refcmp_files(argv[1], argv[2], argc > 3 ? atoi(argv[3]) : 1, &m, &err)) {
        fprintf(stderr, "gi_refcmp: %s\n", err.msg);
        return 2;
    }
    printf("{\"relmse\": %.6f, \"nrmse\": %.6f, \"relmse_raw\": %.6f, \"nrmse_raw\": %.6f, "
           "\"ref_noise_relmse\": %.6f, "
           "\"ref_noise_nrmse\": %.6f, \"mean\": %.6f, \"ref_mean\": %.6f}\n",
           m.relmse, m.nrmse, m.relmse_raw, m.nrmse_raw, m.noise_relmse, m.noise_nrmse, m.mean_a,
           m.mean_b);
    return 0;
}
