// A test plugin whose ABI 1.4 tables are wrong, one way per value of the
// environment variable PROBE_BAD (read each time the loader asks for the
// descriptor), for test_declared_programs: "pass" a pass naming a program
// the table lacks, "export" an export naming no parameter, "both" a program
// with a fragment and a compute file, "define" a program compiling in a
// parameter the module lacks; unset, the tables are valid.
#include "st_module.h"
#include <stdlib.h>
#include <string.h>

static const st_param_def params[] = {{"value", ST_PARAM_FLOAT, 1, 0, 10, NULL, "exported"}};
static const st_program_decl good_programs[] = {{"p", .comp = "probe_bad/p.comp"}};
static const st_program_decl both[] = {
    {"p", .frag = "probe_bad/p.frag", .comp = "probe_bad/p.comp"}};
static const st_program_decl define[] = {
    {"p", .comp = "probe_bad/p.comp", .param_defines = "value,nope"}};
static const st_pass_decl good_passes[] = {
    {{"fill", ST_STAGE_PRE, "", "probe_bad.t", 0}, .program = "p", .target = {GL_R32F, 1}}};
static const st_pass_decl missing[] = {
    {{"fill", ST_STAGE_PRE, "", "probe_bad.t", 0}, .program = "nope", .target = {GL_R32F, 1}}};
static const st_export_decl good_exports[] = {{"u_value", .param = "value"}};
static const st_export_decl no_param[] = {{"u_value", .param = "nope"}};

#define DESC(progs, pass, exp)                                                                     \
    {                                                                                              \
        .abi_major = ST_ABI_MAJOR, .abi_minor = ST_ABI_MINOR, .struct_size = sizeof(st_plugin),    \
        .name = "probe_bad", .description = "test plugin with bad ABI 1.4 tables",                 \
        ST_PARAMS(params), ST_PROGRAMS(progs), ST_PASSES(pass), ST_EXPORTS(exp)                    \
    }
static const st_plugin descs[] = {
    DESC(good_programs, good_passes, good_exports), DESC(good_programs, missing, good_exports),
    DESC(good_programs, good_passes, no_param),     DESC(both, good_passes, good_exports),
    DESC(define, good_passes, good_exports),
};

ST_EXPORT const st_plugin *strahl_plugin(void) {
    static const char *const kinds[] = {"", "pass", "export", "both", "define"};
    const char *k = getenv("PROBE_BAD");
    for (int i = 1; k && i < 5; i++)
        if (!strcmp(k, kinds[i])) return &descs[i];
    return &descs[0];
}
ST_EXPORT const st_abi_sizes *strahl_plugin_sizes(void) {
    static const st_abi_sizes sizes = ST_ABI_SIZES;
    return &sizes;
}
