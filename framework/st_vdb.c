// OpenVDB density grids for the scene (st_vdb_load, st_scene.h), parsed out
// of process: OpenVDB 10.0 overflows a heap buffer on a crafted file
// (docs/security.md, VDB files), so the helper strahl-vdb-read reads the
// file and strahl only checks and places what comes back (st_vdb_reply.c).
// The helper is started with posix_spawn (never fork: the renderer's TBB and
// Embree threads make fork without exec unsafe) and a fixed argv, gets the
// descriptor strahl opened and checked as its stdin (no second open by
// name), limits its own address space and CPU time (st_vdb_limits_for), and
// is killed when it outlives the wall-clock limit.
#define _GNU_SOURCE
#include "st_file.h"
#include "st_vdb_proto.h"

#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <libgen.h>
#include <signal.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

extern char **environ;

st_vdb_limits st_vdb_limits_for(uint64_t max_voxels) {
    st_vdb_limits l = {0};
    l.max_voxels = max_voxels;
    // The dense copy (4 bytes a voxel) and OpenVDB's tree of the same
    // voxels (about 4.2 bytes a voxel in full leaves), doubled for slack,
    // above 1 GiB for the libraries, thread stacks and malloc's arenas.
    l.as_bytes = (1ull << 30) + 16 * max_voxels;
    // A valid grid at the cap takes a few seconds; one per 2^20 voxels
    // above ten gives the helper room on a loaded machine.
    l.cpu_s = 10 + (unsigned)(max_voxels >> 20);
    l.wall_s = 2 * l.cpu_s + 10;
    return l;
}

// The helper beside libstrahl: <libdir>/../libexec/strahl/strahl-vdb-read,
// the same in the build tree (build/lib, build/libexec) and installed.
bool st_vdb_reader_path(char *out, size_t n, st_err *err) {
    Dl_info info;
    if (!dladdr((void *)st_vdb_load, &info) || !info.dli_fname)
        return st_fail(err, ST_ERR_RUNTIME, "cannot locate libstrahl to find %s",
                       ST_VDB_READER_NAME);
    char lib[4096];
    snprintf(lib, sizeof lib, "%s", info.dli_fname);
    snprintf(out, n, "%s/%s", dirname(lib), ST_VDB_READER_REL);
    if (access(out, X_OK) != 0)
        return st_fail(err, ST_ERR_RUNTIME,
                       "the VDB reader %s is missing or not executable (it is installed beside "
                       "libstrahl, in ../libexec/strahl/)",
                       out);
    return true;
}

// Starts the helper on fd (its stdin), its reply on *out_fd; stderr goes to
// /dev/null so a crash inside OpenVDB prints nothing of its own.
static pid_t spawn_reader(const char *exe, int fd, const char *path, const char *grid,
                          const st_vdb_limits *l, int *out_fd, st_err *err) {
    int p[2];
    if (pipe2(p, O_CLOEXEC) != 0)
        return st_fail(err, ST_ERR_RUNTIME, "%s: pipe: %s", path, strerror(errno)), -1;
    fcntl(p[0], F_SETPIPE_SZ, 1 << 20); // fewer wake-ups; a smaller pipe works too
    // Above the standard descriptors (closed ones are reused by open and
    // pipe), so that dup2 onto 0 and 1 cannot clobber one of them.
    const int in = fcntl(fd, F_DUPFD_CLOEXEC, 3), w = fcntl(p[1], F_DUPFD_CLOEXEC, 3);
    close(p[1]);
    if (in < 0 || w < 0) {
        if (in >= 0) close(in);
        if (w >= 0) close(w);
        close(p[0]);
        return st_fail(err, ST_ERR_RUNTIME, "%s: fcntl: %s", path, strerror(errno)), -1;
    }
    char vox[24], as[24], cpu[16];
    snprintf(vox, sizeof vox, "%llu", (unsigned long long)l->max_voxels);
    snprintf(as, sizeof as, "%llu", (unsigned long long)l->as_bytes);
    snprintf(cpu, sizeof cpu, "%u", l->cpu_s);
    char *const argv[] = {(char *)exe, "1", (char *)path, (char *)grid, vox, as, cpu, NULL};
    posix_spawn_file_actions_t fa;
    posix_spawnattr_t at;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_adddup2(&fa, in, 0);
    posix_spawn_file_actions_adddup2(&fa, w, 1);
    posix_spawn_file_actions_addopen(&fa, 2, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addclosefrom_np(&fa, 3);
    posix_spawnattr_init(&at);
    sigset_t none, all;
    sigemptyset(&none);
    sigfillset(&all);
    posix_spawnattr_setsigmask(&at, &none);
    posix_spawnattr_setsigdefault(&at, &all);
    posix_spawnattr_setflags(&at, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
    pid_t pid = -1;
    const int rc = posix_spawn(&pid, exe, &fa, &at, argv, environ);
    posix_spawn_file_actions_destroy(&fa);
    posix_spawnattr_destroy(&at);
    close(in);
    close(w);
    if (rc != 0) {
        close(p[0]);
        return st_fail(err, ST_ERR_RUNTIME, "%s: cannot start %s: %s", path, exe, strerror(rc)), -1;
    }
    *out_fd = p[0];
    return pid;
}

// Reaps pid by the deadline, killing it then; the wait status.
static int reap(pid_t pid, uint64_t deadline, bool *timed_out) {
    int status = 0;
    for (;;) {
        const pid_t r = waitpid(pid, &status, WNOHANG);
        if (r == pid) return status;
        if (r < 0 && errno != EINTR) return -1;
        if ((uint64_t)st_now_ms() >= deadline) break;
        nanosleep(&(struct timespec){0, 1000000}, NULL);
    }
    *timed_out = true;
    kill(pid, SIGKILL);
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    return status;
}

// One message for a helper that did not reply normally: killed by the
// deadline, by a signal (a crash inside OpenVDB, or RLIMIT_CPU), or an exit.
static bool reader_failed(const char *path, const st_vdb_limits *l, int status, bool timed_out,
                          const st_err *reply, st_err *err) {
    static const char *why =
        "a corrupt or hostile file (OpenVDB runs in that separate process, docs/security.md)";
    if (timed_out)
        return st_fail(err, ST_ERR_INPUT,
                       "%s: the VDB reader " ST_VDB_READER_NAME
                       " took longer than %u s and was killed: %s",
                       path, l->wall_s, why);
    // SIGPIPE: strahl stopped reading a reply it refused; that reason wins.
    const bool sigpipe = status != -1 && WIFSIGNALED(status) && WTERMSIG(status) == SIGPIPE;
    if (status != -1 && WIFSIGNALED(status) && !(sigpipe && reply->kind)) {
        const int sig = WTERMSIG(status);
        if (sig == SIGXCPU)
            return st_fail(err, ST_ERR_INPUT,
                           "%s: the VDB reader " ST_VDB_READER_NAME
                           " used up its %u s of CPU time: %s",
                           path, l->cpu_s, why);
        return st_fail(err, ST_ERR_INPUT,
                       "%s: the VDB reader " ST_VDB_READER_NAME " crashed (signal %d, %s): %s",
                       path, sig, strsignal(sig), why);
    }
    if (status == -1 || (WIFEXITED(status) && WEXITSTATUS(status) != 0))
        return st_fail(err, ST_ERR_INPUT,
                       "%s: the VDB reader " ST_VDB_READER_NAME " failed (exit status %d): %s",
                       path, status == -1 ? -1 : WEXITSTATUS(status), why);
    // Its reply was refused (malformed, or the helper's own message).
    *err = *reply;
    if (!err->kind) st_fail(err, ST_ERR_INPUT, "%s: the VDB reader failed: %s", path, why);
    return false;
}

bool st_vdb_load_via(const char *exe, const st_vdb_limits *l, const char *path, const char *grid,
                     const double translate[3], const double scale[3], st_density_grid *out,
                     st_err *err) {
    memset(out, 0, sizeof *out);
    const int fd = st_open_input(path, ST_VDB_MAX_FILE_BYTES, "VDB file", NULL, err);
    if (fd < 0) return false;
    int rfd = -1;
    const uint64_t deadline = (uint64_t)st_now_ms() + 1000ull * l->wall_s;
    const pid_t pid = spawn_reader(exe, fd, path, grid, l, &rfd, err);
    close(fd);
    if (pid < 0) return false;
    st_vdb_raw raw = {0};
    st_err reply = {0};
    bool timed_out = false;
    const bool ok = st_vdb_read_reply(rfd, path, l->max_voxels, deadline, &raw, &timed_out, &reply);
    close(rfd); // a helper still writing gets SIGPIPE
    const int status = reap(pid, timed_out ? 0 : deadline, &timed_out);
    const bool exited0 = status != -1 && WIFEXITED(status) && WEXITSTATUS(status) == 0;
    if (!ok || !exited0 || timed_out) {
        free(raw.values);
        return reader_failed(path, l, status, timed_out, &reply, err);
    }
    return st_vdb_place(&raw, path, grid, l->max_voxels, translate, scale, out, err);
}

bool st_vdb_load(const char *path, const char *grid, const double translate[3],
                 const double scale[3], st_density_grid *out, st_err *err) {
    memset(out, 0, sizeof *out);
    const st_vdb_limits l = st_vdb_limits_for(ST_VDB_MAX_VOXELS);
    char exe[4200];
    return st_vdb_reader_path(exe, sizeof exe, err) &&
           st_vdb_load_via(exe, &l, path, grid, translate, scale, out, err);
}
