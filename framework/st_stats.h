// strahl: what a world reports about itself: per-pass statistics (runs,
// skips, culls, timing samples) and the GPU memory table, for --stats,
// benchmarks and tests.
#ifndef ST_STATS_H
#define ST_STATS_H
#include "st_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct st_world st_world;

// One row of the GPU memory table: a target, a tracked object, a camera
// target, the scene's geometry or the medium's density grid.
typedef struct st_mem_entry {
    char name[ST_NAME_MAX];
    char owner[ST_NAME_MAX]; // the module; "camera", "world" for the world's own
    char format[32];         // "RGBA32F", "3xRGBA32F+D32F" (colour textures, depth); "-"
    const char *kind; // "2D", "1D", "2D array", "cube array", "3D", "buffer", "buffer texture"
    int width, height, layers, levels; // 0 for buffers; a 3D texture's depth is its layers
    size_t bytes;                      // 0 for a target not allocated yet
} st_mem_entry;
// The world's GPU memory, every row: fills at most max of them (out may be
// NULL) and returns how many there are. Rows of one owner are adjacent.
int st_world_memory(st_world *w, st_mem_entry *out, int max);
// Their sum.
size_t st_world_memory_bytes(st_world *w);

#define ST_STATS_MAX_SAMPLES 4096

typedef struct st_pass_stats {
    char module[ST_NAME_MAX], pass[ST_NAME_MAX];
    uint32_t runs, skipped, culled;
    bool ran_last_frame, culled_last_frame;
    int num_samples;
    float gpu_ms[ST_STATS_MAX_SAMPLES], cpu_ms[ST_STATS_MAX_SAMPLES];
} st_pass_stats;

int st_world_num_pass_stats(const st_world *w);
const st_pass_stats *st_world_pass_stats(const st_world *w, int i);
void st_world_reset_stats(st_world *w);
// Drops timing samples (after warm-up) but keeps run/skip/cull counts.
void st_world_reset_samples(st_world *w);

#ifdef __cplusplus
}
#endif
#endif
