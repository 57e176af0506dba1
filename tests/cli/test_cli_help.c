// Every subcommand answers --help on stdout with exit 0, and its text names
// every option its parser accepts (read from tools/cmd_NAME.c: each string
// literal starting with '-' that the parser compares an argument with), a
// default and an example. `strahl --version` names the version and the ABI.
#include "st_test.h"
#include "st_base.h"
#include "st_module.h"

static const char *const commands[] = {"render", "view",  "modules", "reference", "compare",
                                       "bench",  "merge", "plot",    "info"};

// Appends to opts (NUL-separated, at most max) every "-..." literal that is
// the second argument of a strcmp/strncmp in src; returns the count.
static int parser_options(const char *src, char opts[][64], int max) {
    int n = 0;
    for (const char *p = src; (p = strstr(p, "strcmp(")) && n < max; p++) {
        const char *q = strchr(p, ','), *close = strchr(p, ')');
        if (!q || !close || q > close) continue;
        while (*++q == ' ') {
        }
        if (q[0] != '"' || q[1] != '-') continue;
        const char *e = strchr(q + 1, '"');
        size_t len = (size_t)(e - q - 1);
        if (len >= 64) continue;
        if (q[len] == '=') len--; // "--heatmap=" is the --heatmap option
        memcpy(opts[n], q + 1, len);
        opts[n][len] = 0;
        bool dup = false;
        for (int k = 0; k < n; k++)
            dup |= !strcmp(opts[k], opts[n]);
        if (!dup) n++;
    }
    return n;
}

int main(void) {
    char out[16384];
    for (size_t c = 0; c < sizeof commands / sizeof commands[0]; c++) {
        char path[4200], cmd[4400];
        snprintf(path, sizeof path, "%s/tools/cmd_%s.c", ST_TEST_SOURCE_DIR, commands[c]);
        st_err err = {0};
        char *src = st_read_file(path, NULL, &err);
        CHECK(src != NULL, "%s", err.msg);
        if (!src) continue;
        static char opts[128][64];
        int n = parser_options(src, opts, 128);
        free(src);
        CHECK(n >= 2, "%s: found only %d options in the parser", commands[c], n);
        // stdout only: the text must not go to stderr.
        snprintf(cmd, sizeof cmd, "'%s' %s --help 2>/dev/null", ST_TEST_STRAHL, commands[c]);
        int rc = st_test_capture(out, sizeof out, cmd);
        CHECK(rc == 0, "strahl %s --help: exit %d", commands[c], rc);
        char usage[64];
        snprintf(usage, sizeof usage, "usage: strahl %s", commands[c]);
        CHECK(strstr(out, usage) != NULL, "strahl %s --help: no '%s'", commands[c], usage);
        CHECK(strstr(out, "example") != NULL, "strahl %s --help: no example", commands[c]);
        CHECK(strstr(out, "default") != NULL, "strahl %s --help: no default named", commands[c]);
        for (int k = 0; k < n; k++)
            CHECK(strstr(out, opts[k]) != NULL, "strahl %s --help does not mention %s", commands[c],
                  opts[k]);
        // -h is the same.
        snprintf(cmd, sizeof cmd, "'%s' %s -h 2>/dev/null", ST_TEST_STRAHL, commands[c]);
        CHECK(st_test_capture(out, sizeof out, cmd) == 0, "strahl %s -h", commands[c]);
    }
    char want[64];
    snprintf(want, sizeof want, "ABI %d.%d", ST_ABI_MAJOR, ST_ABI_MINOR);
    char cmd[4400];
    snprintf(cmd, sizeof cmd, "'%s' --version", ST_TEST_STRAHL);
    CHECK(st_test_capture(out, sizeof out, cmd) == 0, "strahl --version");
    CHECK(strstr(out, want) != NULL, "--version: no '%s' in '%s'", want, out);
    CHECK(strncmp(out, "strahl ", 7) == 0 && out[7] >= '0' && out[7] <= '9', "--version: '%s'",
          out);
    // An unknown option is still bad input (exit 2), not help.
    snprintf(cmd, sizeof cmd, "'%s' render --no-such-option", ST_TEST_STRAHL);
    CHECK(st_test_capture(out, sizeof out, cmd) == 2, "render --no-such-option");
    return st_test_summary("cli_help");
}
