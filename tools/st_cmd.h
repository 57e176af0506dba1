// The subcommands of the `strahl` command line. Each returns an exit code
// (0 ok, 1 runtime failure, 2 bad input) and prints its own one-line error.
#ifndef ST_CMD_H
#define ST_CMD_H

int st_cmd_render(int argc, char **argv);
int st_cmd_view(int argc, char **argv);
int st_cmd_modules(int argc, char **argv);
int st_cmd_reference(int argc, char **argv);
int st_cmd_compare(int argc, char **argv);
int st_cmd_bench(int argc, char **argv);
int st_cmd_merge(int argc, char **argv);
int st_cmd_plot(int argc, char **argv);
int st_cmd_info(int argc, char **argv);
int st_cmd_convert(int argc, char **argv);

#endif
