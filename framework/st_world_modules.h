// strahl (internal): the module list of a world as creation and destruction
// (st_world.c) drive it; the host's calls (switching, parameters, progress,
// reload) are in st_world.h.
#ifndef ST_WORLD_MODULES_H
#define ST_WORLD_MODULES_H
#include "st_world_state.h"

// Index of the loaded module `name` in frame order, -1 when none.
int st_world_find_module(const st_world *w, const char *name);
// Loads module `name` with its parameters (from the scene, else defaults);
// it is ordered by st_world_resolve and created by st_world_instantiate.
bool st_world_load(st_world *w, const char *name, st_err *err);
// Destroys module m's instance and passes, frees its targets, closes the plugin.
void st_world_unload(st_world *w, int m);
// The plugin's destroy (if it has one) for an instance that was created.
void st_world_destroy_instance(st_module_inst *mi);
// Orders the modules so each comes after the providers of what it requires.
bool st_world_resolve(st_world *w, st_err *err);
// Creates module m's instance and its declared passes (nothing if it exists).
bool st_world_instantiate(st_world *w, int m, st_err *err);
#endif
