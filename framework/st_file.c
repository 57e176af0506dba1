// Bounded reads of regular files and checked, atomic writes (st_file.h).
#define _GNU_SOURCE
#include "st_file.h"
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

static const char *kind_of(mode_t m) {
    if (S_ISDIR(m)) return "a directory";
    if (S_ISFIFO(m)) return "a FIFO";
    if (S_ISCHR(m)) return "a character device";
    if (S_ISBLK(m)) return "a block device";
    if (S_ISSOCK(m)) return "a socket";
    if (S_ISLNK(m)) return "a symbolic link";
    return "not a regular file";
}

static bool cap_fail(st_err *err, const char *path, const char *what, uint64_t cap) {
    return st_fail(err, ST_ERR_INPUT, "%s: larger than the %llu MiB limit for a %s", path,
                   (unsigned long long)(cap >> 20), what ? what : "file");
}

int st_open_input(const char *path, uint64_t cap, const char *what, uint64_t *size, st_err *err) {
    if (!path || !path[0]) return st_fail(err, ST_ERR_INPUT, "empty file name"), -1;
    // O_NONBLOCK: opening a FIFO without a writer, or a device, returns at
    // once; the type is checked on the descriptor (no race with a rename).
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
    if (fd < 0) return st_fail(err, ST_ERR_INPUT, "%s: cannot open: %s", path, strerror(errno)), -1;
    struct stat st;
    if (fstat(fd, &st) != 0) {
        st_fail(err, ST_ERR_INPUT, "%s: cannot stat: %s", path, strerror(errno));
        close(fd);
        return -1;
    }
    if (!S_ISREG(st.st_mode)) {
        st_fail(err, ST_ERR_INPUT, "%s: not a regular file (%s)", path, kind_of(st.st_mode));
        close(fd);
        return -1;
    }
    if ((uint64_t)st.st_size > cap) {
        cap_fail(err, path, what, cap);
        close(fd);
        return -1;
    }
    int fl = fcntl(fd, F_GETFL);
    if (fl >= 0) fcntl(fd, F_SETFL, fl & ~O_NONBLOCK);
    if (size) *size = (uint64_t)st.st_size;
    return fd;
}

char *st_read_input(const char *path, uint64_t cap, const char *what, size_t *len, st_err *err) {
    uint64_t size = 0;
    int fd = st_open_input(path, cap, what, &size, err);
    if (fd < 0) return NULL;
    // fstat's size is a hint (0 for files of /proc); the cap is enforced on
    // what is actually read.
    size_t cap_n = (size_t)(cap < SIZE_MAX - 2 ? cap : SIZE_MAX - 2);
    size_t alloc = (size_t)size + 1 < 4096 ? 4096 : (size_t)size + 1, n = 0;
    char *buf = malloc(alloc + 1);
    for (;;) {
        if (!buf) {
            close(fd);
            st_fail(err, ST_ERR_RUNTIME, "%s: out of memory", path);
            return NULL;
        }
        if (n == alloc) {
            size_t next = alloc > cap_n / 2 ? cap_n + 1 : alloc * 2;
            char *nb = realloc(buf, next + 1);
            if (!nb) free(buf);
            buf = nb;
            alloc = next;
            continue;
        }
        ssize_t r = read(fd, buf + n, alloc - n);
        if (r < 0 && errno == EINTR) continue;
        if (r < 0) {
            st_fail(err, ST_ERR_INPUT, "%s: read error: %s", path, strerror(errno));
            break;
        }
        if (r == 0) {
            close(fd);
            buf[n] = 0;
            if (len) *len = n;
            return buf;
        }
        n += (size_t)r;
        if (n > cap_n) {
            cap_fail(err, path, what, cap);
            break;
        }
    }
    free(buf);
    close(fd);
    return NULL;
}

// st_base.h's whole-file read, which the SDK gives plugins: a user's input
// like any other, under a fixed cap.
char *st_read_file(const char *path, size_t *len, st_err *err) {
    return st_read_input(path, 256ull << 20, "file", len, err);
}

FILE *st_fopen_input(const char *path, uint64_t cap, const char *what, st_err *err) {
    int fd = st_open_input(path, cap, what, NULL, err);
    if (fd < 0) return NULL;
    FILE *f = fdopen(fd, "r");
    if (!f) {
        st_fail(err, ST_ERR_RUNTIME, "%s: %s", path, strerror(errno));
        close(fd);
    }
    return f;
}

// Whether rel, taken lexically, climbs above its folder ("..", "a/../..").
static bool climbs_out(const char *rel) {
    int depth = 0;
    for (const char *p = rel; *p;) {
        size_t len = strcspn(p, "/");
        if (len == 2 && p[0] == '.' && p[1] == '.') {
            if (--depth < 0) return true;
        } else if (len > 0 && !(len == 1 && p[0] == '.')) {
            depth++;
        }
        p += len;
        while (*p == '/')
            p++;
    }
    return false;
}

bool st_path_confined(const char *dir, const char *rel, bool anywhere, char *out, size_t n,
                      st_err *err) {
    st_path_join(out, n, dir, rel);
    if (anywhere) return true;
    char root[PATH_MAX], real[PATH_MAX];
    if (!realpath(dir && dir[0] ? dir : ".", root))
        return st_fail(err, ST_ERR_INPUT, "folder '%s': %s", dir, strerror(errno));
    bool out_of_tree = rel[0] == '/' || climbs_out(rel);
    if (!out_of_tree && realpath(out, real)) {
        size_t k = strlen(root);
        out_of_tree = strcmp(root, "/") && (strncmp(real, root, k) || (real[k] && real[k] != '/'));
        if (!out_of_tree) snprintf(out, n, "%s", real);
    }
    if (out_of_tree)
        return st_fail(err, ST_ERR_INPUT,
                       "'%s' is outside the scene's folder '%s' (--allow-outside-assets allows "
                       "it)",
                       rel, root);
    return true;
}

bool st_same_file(const char *a, const char *b) {
    struct stat x, y;
    return a && b && stat(a, &x) == 0 && stat(b, &y) == 0 && x.st_dev == y.st_dev &&
           x.st_ino == y.st_ino;
}

bool st_check_output(const char *flag, const char *path, const char *const *exts,
                     const char *const *inputs, st_err *err) {
    if (!flag) flag = "output";
    if (!path || !path[0]) return st_fail(err, ST_ERR_INPUT, "%s: empty file name", flag);
    const char *slash = strrchr(path, '/'), *base = slash ? slash + 1 : path;
    if (!base[0] || !strcmp(base, ".") || !strcmp(base, ".."))
        return st_fail(err, ST_ERR_INPUT, "%s %s: names a directory, not a file", flag, path);
    if (strlen(path) >= sizeof((st_outfile *)0)->path)
        return st_fail(err, ST_ERR_INPUT, "%s %.64s...: path longer than %zu bytes", flag, path,
                       sizeof((st_outfile *)0)->path - 1);
    if (strlen(base) > NAME_MAX)
        return st_fail(err, ST_ERR_INPUT, "%s %s: file name longer than %d bytes", flag, path,
                       NAME_MAX);
    for (const char *p = path; *p; p++)
        if ((unsigned char)*p < 0x20 || *p == 0x7f)
            return st_fail(err, ST_ERR_INPUT, "%s: the path contains a control character", flag);
    if (exts) {
        const char *dot = strrchr(base, '.');
        bool ok = false;
        char list[128] = "";
        size_t l = 0;
        for (int i = 0; exts[i]; i++) {
            ok |= dot && !strcasecmp(dot + 1, exts[i]);
            l += (size_t)snprintf(list + l, sizeof list - l, "%s.%s", i ? " or " : "", exts[i]);
            if (l >= sizeof list) l = sizeof list - 1;
        }
        if (!ok)
            return st_fail(err, ST_ERR_INPUT, "%s %s: the file name must end in %s", flag, path,
                           list);
    }
    struct stat st;
    if (stat(path, &st) == 0 && !S_ISREG(st.st_mode))
        return st_fail(err, ST_ERR_INPUT, "%s %s: exists and is %s", flag, path,
                       kind_of(st.st_mode));
    char dir[4096];
    st_path_dir(dir, sizeof dir, path);
    if (stat(dir, &st) != 0)
        return st_fail(err, ST_ERR_INPUT, "%s %s: folder '%s' does not exist", flag, path, dir);
    if (!S_ISDIR(st.st_mode))
        return st_fail(err, ST_ERR_INPUT, "%s %s: '%s' is not a folder", flag, path, dir);
    for (int i = 0; inputs && inputs[i]; i++)
        if (st_same_file(path, inputs[i]))
            return st_fail(err, ST_ERR_INPUT,
                           "%s %s: is the input '%s' (the same file); refusing to overwrite it",
                           flag, path, inputs[i]);
    // The only reliable test of "can a file be created here" (root ignores
    // modes, /proc refuses anyway): create one.
    st_outfile probe;
    st_err e = {0};
    if (!st_out_begin(&probe, path, &e)) return st_fail(err, ST_ERR_INPUT, "%s %s", flag, e.msg);
    st_out_abort(&probe);
    return true;
}

bool st_out_begin(st_outfile *o, const char *path, st_err *err) {
    memset(o, 0, sizeof *o);
    o->fd = -1;
    if (!path || !path[0]) return st_fail(err, ST_ERR_INPUT, "empty output path");
    if (strlen(path) >= sizeof o->path)
        return st_fail(err, ST_ERR_INPUT, "%.64s...: path too long", path);
    snprintf(o->path, sizeof o->path, "%s", path);
    char dir[4096];
    st_path_dir(dir, sizeof dir, path);
    // A short fixed name: the output's own name may be near NAME_MAX.
    snprintf(o->tmp, sizeof o->tmp, "%s/.strahl-XXXXXX", dir);
    o->fd = mkostemp(o->tmp, O_CLOEXEC);
    if (o->fd < 0) {
        int e = errno;
        o->tmp[0] = 0;
        return st_fail(err, ST_ERR_RUNTIME, "%s: cannot create a temporary file in '%s': %s", path,
                       dir, strerror(e));
    }
    // mkstemp makes 0600; an output gets the usual 0666 less the umask.
    mode_t um = umask(0);
    umask(um);
    int rc = fchmod(o->fd, 0666 & ~um); // on failure the file just stays private
    (void)rc;
    return true;
}

FILE *st_out_stream(st_outfile *o, st_err *err) {
    if (o->f) return o->f;
    o->f = fdopen(o->fd, "w");
    if (!o->f) st_fail(err, ST_ERR_RUNTIME, "%s: %s", o->path, strerror(errno));
    return o->f;
}

void st_out_abort(st_outfile *o) {
    if (o->f)
        fclose(o->f);
    else if (o->fd >= 0)
        close(o->fd);
    if (o->tmp[0]) unlink(o->tmp);
    o->f = NULL;
    o->fd = -1;
    o->tmp[0] = 0;
}

bool st_out_commit(st_outfile *o, st_err *err) {
    bool ok = true;
    int e = 0;
    if (o->f) {
        ok = fflush(o->f) == 0 && !ferror(o->f);
        if (!ok) e = errno;
        ok = (fclose(o->f) == 0) && ok;
    } else if (o->fd >= 0) {
        ok = close(o->fd) == 0;
    }
    if (!ok && !e) e = errno;
    o->f = NULL;
    o->fd = -1;
    if (ok && rename(o->tmp, o->path) != 0) {
        ok = false;
        e = errno;
    }
    if (!ok) {
        unlink(o->tmp);
        o->tmp[0] = 0;
        return st_fail(err, ST_ERR_RUNTIME, "%s: cannot write: %s", o->path,
                       e ? strerror(e) : "I/O error");
    }
    o->tmp[0] = 0;
    return true;
}
