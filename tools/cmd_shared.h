// What the command files share with the Python module (python/): pieces of
// `strahl modules` and `strahl bench` that both need, defined in their
// cmd_*.c so there is one copy. The still loop is st_still.h.
#ifndef ST_CMD_SHARED_H
#define ST_CMD_SHARED_H
#include "st_gl.h"
#include "st_module.h"

// "float", "int", "bool", "enum" (cmd_modules.c).
const char *st_param_type_name(st_param_type t);
// The light types a plugin handles, ST_LIGHT_BIT(type) bits (0 in the
// descriptor: point lights only) (cmd_modules.c).
unsigned st_plugin_lights(const st_plugin *p);

// `strahl bench` without its files: argv as the command's (argv[0] is
// skipped; --csv, --plot, --append are not needed), the CSV text it would
// write (header and one line per setting; malloc'd) or NULL. Renders on
// ctx (current; the framework keeps some GL objects per process, so a host
// with a context of its own passes it). Prints nothing but the command's
// warnings (cmd_bench.c).
char *st_bench_rows(int argc, char **argv, st_context *ctx, st_err *err);

#endif
