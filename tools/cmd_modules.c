// strahl modules: every installed plugin with its parameters (from the
// descriptors, so plugins written later show up without changes here).
#include "cmd_shared.h"
#include "st_cmd.h"
#include "st_module.h"
#include <stdio.h>
#include <string.h>

static void json_str(const char *s) {
    putchar('"');
    for (; s && *s; s++) {
        if (*s == '"' || *s == '\\') putchar('\\');
        if ((unsigned char)*s < 0x20)
            printf("\\u%04x", *s);
        else
            putchar(*s);
    }
    putchar('"');
}

const char *st_param_type_name(st_param_type t) {
    switch (t) {
    case ST_PARAM_FLOAT:
        return "float";
    case ST_PARAM_INT:
        return "int";
    case ST_PARAM_BOOL:
        return "bool";
    case ST_PARAM_ENUM:
        return "enum";
    }
    return "?";
}

static const char help_text[] =
    "usage: strahl modules [--json]\n"
    "Lists every installed plugin (found in $STRAHL_MODULE_PATH, the build and the\n"
    "install folder) with its requirements, light types and parameters: type, default, range or\n"
    "choices, help. Ranges are the descriptors', the same on every driver; where a driver\n"
    "enforces less (toth.samples on llvmpipe), the parameter's help says so and the value\n"
    "is refused there with a message (exit 2).\n"
    "  --json      machine-readable list (default: text)\n"
    "  -h, --help  this text\n"
    "example:\n"
    "  strahl modules --json\n";

unsigned st_plugin_lights(const st_plugin *p) {
    return p->light_types ? p->light_types : ST_LIGHT_BIT(ST_LIGHT_POINT);
}

// One parameter as a JSON object.
static void print_param_json(const st_param_def *d, bool first) {
    char def[64];
    st_param_format(d, d->def, def, sizeof def);
    printf("%s\n   {\"name\": ", first ? "" : ",");
    json_str(d->name);
    printf(", \"type\": \"%s\", \"default\": ", st_param_type_name(d->type));
    if (d->type == ST_PARAM_ENUM)
        json_str(def);
    else if (d->type == ST_PARAM_BOOL)
        printf("%s", def);
    else
        printf("%.9g", d->def);
    if (d->type == ST_PARAM_FLOAT || d->type == ST_PARAM_INT)
        printf(", \"min\": %.9g, \"max\": %.9g", d->min, d->max);
    if (d->type == ST_PARAM_ENUM) {
        printf(", \"choices\": ");
        json_str(d->choices);
    }
    printf(", \"help\": ");
    json_str(d->help);
    printf("}");
}

// One plugin as a JSON object (after a comma unless it is the first).
static void print_json(const st_plugin *p, bool first) {
    printf("%s\n {\"name\": ", first ? "" : ",");
    json_str(p->name);
    printf(", \"description\": ");
    json_str(p->description);
    printf(", \"abi\": \"%u.%u\", \"requires\": ", p->abi_major, p->abi_minor);
    json_str(p->requires);
    printf(", \"provides\": ");
    json_str(p->provides);
    printf(", \"lights\": [");
    for (int t = 0, n = 0; t < ST_LIGHT_TYPE_COUNT; t++)
        if (st_plugin_lights(p) & ST_LIGHT_BIT(t))
            printf("%s\"%s\"", n++ ? ", " : "", st_light_type_name(t));
    printf("]");
    printf(", \"params\": [");
    for (int k = 0; k < p->num_params; k++)
        print_param_json(&p->params[k], k == 0);
    printf("]}");
}

// One plugin as text: name, description, requires/provides, lights, one
// line per parameter.
static void print_text(const st_plugin *p) {
    printf("%s - %s\n", p->name, p->description ? p->description : "");
    if (p->requires && p->requires[0]) printf("  requires: %s\n", p->requires);
    if (p->provides && p->provides[0]) printf("  provides: %s\n", p->provides);
    printf("  lights:");
    for (int t = 0; t < ST_LIGHT_TYPE_COUNT; t++)
        if (st_plugin_lights(p) & ST_LIGHT_BIT(t)) printf(" %s", st_light_type_name(t));
    printf("\n");
    for (int k = 0; k < p->num_params; k++) {
        const st_param_def *d = &p->params[k];
        char def[64];
        st_param_format(d, d->def, def, sizeof def);
        printf("  %-16s %-5s default %-8s", d->name, st_param_type_name(d->type), def);
        if (d->type == ST_PARAM_FLOAT || d->type == ST_PARAM_INT)
            printf(" [%g, %g]", d->min, d->max);
        if (d->type == ST_PARAM_ENUM) printf(" {%s}", d->choices);
        printf("  %s\n", d->help ? d->help : "");
    }
}

int st_cmd_modules(int argc, char **argv) {
    bool json = false;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "-h") || !strcmp(argv[i], "--help")) {
            fputs(help_text, stdout);
            return 0;
        }
        if (!strcmp(argv[i], "--json"))
            json = true;
        else {
            fprintf(stderr, "strahl modules: unexpected argument '%s'\n", argv[i]);
            return 2;
        }
    }
    char names[64][ST_NAME_MAX];
    int n = st_plugin_list(names, 64);
    if (json) printf("[");
    int shown = 0, rc = 0;
    for (int i = 0; i < n; i++) {
        st_err err = {0};
        st_plugin_lib *lib = st_plugin_open(names[i], &err);
        if (!lib) {
            fprintf(stderr, "strahl modules: %s\n", err.msg);
            rc = 1;
            continue;
        }
        if (json)
            print_json(st_plugin_desc(lib), shown == 0);
        else
            print_text(st_plugin_desc(lib));
        shown++;
        st_plugin_close(lib);
    }
    if (json) printf("\n]\n");
    return rc;
}
