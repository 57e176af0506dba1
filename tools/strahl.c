// strahl command line: dispatches to the subcommands in tools/cmd_*.c.
#include "st_cmd.h"
#include "st_module.h"
#include <stdio.h>
#include <string.h>

// Weak so a subcommand whose file is not part of this build reports itself
// as missing instead of breaking the link.
#pragma weak st_cmd_render
#pragma weak st_cmd_view
#pragma weak st_cmd_modules
#pragma weak st_cmd_reference
#pragma weak st_cmd_compare
#pragma weak st_cmd_bench
#pragma weak st_cmd_merge
#pragma weak st_cmd_plot
#pragma weak st_cmd_info
#pragma weak st_cmd_convert

#ifndef ST_VERSION
#define ST_VERSION "unknown"
#endif

typedef struct {
    const char *name;
    int (*fn)(int, char **);
    const char *usage;
} st_command;

static int usage(FILE *f, const st_command *cmds, int n) {
    fprintf(f, "usage: strahl COMMAND ...   (strahl COMMAND --help for its options)\n");
    for (int i = 0; i < n; i++)
        fprintf(f, "  strahl %s %s\n", cmds[i].name, cmds[i].usage);
    fprintf(f, "  strahl --version\n");
    return 2;
}

int main(int argc, char **argv) {
    const st_command cmds[] = {
        {"render", st_cmd_render,
         "SCENE.json -o OUT.exr|OUT.png [--set MODULE.PARAM=VALUE]... [--size WxH] [--frames N] "
         "[--stats[=json]] [--exposure EV]"},
        {"view", st_cmd_view, "SCENE.json [--script FILE] [--size WxH] [--window WxH]"},
        {"info", st_cmd_info, "SCENE.json [--enable M,...] [--disable M,...] [--auto-camera]"},
        {"modules", st_cmd_modules, "[--json]"},
        {"reference", st_cmd_reference,
         "SCENE.json -o OUT.exr [--spp N] [--seed S] [--aov combined|direct|indirect|inscatter]"},
        {"convert", st_cmd_convert,
         "IN.exr -o OUT.png [--exposure EV] [--tonemap clamp|aces|filmic] [--false-colour "
         "[--scale MAX]]"},
        {"compare", st_cmd_compare, "A.exr B.exr [--json] [--heatmap OUT.png [--scale MAX]]"},
        {"merge", st_cmd_merge, "SHARD.exr SHARD.exr... -o OUT.exr"},
        {"plot", st_cmd_plot, "BENCH.csv... -o OUT.png|OUT.svg [--baseline MODULE.PARAM=V,...]"},
        {"bench", st_cmd_bench,
         "SCENE.json --reference REF.exr --sweep MODULE.PARAM=v1,v2,... --csv OUT.csv [--plot "
         "OUT.png]"},
    };
    const int n = (int)(sizeof cmds / sizeof cmds[0]);
    if (argc < 2) return usage(stderr, cmds, n);
    if (!strcmp(argv[1], "--version") || !strcmp(argv[1], "-V")) {
        printf("strahl %s (plugin ABI %d.%d)\n", ST_VERSION, ST_ABI_MAJOR, ST_ABI_MINOR);
        return 0;
    }
    if (!strcmp(argv[1], "-h") || !strcmp(argv[1], "--help") || !strcmp(argv[1], "help")) {
        usage(stdout, cmds, n);
        return 0;
    }
    for (int i = 0; i < n; i++) {
        if (strcmp(argv[1], cmds[i].name)) continue;
        if (!cmds[i].fn) {
            fprintf(stderr, "strahl: command '%s' is not part of this build\n", argv[1]);
            return 1;
        }
        return cmds[i].fn(argc - 1, argv + 1);
    }
    fprintf(stderr, "strahl: unknown command '%s'\n", argv[1]);
    return usage(stderr, cmds, n);
}
