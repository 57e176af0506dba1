#include "st_test.h"
#include "st_base.h"

int main(void) {
    char out[256];
    st_path_join(out, sizeof out, "scenes", "assets/a.glb");
    CHECK(!strcmp(out, "scenes/assets/a.glb"), "%s", out);
    st_path_join(out, sizeof out, "scenes", "/abs/a.glb");
    CHECK(!strcmp(out, "/abs/a.glb"), "%s", out);
    st_path_dir(out, sizeof out, "x/y/scene.json");
    CHECK(!strcmp(out, "x/y"), "%s", out);
    st_path_dir(out, sizeof out, "scene.json");
    CHECK(!strcmp(out, "."), "%s", out);
    st_err err = {0};
    CHECK(st_read_file("/nonexistent/file.json", NULL, &err) == NULL, "read of missing file");
    CHECK(st_err_exit_code(&err) == 2, "missing file is bad input: %d", st_err_exit_code(&err));
    CHECK(strstr(err.msg, "/nonexistent/file.json") != NULL, "message names the file: %s", err.msg);
    return st_test_summary("test_base");
}
