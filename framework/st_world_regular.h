// strahl (internal): the regular pass's program, rebuilt whenever the module
// list changes (creation, switching, reload).
#ifndef ST_WORLD_REGULAR_H
#define ST_WORLD_REGULAR_H
#include "st_world_api.h"

// (Re)builds the regular pass's shader (and the background's) for the loaded
// modules' includes; the old ones stay on failure.
bool st_world_build_regular(st_world *w, st_err *err);
#endif
