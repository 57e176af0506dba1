// The files a scene was read from, and the output check against them
// (st_scene.h): `render s.json -o model.png` must not replace the glb named
// model.png that the scene loads.
#define _GNU_SOURCE
#include "st_scene.h"
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

bool st_scene_note_file(st_scene *scene, const char *path, st_err *err) {
    struct stat st;
    if (!path || stat(path, &st) != 0) return true; // nothing there to overwrite
    for (int i = 0; i < scene->num_files; i++)
        if (scene->files[i].dev == (uint64_t)st.st_dev &&
            scene->files[i].ino == (uint64_t)st.st_ino)
            return true;
    st_scene_file *f = realloc(scene->files, (size_t)(scene->num_files + 1) * sizeof *f);
    char *copy = strdup(path);
    if (f) scene->files = f;
    if (!f || !copy) {
        free(copy);
        return st_fail(err, ST_ERR_RUNTIME, "%s: out of memory", path);
    }
    f[scene->num_files++] = (st_scene_file){copy, (uint64_t)st.st_dev, (uint64_t)st.st_ino};
    return true;
}

bool st_scene_check_output(const st_scene *scene, const char *flag, const char *path, st_err *err) {
    struct stat st;
    // An output that does not exist yet is no input; one that does is
    // compared by identity, so hard links and symlinks are caught too.
    if (!scene || !path || stat(path, &st) != 0) return true;
    for (int i = 0; i < scene->num_files; i++) {
        const st_scene_file *f = &scene->files[i];
        if (f->dev == (uint64_t)st.st_dev && f->ino == (uint64_t)st.st_ino)
            return st_fail(err, ST_ERR_INPUT,
                           "%s %s: is '%s', a file the scene %s uses (the same file); "
                           "refusing to overwrite it",
                           flag ? flag : "output", path, f->path, scene->path);
    }
    return true;
}

void st_scene_files_free(st_scene *scene) {
    for (int i = 0; i < scene->num_files; i++)
        free(scene->files[i].path);
    free(scene->files);
    scene->files = NULL;
    scene->num_files = 0;
}
