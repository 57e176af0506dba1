// Every subcommand answers --help on stdout with exit 0, and its text names
// every option its parser accepts (read from tools/cmd_NAME.c: each string
// literal starting with '-' that the parser compares an argument with), a
// default and an example. `strahl --version` names the version and the ABI.
// The README's usage block names the same options as each --help.
#include "st_test.h"
#include "st_base.h"
#include "st_module.h"

static const char *const commands[] = {"render", "view",  "modules", "reference", "compare",
                                       "bench",  "merge", "plot",    "info",      "convert"};

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

// Adds to set (n of max) the option starting at p ("--stats[=json]" and
// "--stats=json" are "--stats"); returns where it ends.
static const char *add_option(const char *p, char set[][64], int *n, int max) {
    size_t len = strspn(p, "-abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789");
    bool dup = len >= 64 || !strncmp(p, "-h", len) || !strncmp(p, "--help", len) || len < 2;
    for (int k = 0; !dup && k < *n; k++)
        dup = strlen(set[k]) == len && !strncmp(set[k], p, len);
    if (!dup && *n < max) {
        memcpy(set[*n], p, len);
        set[(*n)++][len] = 0;
    }
    return p + len;
}

// The options the README's usage block gives `strahl cmd` (its line and the
// indented lines after it).
static int readme_options(const char *readme, const char *cmd, char set[][64], int max) {
    const char *block = strstr(readme, "## Command line");
    block = block ? strstr(block, "```\n") : NULL;
    const char *end = block ? strstr(block + 4, "```") : NULL;
    char head[64];
    snprintf(head, sizeof head, "\nstrahl %s ", cmd);
    const char *p = block ? strstr(block, head) : NULL;
    if (!p || p > end) return -1;
    const char *stop = p + strlen(head);
    while ((stop = strchr(stop, '\n')) && stop < end && stop[1] == ' ')
        stop++;
    int n = 0;
    for (p += strlen(head); p < stop; p++)
        if (*p == '-' && (p[-1] == ' ' || p[-1] == '[') && p[1] != ' ')
            p = add_option(p, set, &n, max) - 1;
    return n;
}

// The options `strahl cmd --help` lists: the first word(s) of its lines
// that start with "  -" ("  -h, --help", "  --stats, --stats=json").
static int help_options(const char *help, char set[][64], int max) {
    int n = 0;
    for (const char *p = help; (p = strstr(p, "\n  -"));) {
        p += 3;
        while (*p == '-') {
            p = add_option(p, set, &n, max);
            p += strspn(p, "=abcdefghijklmnopqrstuvwxyz");
            if (strncmp(p, ", -", 3)) break;
            p += 2;
        }
    }
    return n;
}

// The README's usage block names exactly the options of every --help.
static void readme_agrees(const char *cmd, const char *help) {
    char path[4200];
    snprintf(path, sizeof path, "%s/README.md", ST_TEST_SOURCE_DIR);
    st_err err = {0};
    char *readme = st_read_file(path, NULL, &err);
    CHECK(readme != NULL, "%s", err.msg);
    if (!readme) return;
    static char a[128][64], b[128][64];
    int na = readme_options(readme, cmd, a, 128), nb = help_options(help, b, 128);
    free(readme);
    CHECK(na >= 0, "README.md's usage block has no 'strahl %s' line", cmd);
    for (int i = 0; i < nb; i++) {
        bool found = false;
        for (int k = 0; k < na; k++)
            found |= !strcmp(a[k], b[i]);
        CHECK(found, "README.md's usage of strahl %s lacks %s (in its --help)", cmd, b[i]);
    }
    for (int k = 0; k < na; k++) {
        bool found = false;
        for (int i = 0; i < nb; i++)
            found |= !strcmp(a[k], b[i]);
        CHECK(found, "README.md's usage of strahl %s names %s, which its --help does not", cmd,
              a[k]);
    }
}

// Every command of the viewer's script language (the table in
// tools/view/view_script.c) is in `strahl view --help` and docs/viewer.md.
static void script_commands_documented(void) {
    char path[4200], cmd[4400];
    static char help[16384];
    snprintf(path, sizeof path, "%s/tools/view/view_script.c", ST_TEST_SOURCE_DIR);
    st_err err = {0};
    char *src = st_read_file(path, NULL, &err);
    snprintf(path, sizeof path, "%s/docs/viewer.md", ST_TEST_SOURCE_DIR);
    char *doc = st_read_file(path, NULL, &err);
    snprintf(cmd, sizeof cmd, "'%s' view --help", ST_TEST_STRAHL);
    int rc = st_test_capture(help, sizeof help, cmd);
    CHECK(src && doc && rc == 0, "view_script.c, docs/viewer.md or view --help: %s", err.msg);
    int n = 0;
    for (const char *p = src; p && (p = strstr(p, "{\"")); p++) {
        const char *e = strchr(p + 2, '"');
        if (!e || strncmp(e, "\", c_", 4) || e - p > 40) continue;
        char name[48], a[64], b[64], c[64];
        snprintf(name, sizeof name, "%.*s", (int)(e - p - 2), p + 2);
        snprintf(a, sizeof a, "\n  %s ", name);
        snprintf(b, sizeof b, "| %s ", name);
        snprintf(c, sizeof c, "`%s", name);
        CHECK(strstr(help, a) || strstr(help, b), "view --help lacks the script command '%s'",
              name);
        CHECK(doc && strstr(doc, c), "docs/viewer.md lacks the script command '%s'", name);
        n++;
    }
    CHECK(n >= 20, "found only %d script commands in view_script.c", n);
    free(src);
    free(doc);
}

int main(void) {
    char out[16384];
    script_commands_documented();
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
        readme_agrees(commands[c], out);
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
